"""Monte Carlo of the powered descent: chunks, gathering, and the B-T3 summary
(paper B sec. 3, Fig. 6-7; SPEC B.4).

Description
-----------
Run ``i`` of every method uses the random stream ``SeedSequence([base_seed,
i])`` only (``opnav.landing.descent.run_descents``), so the methods are paired
(same initial errors, IMU and pixel noise) and a run's result does not depend
on how runs are grouped into Snakemake jobs or batches. :func:`run_chunk`
flies a list of run indices (in batches of ``landing.mc.batch_size``) and
stacks the per-run arrays; :func:`summarize_run` is one run's
:func:`per_run_stats` row; :func:`gather` concatenates chunks
in run order. (B-T3, the table of these statistics per method, is
``opnav.report.landing.summary.summary_table``.)

Statistics (per method, over the runs): final (touchdown) and RMS (over time)
error norms of position (m), velocity (m/s) and attitude (deg, small-angle
``dtheta``), each as mean and ``3 sigma`` (three sample standard deviations),
the position and velocity error at the last vision update (``lastvis_``:
the filter then coasts on the IMU to touchdown), at the last update with a
landmark bearing (``lastlm_``) and RMS over the landmark-tracking phase
(``lmrms_``, :func:`landmark_phase`): what a landmark choice can move; the median
objective evaluations per call (the descent's count). The per-call records
(``opnav.landing.records``) are concatenated over runs with their run index;
planning times are not among them: they come from the replay of the recorded
planning calls (``opnav.landing.timing``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd
# The descent (scipy, CasADi) and pandas are imported by the functions that use them:
# the workflow parses this module at start-up and the gather jobs only stack arrays.

from opnav.landing import records   # numpy only
from opnav.landing.records import CALL_KEYS, TRACK_KEYS, Descent, MonteCarlo
from opnav.landing.setup import Setup

__all__ = ["yaw_convergence", "YawConvergence", "run_chunk", "stack_runs", "summarize_run", "last_update_index", "save", "load", "gather", "per_run_stats",
           "chunks", "chunk_label", "chunk_runs", "earlier_chunks", "run_chunk_reusing", "CHUNK_PATTERN",
           "same_pick_pct", "pick_quality", "first_runs", "end_phase", "landmark_phase", "phase_rms", "time_below",
           "nees_band", "nees_consistency", "NeesConsistency", "RunSummary",
           "EndPhase", "PickQuality", "MonteCarlo", "Descent"]


def chunks(n_runs: int, runs_per_job: int) -> list[list[int]]:
    """Run indices grouped into jobs of ``runs_per_job``."""
    if n_runs < 1 or runs_per_job < 1:
        raise ValueError("landing.mc.n_runs and runs_per_job must be >= 1")
    return [list(range(a, min(a + runs_per_job, n_runs))) for a in range(0, n_runs, runs_per_job)]


def chunk_label(run_indices) -> str:
    """A chunk's name from its (consecutive) run indices: ``[4, 5]`` -> ``"r0004-0005"``.

    Chunk files are named by the runs they hold, not by their position, so
    raising ``n_runs`` keeps every full chunk (same name, same runs); a formerly
    partial last chunk's runs are taken over by the chunk that replaces it
    (:func:`earlier_chunks`), so only the new runs are flown.
    """
    runs = [int(i) for i in run_indices]
    if not runs or runs != list(range(runs[0], runs[0] + len(runs))):
        raise ValueError(f"a chunk holds consecutive run indices, got {runs}")
    return f"r{runs[0]:04d}-{runs[-1]:04d}"


def chunk_runs(label: str) -> list[int]:
    """The run indices of a :func:`chunk_label` (inverse)."""
    m = re.fullmatch(r"r(\d{4,})-(\d{4,})", label)
    if not m or int(m.group(2)) < int(m.group(1)):
        raise ValueError(f"not a Monte-Carlo chunk label: {label!r} (expected e.g. 'r0000-0024')")
    return list(range(int(m.group(1)), int(m.group(2)) + 1))


def earlier_chunks(path, run_indices) -> list[tuple[Path, list[int]]]:
    """Chunk files beside ``path`` (same folder and suffix, :func:`chunk_label`
    names, not ``path`` itself) holding only runs of ``run_indices``: what a
    smaller ``n_runs`` (or study ``runs``) left, e.g. ``r0000-0003`` when
    ``r0000-0005`` is asked for. Disjoint, the largest first; (path, runs) pairs.
    Each run's random stream depends on its index only, so their runs need not be
    flown again; the caller checks that they were flown with the same config."""
    path = Path(path)
    want = {int(i) for i in run_indices}
    found = []
    for p in path.parent.glob(f"r*{path.suffix}"):
        try:
            runs = chunk_runs(p.name[:-len(path.suffix)] if path.suffix else p.name)
        except ValueError:
            continue
        if p.name != path.name and set(runs) <= want:
            found.append((p, runs))
    taken, out = set(), []
    for p, runs in sorted(found, key=lambda f: (-len(f[1]), f[1][0])):
        if not taken & set(runs):
            out.append((p, runs))
            taken |= set(runs)
    return out


def run_chunk_reusing(path, reuse_key: str, setup: Setup, method: str, run_indices,
                      pick_ratio: bool = True, batch_size: int | None = None) -> tuple[MonteCarlo, list[int]]:
    """:func:`run_chunk` for the chunk file ``path``, taking the runs already
    flown in :func:`earlier_chunks` whose stored ``reuse_key`` (a digest of
    everything the runs depend on, given by the caller) equals ``reuse_key``:
    (the chunk, as :func:`run_chunk` would return it, with ``reuse_key``; the run
    indices actually flown; ``batch_size`` as :func:`run_chunk`'s, not in the key). Gathering in run order makes it the same chunk
    whatever was reused (:func:`gather`)."""
    idx = [int(i) for i in run_indices]
    parts = []
    for p, _ in earlier_chunks(path, idx):
        old = load(p)
        if (old.reuse_key or "") == reuse_key:
            parts.append(old.replace(method=None, reuse_key=None))
    have = {int(i) for part in parts for i in part.run_index}
    todo = [i for i in idx if i not in have]
    if todo:
        parts.append(run_chunk(setup, method, todo, batch_size=batch_size, pick_ratio=pick_ratio))
    data = parts[0] if len(parts) == 1 else gather(parts)
    return data.replace(reuse_key=str(reuse_key)), todo


#: Snakemake wildcard pattern of :func:`chunk_label`.
CHUNK_PATTERN = r"r[0-9]+-[0-9]+"


def run_chunk(setup: Setup, method: str, run_indices, batch_size: int | None = None,
              pick_ratio: bool = True) -> MonteCarlo:
    """Fly the runs ``run_indices`` with ``method`` in the scenario of the landing ``setup``; their
    records stacked (see module doc).

    Runs are flown in batches of ``batch_size`` (default ``landing.mc.batch_size``;
    0 = all runs as one batch); the numbers do not depend on it (to round-off).
    ``pick_ratio = False``: no pick-ratio diagnostic (``plan_ratio`` NaN; nothing
    else changes), for methods no table shows it for (B-T3 lists ``landing.mc.methods``)."""
    from opnav.landing.descent import run_descents
    from opnav.landing.scenario import build_scenario

    scn = build_scenario(setup)
    idx = [int(i) for i in run_indices]
    if batch_size is None:
        batch_size = int(setup.mc.batch_size)
    size = len(idx) if batch_size <= 0 else int(batch_size)
    runs = []
    for a in range(0, len(idx), max(size, 1)):
        runs.extend(run_descents(scn, method, idx[a:a + size], pick_ratio=pick_ratio))
    return stack_runs(idx, runs, scn.truth.t)


def stack_runs(run_indices, runs: list[Descent], t: np.ndarray) -> MonteCarlo:
    """The :class:`Descent` records of :func:`opnav.landing.descent.run_descents` as one
    chunk: tracks stacked (runs x ...), planning calls concatenated with their
    run index (``plan_run``); :meth:`MonteCarlo.of_runs`."""
    return MonteCarlo.of_runs(run_indices, runs, t)


@dataclass(frozen=True)
class RunSummary:
    """One run in numbers (:func:`summarize_run`): its :func:`per_run_stats` row by column
    (``stats``: final, last-vision and RMS error norms, mean NEES, landmarks used; written as the
    summary's own keys), the final yaw error (deg), the planning calls and their median
    evaluation count."""

    stats: dict[str, float] = field(metadata={"json_flatten": True})
    final_yaw_err_deg: float
    n_plans: int
    median_plan_evals: float


def summarize_run(run: Descent, run_index: int = 0) -> RunSummary:
    """One run of :func:`opnav.landing.descent.run_descent`: its
    :func:`per_run_stats` row (final, last-vision and RMS error norms, mean
    NEES, landmarks used) plus the final yaw error (deg), the number of
    planning calls and their median evaluation count (planning time: replay
    the run's calls, ``opnav.landing.timing.replay_own``)."""
    data = MonteCarlo.of_descent(run, run_index)
    stats = {k: (int(v) if k == "n_landmarks" else float(v)) for k, v in per_run_stats(data).iloc[0].items()}
    return RunSummary(stats, float(run.err_rpy_deg[-1, 2]), int(len(run.plan_t)),
                      float(np.median(run.plan_evals)) if len(run.plan_evals) else math.nan)


def save(path, data: MonteCarlo, method: str) -> None:
    """Write a chunk or gathered result of ``method`` (the file edge: ``records.save`` of
    :meth:`MonteCarlo.arrays`, ``.npz``, atomically; read it with :func:`load`)."""
    records.save(path, data.replace(method=str(method)).arrays())


def load(path) -> MonteCarlo:
    """A :func:`save` file as its record (``records.load``: a truncated or corrupt file raises
    ``CorruptIntermediate`` naming it)."""
    return MonteCarlo.from_arrays(records.load(path))


def gather(parts: list[MonteCarlo]) -> MonteCarlo:
    """Concatenate chunk results in run-index order; checks for gaps/duplicates."""
    if not parts:
        raise ValueError("no Monte-Carlo chunks to gather")
    methods = {p.method for p in parts if p.method is not None}
    if len(methods) > 1:
        raise ValueError(f"chunks of different methods gathered together: {sorted(methods)}")
    idx = np.concatenate([p.run_index for p in parts])
    order = np.argsort(idx, kind="stable")
    if len(np.unique(idx)) != len(idx):
        raise ValueError("duplicate run indices in the Monte-Carlo chunks")
    out = {"run_index": idx[order], "t": parts[0].t}
    for k in TRACK_KEYS + ("n_landmarks", "init_error"):
        out[k] = np.concatenate([getattr(p, k) for p in parts])[order]
    pr = np.concatenate([p.plan_run for p in parts])
    po = np.argsort(pr, kind="stable")
    for k in CALL_KEYS:
        out[k] = np.concatenate([getattr(p, k) for p in parts])[po]
    out["plan_run"] = pr[po]
    return MonteCarlo(**out, method=methods.pop() if methods else None)


def first_runs(data: MonteCarlo, n: int) -> MonteCarlo:
    """``data`` (:func:`gather`'s layout) restricted to its runs of index < ``n`` (tracks by
    ``run_index``, planning calls by ``plan_run``): the paired runs every method of B-X1
    flew. Raises ``ValueError`` if it lacks one of runs 0..n-1."""
    keep = np.asarray(data.run_index) < n
    if int(keep.sum()) != n or not np.array_equal(np.sort(data.run_index[keep]), np.arange(n)):
        raise ValueError(f"Monte Carlo of {data.method or '?'!r} lacks some of runs 0..{n - 1}")
    calls = np.asarray(data.plan_run) < n
    out = {}
    for k in TRACK_KEYS + ("n_landmarks", "init_error", "run_index"):
        out[k] = np.asarray(getattr(data, k))[keep]
    for k in CALL_KEYS + ("plan_run",):
        out[k] = np.asarray(getattr(data, k))[calls]
    return data.replace(**out)


def per_run_stats(data: MonteCarlo) -> pd.DataFrame:
    """Per run: final and RMS error norms (m, m/s, deg) and mean NEES."""
    import pandas as pd

    rows = {}
    for key, name in (("err_r", "pos_err_m"), ("err_v", "vel_err_mps"), ("err_th_deg", "att_err_deg")):
        nrm = np.linalg.norm(getattr(data, key), axis=2)
        rows[f"final_{name}"] = nrm[:, -1]
        if data.updated is not None:      # at the last vision update (then the IMU-only coast)
            rows[f"lastvis_{name}"] = nrm[np.arange(len(nrm)), last_update_index(data.updated)]
        if data.lm_updated is not None:   # what selection can move: the landmark-tracking phase
            first, last = landmark_phase(data.lm_updated)
            rows[f"lastlm_{name}"] = nrm[np.arange(len(nrm)), last]
            rows[f"lmrms_{name}"] = phase_rms(nrm, first, last)
        rows[f"rms_{name}"] = np.sqrt(np.mean(nrm**2, axis=1))
    rows["mean_nees_pos"] = data.nees_r.mean(axis=1)
    rows["mean_nees_vel"] = data.nees_v.mean(axis=1)
    rows["n_landmarks"] = data.n_landmarks
    return pd.DataFrame(rows, index=pd.Index(data.run_index, name="run"))


def landmark_phase(lm_updated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per run (``lm_updated``: runs x times), the indices of the first and the
    last filter time whose update held a landmark bearing: the landmark-tracking
    phase, the part of the descent a landmark choice can act on (before it the
    initial error, after it the site bearings and the IMU coast). A run with no
    landmark update has the phase (0, 0)."""
    u = np.asarray(lm_updated, bool)
    first = np.where(u.any(axis=-1), np.argmax(u, axis=-1), 0)
    return first, last_update_index(u)


def phase_rms(nrm: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Per run, the RMS of the error norms ``nrm`` (runs x times) over the times
    ``first..last`` (inclusive), same unit as ``nrm``."""
    k = np.arange(nrm.shape[1])[None, :]
    w = (k >= np.asarray(first)[:, None]) & (k <= np.asarray(last)[:, None])
    return np.sqrt((nrm**2 * w).sum(axis=1) / w.sum(axis=1))


def time_below(data: MonteCarlo, threshold_m: float) -> np.ndarray:
    """Per run, the first filter time (s) at which the position error norm is
    below ``threshold_m`` (m); NaN if never. "Converges faster" is a paired
    comparison of these times (``opnav.landing.equivalence.converges_faster``)."""
    below = np.linalg.norm(data.err_r, axis=2) < float(threshold_m)
    t = np.asarray(data.t, float)
    return np.where(below.any(axis=1), t[np.argmax(below, axis=1)], np.nan)


def nees_band(n_runs: int, dof: int = 3, level: float = 0.95) -> tuple[float, float]:
    """Two-sided ``level`` band of the mean of ``n_runs`` independent NEES
    values of a consistent filter (each chi-square with ``dof`` degrees of
    freedom): ``chi2_{n dof}`` quantiles over ``n_runs``."""
    from scipy import special

    v = int(n_runs) * int(dof)
    a = (1.0 - level) / 2.0
    return float(special.chdtri(v, 1.0 - a)) / n_runs, float(special.chdtri(v, a)) / n_runs


@dataclass(frozen=True)
class NeesConsistency:
    """Filter consistency on a Monte Carlo (:func:`nees_consistency`): runs, the band's level and
    the band of an ``n_runs`` mean, and per state (position, velocity) the share of filter times
    whose run mean lies in it (%), its time average and median."""

    n_runs: int
    level: float
    band: tuple[float, float]
    pos_in_band_pct: float
    pos_mean: float
    pos_median: float
    vel_in_band_pct: float
    vel_mean: float
    vel_median: float

    @classmethod
    def from_json(cls, d) -> "NeesConsistency":
        """The record of its JSON object (null read as NaN)."""
        num = lambda v: math.nan if v is None else float(v)  # noqa: E731
        return cls(int(d["n_runs"]), num(d["level"]), tuple(num(x) for x in d["band"]),
                   *(num(d[f"{q}_{k}"]) for q in ("pos", "vel") for k in ("in_band_pct", "mean", "median")))


def nees_consistency(data: MonteCarlo, level: float = 0.95) -> NeesConsistency:
    """Filter consistency on the Monte Carlo (held-out evidence when the tuning
    was chosen on other runs): per state (position, velocity; 3 dof each) the
    NEES averaged over the runs at each filter time after the start, the share
    of those times whose average lies in the :func:`nees_band` of an
    ``n_runs`` mean (%), its time average and median, and the band."""
    n = int(len(data.nees_r))
    lo, hi = nees_band(n, 3, level)
    per = []
    for key in ("nees_r", "nees_v"):
        avg = np.asarray(getattr(data, key), float)[:, 1:].mean(axis=0)
        per += [float(100.0 * np.mean((avg >= lo) & (avg <= hi))), float(avg.mean()), float(np.median(avg))]
    return NeesConsistency(n, float(level), (lo, hi), *per)


def last_update_index(updated: np.ndarray):
    """Index of the last filter time with a vision update (0 if none), per run
    for ``updated`` (runs, times), or an int for one run (times,): after it the
    filter coasts on the IMU to touchdown."""
    u = np.asarray(updated, bool)
    last = u.shape[-1] - 1 - np.argmax(u[..., ::-1], axis=-1)
    out = np.where(u.any(axis=-1), last, 0)
    return int(out) if u.ndim == 1 else out


@dataclass(frozen=True)
class EndPhase:
    """The end of the descent over the runs (:func:`end_phase`; s, m; None: no run has one): the
    runs, the ground and margin altitudes, per kind of update (the last landmark update,
    ``last_lm``; the last vision update, ``last_vis``) its time's median, minimum and maximum and
    the runs that have one, the median gap between the two, the runs updating below the ground
    altitude and below the margin, and the lowest true altitude of a vision update. Fields in
    B-T3 end-phase's column order."""

    n_runs: int
    ground_m: float
    margin_m: float
    last_lm_t_s_median: float | None
    last_lm_t_s_min: float | None
    last_lm_t_s_max: float | None
    last_lm_runs: int
    last_vis_t_s_median: float | None
    last_vis_t_s_min: float | None
    last_vis_t_s_max: float | None
    last_vis_runs: int
    vision_after_last_lm_s_median: float | None
    runs_vision_below_ground_m: int
    runs_vision_below_margin: int
    min_true_alt_vision_m: float | None


def end_phase(data: MonteCarlo, alt_true_m: np.ndarray, margin_m: float, ground_m: float = 1.0) -> EndPhase:
    """The end of the descent counted from the per-step records of ``data`` (gathered
    Monte Carlo: ``t`` (s), ``updated`` and ``lm_updated`` (runs, times)) and the true
    altitude at each filter time ``alt_true_m`` (m; the truth is the same in every run):
    per run the time of its last landmark update and of its last vision update (s; NaN if
    none), summarised by median, minimum and maximum over the runs; the gap between the two
    (s, median); the runs taking a vision update with the true altitude below ``ground_m``
    (1 m: on the ground, to a lander's scale) and below ``margin_m`` (the vision cut-off's
    own margin on the estimated altitude), and the lowest true altitude of a vision update
    (m). The cut-off itself compares the ESTIMATED altitude less the margin
    (``descent.vision_cutoff_altitude``): these counts say what that does in truth."""
    t = np.asarray(data.t, float)
    z = np.asarray(alt_true_m, float)
    upd, lm = np.asarray(data.updated, bool), np.asarray(data.lm_updated, bool)
    if z.shape != t.shape or upd.shape[-1] != t.size:
        raise ValueError(f"end_phase: {t.size} filter times, {z.size} true altitudes, {upd.shape[-1]} records")
    last, per = [], []
    for u in (lm, upd):
        tl = np.where(u.any(axis=1), t[last_update_index(u)], np.nan)
        last.append(tl)
        ok = np.isfinite(tl)
        per += ([float(np.median(tl[ok])), float(tl[ok].min()), float(tl[ok].max())] if ok.any() else [None] * 3)
        per.append(int(ok.sum()))
    gap = last[1] - last[0]
    zu = np.where(upd, z[None, :], np.inf)
    return EndPhase(int(upd.shape[0]), float(ground_m), float(margin_m), *per,
                    vision_after_last_lm_s_median=float(np.nanmedian(gap)) if np.isfinite(gap).any() else None,
                    runs_vision_below_ground_m=int((upd & (z < ground_m)[None, :]).any(axis=1).sum()),
                    runs_vision_below_margin=int((upd & (z < margin_m)[None, :]).any(axis=1).sum()),
                    min_true_alt_vision_m=float(zu.min()) if upd.any() else None)


@dataclass(frozen=True)
class PickQuality:
    """A method's picks (:func:`pick_quality`): the share of calls on the edge of the visible
    interval (%) and the median / max over calls of the picked landmark's metric over the best
    detected one's (1 = best); NaN where not recorded."""

    edge_calls_pct: float = math.nan
    pick_ratio_median: float = math.nan
    pick_ratio_max: float = math.nan


def pick_quality(d: MonteCarlo) -> PickQuality:
    """Per method: share of planning calls whose in-plane optimum fell on an end
    of the visible interval (edge rule, %), and the median / max over calls of
    the picked landmark's metric over the best detected landmark's (1 = best)."""
    edge = float(100.0 * np.mean(d.plan_edge)) if d.plan_edge is not None and len(d.plan_edge) else math.nan
    r = np.asarray(d.plan_ratio if d.plan_ratio is not None else [], float)
    r = r[np.isfinite(r)]
    if r.size:
        return PickQuality(edge, float(np.median(r)), float(r.max()))
    return PickQuality(edge)


def same_pick_pct(a: MonteCarlo, b: MonteCarlo) -> float:
    """Percentage of planning calls (matched by run and time) at which two
    methods chose the same landmark."""
    ka = {(int(r), float(t)): int(i) for r, t, i in zip(a.plan_run, a.plan_t, a.plan_index)}
    kb = {(int(r), float(t)): int(i) for r, t, i in zip(b.plan_run, b.plan_t, b.plan_index)}
    common = set(ka) & set(kb)
    if not common:
        return math.nan
    return 100.0 * sum(ka[k] == kb[k] for k in common) / len(common)


@dataclass(frozen=True)
class YawConvergence:
    """The yaw claim's numbers (:func:`yaw_convergence`): the Monte-Carlo 3-sigma of the yaw
    error at the start and at touchdown (deg) over ``n_runs`` runs of ``method``, the ratio the
    reading used and whether the envelope fell below it (``converges``). Its words are the
    report layer's (``opnav.report.landing.summary.yaw_reason``)."""

    converges: bool
    n_runs: int
    method: str
    sigma3_start_deg: float
    sigma3_end_deg: float
    ratio: float


def yaw_convergence(data: MonteCarlo, ratio: float, method: str) -> YawConvergence:
    """Does the Monte-Carlo 3-sigma envelope of the yaw error shrink (paper B: it
    does not, one known landmark leaves yaw unobservable)? Converging means the
    3-sigma at touchdown is below ``ratio`` times the one at the start (deg)."""
    yaw = data.err_rpy_deg[:, :, 2]
    s_first, s_last = float(3 * yaw[:, 0].std(ddof=1)), float(3 * yaw[:, -1].std(ddof=1))
    return YawConvergence(bool(s_last < ratio * s_first), int(yaw.shape[0]), str(method), s_first, s_last,
                          float(ratio))
