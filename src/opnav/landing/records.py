"""Per planning call records of the descent (paper B sec. 3; SPEC B.4): what each
call returned and everything it took, and the ``.npz`` files they are kept in.

Description
-----------
The descent (``opnav.landing.descent.run_descents``) keeps, per run and per
planning call in call order:

* :data:`PLAN_KEYS`, what the call returned: the filter time ``plan_t`` (s), the
  number of objective evaluations, the optimum ``beta`` (rad), the picked
  landmark (-1: none), the edge flag and the pick ratio;
* :data:`RECORD_KEYS`, everything ``planner.plan`` took, to replay the call
  exactly (``opnav.landing.timing``): the filter step (the truth pose, hence the
  detected landmarks, follows from the scenario), the estimate ``PlanState(r,
  v, a, R_LtoB, P)``, the excluded current landmark (-1: none) and the state of
  the run's picker stream (:func:`rng_words`).

:data:`CALL_KEYS` is both: the per-call arrays that the Monte Carlo
concatenates over runs (``opnav.landing.montecarlo``). Planning *time* is not a
record: it is measured by replaying these inputs (``opnav.landing.timing``).

The typed records: :class:`Descent` is one flown run (what ``run_descents`` returns),
:class:`MonteCarlo` runs of one method stacked (a chunk or a gathered Monte Carlo: the
tracks with a leading run axis, the calls concatenated over runs with their run index
``plan_run``). Their fields are the arrays' names in the files.

Files: :func:`save` / :func:`load` write and read a dict of arrays (``.npz``,
atomically; a truncated or corrupt file raises
``opnav.core.snakeio.CorruptIntermediate`` naming it and its rebuild command), for
the Monte-Carlo chunks and the timing replay alike; :meth:`MonteCarlo.arrays` and
:meth:`MonteCarlo.from_arrays` are the records' side of that edge.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Mapping

import numpy as np

__all__ = ["PLAN_KEYS", "RECORD_KEYS", "CALL_KEYS", "TRACK_KEYS", "Descent", "MonteCarlo", "CallLog", "Replay",
           "rng_words", "rng_from_words", "save", "load"]

#: per planning call, what it returned: key -> dtype
_PLAN_DTYPES = {"plan_evals": np.int64, "plan_t": float, "plan_beta": float, "plan_index": np.int64,
                "plan_edge": bool, "plan_ratio": float}
PLAN_KEYS = tuple(_PLAN_DTYPES)
#: per planning call, its inputs: filter step index, estimate r (3), v (3), a (3),
#: R_LtoB (3, 3), covariance P (12, 12), excluded landmark (-1: none), picker
#: stream state (6 words)
_SHAPES = {"plan_step": (), "plan_r": (3,), "plan_v": (3,), "plan_a": (3,), "plan_R": (3, 3),
           "plan_P": (12, 12), "plan_exclude": (), "plan_rng": (6,)}
RECORD_KEYS = tuple(_SHAPES)
_DTYPES = {"plan_step": np.int64, "plan_exclude": np.int64, "plan_rng": np.uint64}
#: every per-call array of a run (returned values, then inputs)
CALL_KEYS = PLAN_KEYS + RECORD_KEYS
#: per run and filter time (n_steps + 1), the descent's tracks: errors truth - estimate of
#: position (m), velocity (m/s), attitude (small-angle dtheta and roll/pitch/yaw, deg), the
#: filter's 1-sigma of each, the heading 1-sigma (deg), position and velocity NEES, whether a
#: vision update / an update with a landmark bearing happened, the cut-off quantity (m)
TRACK_KEYS = ("err_r", "err_v", "err_th_deg", "err_rpy_deg", "sig_r", "sig_v", "sig_th_deg",
              "sig_yaw_deg", "nees_r", "nees_v", "updated", "lm_updated", "cut_alt_m")
_MASK64 = (1 << 64) - 1
_META = {**{k: ((), dt) for k, dt in _PLAN_DTYPES.items()},
         **{k: (shape, _DTYPES.get(k, float)) for k, shape in _SHAPES.items()}}


def rng_words(rng: np.random.Generator | None) -> np.ndarray:
    """The state of a PCG64 generator as 6 uint64 words (state hi/lo, inc
    hi/lo, has_uint32, uinteger); zeros for no generator."""
    if rng is None:
        return np.zeros(6, np.uint64)
    s = rng.bit_generator.state
    if s["bit_generator"] != "PCG64":
        raise ValueError(f"rng_words: PCG64 expected, got {s['bit_generator']}")
    st, inc = int(s["state"]["state"]), int(s["state"]["inc"])
    return np.array([st >> 64, st & _MASK64, inc >> 64, inc & _MASK64, int(s["has_uint32"]),
                     int(s["uinteger"])], np.uint64)


def rng_from_words(words) -> np.random.Generator:
    """Inverse of :func:`rng_words`: a generator in exactly that state."""
    w = [int(x) for x in np.asarray(words, np.uint64)]
    g = np.random.Generator(np.random.PCG64())
    g.bit_generator.state = {"bit_generator": "PCG64",
                             "state": {"state": (w[0] << 64) | w[1], "inc": (w[2] << 64) | w[3]},
                             "has_uint32": w[4], "uinteger": w[5]}
    return g


class CallLog:
    """One run's planning calls as the descent flies them: per key of :data:`CALL_KEYS` the
    values in call order (:meth:`record_inputs` just before a call, :meth:`append` after it),
    stacked into arrays by :meth:`arrays`."""

    __slots__ = ("_lists",)

    def __init__(self):
        self._lists = {k: [] for k in CALL_KEYS}

    @property
    def n_calls(self) -> int:
        """Calls whose inputs were recorded so far."""
        return len(self._lists["plan_step"])

    def record_inputs(self, step: int, r, v, a, R_LtoB, P, exclude: int,
                      rng: np.random.Generator | None) -> None:
        """Append one planning call's inputs (:data:`RECORD_KEYS`); call it just before the
        planning call (the picker stream's state before it draws)."""
        for key, val in zip(RECORD_KEYS, (int(step), r, v, a, R_LtoB, P, int(exclude), rng_words(rng))):
            self._lists[key].append(np.array(val, _META[key][1], copy=True))

    def append(self, t_s: float, res) -> None:
        """Append what one planning call returned (:data:`PLAN_KEYS`): the filter time ``t_s``
        (s) and the ``planner.PlanResult`` ``res``."""
        for key, val in zip(PLAN_KEYS, (res.n_evals, t_s, res.beta, res.index, res.edge, res.pick_ratio)):
            self._lists[key].append(val)

    def arrays(self) -> dict[str, np.ndarray]:
        """The recorded lists as arrays, by key of :data:`CALL_KEYS` (calls first; empty arrays
        of the right shape and dtype if none): a :class:`Descent`'s call fields."""
        out = {}
        for k, vals in self._lists.items():
            shape, dt = _META[k]
            out[k] = np.stack([np.asarray(v, dt) for v in vals]) if vals else np.zeros((0,) + shape, dt)
        return out


def save(path, data: dict) -> None:
    """Write a dict of arrays (``.npz``, compressed, atomically)."""
    from opnav.core.tables import atomic_target

    with atomic_target(path) as tmp:
        np.savez_compressed(tmp, **data)


def load(path) -> dict[str, np.ndarray]:
    """Read a :func:`save` file; a truncated or corrupt one raises
    :class:`opnav.core.snakeio.CorruptIntermediate` naming it and its rebuild command."""
    import zipfile

    from opnav.core.snakeio import corrupt_intermediate

    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except (zipfile.BadZipFile, EOFError, ValueError, OSError, KeyError) as exc:
        raise corrupt_intermediate(path, exc) from exc


@dataclass(frozen=True, eq=False)
class Descent:
    """One flown descent (``descent.run_descents``): the filter times ``t`` (s), the tracks of
    :data:`TRACK_KEYS` (times first), the landmarks used, the initial error (truth - estimate
    [dr, dv, dtheta] (9,), m, m/s, rad) and its planning calls (:data:`CALL_KEYS`, calls first)."""

    t: np.ndarray
    err_r: np.ndarray
    err_v: np.ndarray
    err_th_deg: np.ndarray
    err_rpy_deg: np.ndarray
    sig_r: np.ndarray
    sig_v: np.ndarray
    sig_th_deg: np.ndarray
    sig_yaw_deg: np.ndarray
    nees_r: np.ndarray
    nees_v: np.ndarray
    updated: np.ndarray
    lm_updated: np.ndarray
    cut_alt_m: np.ndarray
    n_landmarks: int
    init_error: np.ndarray
    plan_evals: np.ndarray
    plan_t: np.ndarray
    plan_beta: np.ndarray
    plan_index: np.ndarray
    plan_edge: np.ndarray
    plan_ratio: np.ndarray
    plan_step: np.ndarray
    plan_r: np.ndarray
    plan_v: np.ndarray
    plan_a: np.ndarray
    plan_R: np.ndarray
    plan_P: np.ndarray
    plan_exclude: np.ndarray
    plan_rng: np.ndarray


@dataclass(frozen=True, eq=False)
class MonteCarlo:
    """Runs of one planning method stacked (a chunk, a gathered Monte Carlo, or part of one):
    ``run_index`` (runs,), ``t`` (filter times, s), the tracks of :data:`TRACK_KEYS` (runs x
    times ...), ``n_landmarks`` and ``init_error`` per run, the planning calls of
    :data:`CALL_KEYS` concatenated over runs in run order with their run ``plan_run``, the
    ``method`` and the chunk's ``reuse_key`` (``montecarlo.run_chunk_reusing``) where known.

    A field is None where the record does not hold it: a replay reads only the calls
    (``timing.load_calls``), a test builds the part it checks."""

    run_index: np.ndarray | None = None
    t: np.ndarray | None = None
    err_r: np.ndarray | None = None
    err_v: np.ndarray | None = None
    err_th_deg: np.ndarray | None = None
    err_rpy_deg: np.ndarray | None = None
    sig_r: np.ndarray | None = None
    sig_v: np.ndarray | None = None
    sig_th_deg: np.ndarray | None = None
    sig_yaw_deg: np.ndarray | None = None
    nees_r: np.ndarray | None = None
    nees_v: np.ndarray | None = None
    updated: np.ndarray | None = None
    lm_updated: np.ndarray | None = None
    cut_alt_m: np.ndarray | None = None
    n_landmarks: np.ndarray | None = None
    init_error: np.ndarray | None = None
    plan_evals: np.ndarray | None = None
    plan_t: np.ndarray | None = None
    plan_beta: np.ndarray | None = None
    plan_index: np.ndarray | None = None
    plan_edge: np.ndarray | None = None
    plan_ratio: np.ndarray | None = None
    plan_step: np.ndarray | None = None
    plan_r: np.ndarray | None = None
    plan_v: np.ndarray | None = None
    plan_a: np.ndarray | None = None
    plan_R: np.ndarray | None = None
    plan_P: np.ndarray | None = None
    plan_exclude: np.ndarray | None = None
    plan_rng: np.ndarray | None = None
    plan_run: np.ndarray | None = None
    method: str | None = None
    reuse_key: str | None = None

    #: the per-run arrays (leading axis: runs), in file order
    RUN_KEYS = ("run_index",) + TRACK_KEYS + ("n_landmarks", "init_error")

    @property
    def n_runs(self) -> int:
        return int(len(self.run_index))

    def has(self, name: str) -> bool:
        """Whether the record holds the array ``name`` (a field that is not None)."""
        return getattr(self, name) is not None

    def replace(self, **changes) -> "MonteCarlo":
        return dataclasses.replace(self, **changes)

    def arrays(self) -> dict[str, np.ndarray]:
        """The record as the ``.npz`` file holds it (the file edge, :func:`save`): ``method``
        first, then every array held, then ``reuse_key``."""
        out = {} if self.method is None else {"method": np.array(self.method)}
        for f in dataclasses.fields(self):
            if f.name not in ("method", "reuse_key") and getattr(self, f.name) is not None:
                out[f.name] = getattr(self, f.name)
        if self.reuse_key is not None:
            out["reuse_key"] = np.array(self.reuse_key)
        return out

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> "MonteCarlo":
        """The record of a file's arrays (:func:`load`); an array of another name is refused."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(arrays) - names)
        if unknown:
            raise ValueError(f"not a Monte-Carlo record: unknown arrays {unknown}")
        kw = {k: v for k, v in arrays.items() if k not in ("method", "reuse_key")}
        for k in ("method", "reuse_key"):
            if k in arrays:
                kw[k] = str(arrays[k])
        return cls(**kw)

    @classmethod
    def of_runs(cls, run_indices, runs: "list[Descent]", t: np.ndarray) -> "MonteCarlo":
        """The :class:`Descent` records ``runs`` of the runs ``run_indices`` as one record:
        tracks stacked (runs x ...), planning calls concatenated with their run index."""
        kw = {"run_index": np.asarray(list(run_indices), np.int64), "t": np.asarray(t).copy()}
        for k in TRACK_KEYS:
            kw[k] = np.stack([getattr(r, k) for r in runs])
        for k in CALL_KEYS:
            kw[k] = np.concatenate([getattr(r, k) for r in runs]) if runs else np.zeros(0)
        kw["plan_run"] = (np.concatenate([np.full(len(r.plan_t), int(i), np.int64)
                                          for i, r in zip(run_indices, runs)]) if runs else np.zeros(0, np.int64))
        kw["n_landmarks"] = np.array([r.n_landmarks for r in runs], np.int64)
        kw["init_error"] = np.stack([r.init_error for r in runs])
        return cls(**kw)

    @classmethod
    def of_descent(cls, run: Descent, run_index: int = 0) -> "MonteCarlo":
        """One :class:`Descent` as a record of one run (its calls' ``plan_run`` = ``run_index``)."""
        return cls.of_runs([run_index], [run], run.t)


@dataclass(frozen=True, eq=False)
class Replay:
    """A planning-time replay (``timing.replay``; several merged by ``timing.merge``), the arrays
    of its ``.npz`` file by name. Per replayed call (rows): ``source`` (position in ``sources``),
    ``run``, ``call``, ``step`` and, merged, ``replay`` (which replay) and ``row_clock_ns``; per row
    and variant (cells): ``wall_ns``, ``cpu_ns``, ``pick``, ``n_evals``, ``slot``, ``timed``,
    ``eval_ns``, ``reps``; per variant ``variant_method``, ``variant_path``,
    ``variant_eval_path``; per method of ``methods`` ``mismatch`` and ``checked``; scalars
    ``n_pool``, ``max_calls``, ``max_calls_paper``, ``clock_ns``, ``dispatch_ns``, ``n_cpu``,
    ``n_replays``, the load averages and ``part`` (``"replay"``: one of the claims' replays).
    Times ns. A field is None where the replay does not hold it (a file saved before it was
    recorded, a test's replay of given times): its readers say what None means."""

    sources: np.ndarray | None = None
    methods: np.ndarray | None = None
    source: np.ndarray | None = None
    call: np.ndarray | None = None
    run: np.ndarray | None = None
    step: np.ndarray | None = None
    wall_ns: np.ndarray | None = None
    cpu_ns: np.ndarray | None = None
    pick: np.ndarray | None = None
    n_evals: np.ndarray | None = None
    slot: np.ndarray | None = None
    timed: np.ndarray | None = None
    eval_ns: np.ndarray | None = None
    reps: np.ndarray | None = None
    variant_method: np.ndarray | None = None
    variant_path: np.ndarray | None = None
    variant_eval_path: np.ndarray | None = None
    mismatch: np.ndarray | None = None
    checked: np.ndarray | None = None
    n_pool: np.ndarray | None = None
    max_calls: np.ndarray | None = None
    max_calls_paper: np.ndarray | None = None
    clock_ns: np.ndarray | None = None
    dispatch_ns: np.ndarray | None = None
    load_avg: np.ndarray | None = None
    n_cpu: np.ndarray | None = None
    replay: np.ndarray | None = None
    n_replays: np.ndarray | None = None
    replay_clock_ns: np.ndarray | None = None
    replay_dispatch_ns: np.ndarray | None = None
    replay_load_avg: np.ndarray | None = None
    row_clock_ns: np.ndarray | None = None
    extra_load_avg: np.ndarray | None = None
    extra_clock_ns: np.ndarray | None = None
    part: np.ndarray | None = None

    #: per-call arrays (first axis: the replayed calls)
    ROW_KEYS = ("source", "call", "run", "step")
    #: per (call, variant) arrays
    CELL_KEYS = ("wall_ns", "cpu_ns", "pick", "n_evals", "slot", "timed", "eval_ns", "reps")

    def has(self, name: str) -> bool:
        """Whether the replay holds the array ``name`` (a field that is not None)."""
        return getattr(self, name) is not None

    def replace(self, **changes) -> "Replay":
        return dataclasses.replace(self, **changes)

    def arrays(self) -> dict[str, np.ndarray]:
        """The replay as its ``.npz`` file holds it (the file edge, :func:`save`): every array held."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if getattr(self, f.name) is not None}

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> "Replay":
        """The record of a file's arrays (:func:`load`); an array of another name is refused."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(arrays) - names)
        if unknown:
            raise ValueError(f"not a timing replay: unknown arrays {unknown}")
        return cls(**arrays)
