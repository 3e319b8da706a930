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

Files: :func:`save` / :func:`load` write and read a dict of arrays (``.npz``,
atomically; a truncated or corrupt file raises
``opnav.core.snakeio.CorruptIntermediate`` naming it and its rebuild command), for
the Monte-Carlo chunks and the timing replay alike.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PLAN_KEYS", "RECORD_KEYS", "CALL_KEYS", "new_calls", "append_call", "record_plan_inputs",
           "stack_calls", "rng_words", "rng_from_words", "save", "load"]

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


def new_calls() -> dict:
    """An empty record of one run's planning calls (lists keyed by :data:`CALL_KEYS`)."""
    return {k: [] for k in CALL_KEYS}


def record_plan_inputs(rec: dict, step: int, r, v, a, R_LtoB, P, exclude: int,
                       rng: np.random.Generator | None) -> None:
    """Append one planning call's inputs to ``rec`` (:data:`RECORD_KEYS`); call it
    just before the planning call (the picker stream's state before it draws)."""
    for key, val in zip(RECORD_KEYS, (int(step), r, v, a, R_LtoB, P, int(exclude), rng_words(rng))):
        rec[key].append(np.array(val, _META[key][1], copy=True))


def append_call(rec: dict, t_s: float, res) -> None:
    """Append what one planning call returned (:data:`PLAN_KEYS`) to ``rec``: the
    filter time ``t_s`` (s) and the ``planner.PlanResult`` ``res``."""
    for key, val in zip(PLAN_KEYS, (res.n_evals, t_s, res.beta, res.index, res.edge, res.pick_ratio)):
        rec[key].append(val)


def stack_calls(rec: dict) -> dict:
    """The recorded lists as arrays (calls first; empty arrays of the right shape
    and dtype if none), for every key of ``rec`` (:data:`CALL_KEYS` or part of it)."""
    out = {}
    for k, vals in rec.items():
        shape, dt = _META[k]
        out[k] = np.stack([np.asarray(v, dt) for v in vals]) if vals else np.zeros((0,) + shape, dt)
    return out


def save(path, data: dict) -> None:
    """Write a dict of arrays (``.npz``, compressed, atomically)."""
    from opnav.core.tables import atomic_target

    with atomic_target(path) as tmp:
        np.savez_compressed(tmp, **data)


def load(path) -> dict:
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
