"""Readers of a planning-time replay (``opnav.landing.timing.replay``): which calls each
variant was timed on, its times, medians and evaluations, depth's time reduction against
another method with its paired cluster-bootstrap interval over the replayed calls, the
clock's share of the timed brackets, and the sentence and table stating how the times were
measured (B-T3, B-F7, B-X1, the summary and the manuscript read these).

A replay is the dict :func:`opnav.landing.timing.replay` returns (or ``timing.load``
reads); the measurement itself and its rules live in :mod:`opnav.landing.timing`. Times are
ns in the arrays, us in what these return.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["clock_share", "per_run_median_us", "variant_index", "timed", "times_ns", "timed_calls", "median_evals", "median_us", "time_reduction", "time_reduction_interval", "VS_DEPTH", "vs_depth", "less_time_text", "method_summary", "method_text", "summary_frame"]


def variant_index(tm: dict, method: str, path: str) -> int | None:
    vm, vp = [str(x) for x in tm["variant_method"]], [str(x) for x in tm["variant_path"]]
    for j, (m, p) in enumerate(zip(vm, vp)):
        if m == method and p == path:
            return j
    return None


def timed(tm: dict) -> np.ndarray:
    """``(calls, variants)``: whether the replay ran that variant on that call
    (false for the paper path's calls outside its subset; a replay saved before
    the flag: every entry with a time >= 0)."""
    if "timed" in tm:
        return np.asarray(tm["timed"], bool)
    return np.asarray(tm["wall_ns"]) >= 0


def times_ns(tm: dict, method: str, path: str = "main", clock: str = "wall") -> np.ndarray:
    """The planning times (ns) of ``method`` on ``path`` (``"main"`` /
    ``"alt"``) by ``clock`` (``"wall"``: perf_counter, ``"cpu"``: thread CPU),
    one per replayed call timed on that variant (:func:`timed`), in replay
    order; empty if that variant was not timed."""
    if clock not in ("wall", "cpu"):
        raise ValueError(f"clock must be 'wall' or 'cpu', got {clock!r}")
    j = variant_index(tm, method, path)
    if j is None:
        return np.zeros(0, np.int64)
    return np.asarray(tm[f"{clock}_ns"])[timed(tm)[:, j], j]


def timed_calls(tm: dict, method: str, path: str = "main") -> int:
    """Replayed calls timed on ``method``'s ``path`` variant (0 if none)."""
    j = variant_index(tm, method, path)
    return 0 if j is None else int(np.sum(timed(tm)[:, j]))


def median_evals(tm: dict, method: str, path: str = "main") -> float:
    """Median objective evaluations per timed replayed call (nan if none)."""
    j = variant_index(tm, method, path)
    if j is None:
        return math.nan
    ev = np.asarray(tm["n_evals"])[timed(tm)[:, j], j]
    return float(np.median(ev)) if ev.size else math.nan


def median_us(tm: dict, method: str, path: str = "main", clock: str = "wall") -> float:
    """Median planning time (us) over the replayed calls (nan if none)."""
    t = times_ns(tm, method, path, clock)
    return float(np.median(t) / 1e3) if t.size else math.nan


def _reductions(tm: dict, a: str, b: str, clock: str, path_a: str, path_b: str, n_boot: int,
                seed: int) -> tuple[float, np.ndarray]:
    """(reduction %, its bootstrap replicates) of :func:`time_reduction`."""
    if clock not in ("wall", "cpu"):
        raise ValueError(f"clock must be 'wall' or 'cpu', got {clock!r}")
    ja, jb = variant_index(tm, a, path_a), variant_index(tm, b, path_b)
    if ja is None or jb is None:
        return math.nan, np.zeros(0)
    both = timed(tm)[:, ja] & timed(tm)[:, jb]
    if not both.any():
        return math.nan, np.zeros(0)
    t = np.asarray(tm[f"{clock}_ns"])[both]
    ta, tb = t[:, ja], t[:, jb]
    red = 100.0 * (1.0 - float(np.median(ta)) / float(np.median(tb)))
    key = (np.asarray(tm["source"]) * (1 << 32) + np.asarray(tm["run"]))[both]
    clusters, inv = np.unique(key, return_inverse=True)
    if len(clusters) < 2 or n_boot < 2:
        return red, np.zeros(0)
    rng = np.random.default_rng(seed)
    members = [np.flatnonzero(inv == c) for c in range(len(clusters))]
    vals = np.empty(n_boot)
    for i in range(n_boot):
        idx = np.concatenate([members[c] for c in rng.integers(len(clusters), size=len(clusters))])
        vals[i] = 100.0 * (1.0 - np.median(ta[idx]) / np.median(tb[idx]))
    return red, vals


def time_reduction(tm: dict, a: str, b: str, *, clock: str = "wall", path_a: str = "main",
                   path_b: str = "main", n_boot: int = 200, seed: int = 0) -> tuple[float, float]:
    """``100 (1 - median_a / median_b)`` (%) of the planning times of methods
    ``a`` (on ``path_a``) and ``b`` (``path_b``) on the same replayed calls (those
    timed on both variants: the paper path's subset when either is on it), and
    its bootstrap standard deviation: clusters (source Monte Carlo, run)
    resampled with replacement, both methods from the same resample (paired).
    ``nan`` if a variant is missing or no call was timed on both; the spread is
    ``nan`` below two clusters or two resamples."""
    red, vals = _reductions(tm, a, b, clock, path_a, path_b, n_boot, seed)
    return red, (float(np.std(vals, ddof=1)) if vals.size >= 2 else math.nan)


def time_reduction_interval(tm: dict, a: str, b: str, *, clock: str = "cpu", path_a: str = "main",
                            path_b: str = "main", n_boot: int = 1000, seed: int = 0,
                            level: float = 0.95) -> tuple[float, float, float]:
    """(reduction %, lo, hi): :func:`time_reduction` with its ``level`` percentile interval over
    the same paired cluster bootstrap of the replayed calls (nan where it has none)."""
    red, vals = _reductions(tm, a, b, clock, path_a, path_b, n_boot, seed)
    if vals.size < 2:
        return red, math.nan, math.nan
    q = 100.0 * (1.0 - level) / 2.0
    lo, hi = np.percentile(vals, [q, 100.0 - q])
    return red, float(lo), float(hi)


#: the planning-time comparisons with depth the summary reports (B-C4): (method, path, label)
VS_DEPTH = (("svd", "main", "svd_closed_form"), ("svd_lapack", "main", "svd_lapack"),
            ("svd", "alt", "svd_paper"), ("gdop", "main", "gdop"), ("cond", "main", "cond"))


def vs_depth(tm: dict, clock: str = "cpu") -> dict:
    """Depth's planning time against each of :data:`VS_DEPTH` timed in ``tm``: per label the
    median call (us) of both on the calls timed on both, and depth's reduction (%) with its
    95 % paired bootstrap interval over the replayed calls (clusters by run); depth on the
    same path as the baseline (the paper path against svd's paper path)."""
    out = {}
    for m, path, label in VS_DEPTH:
        if variant_index(tm, m, path) is None or variant_index(tm, "depth", path) is None:
            continue
        red, lo, hi = time_reduction_interval(tm, "depth", m, clock=clock, path_a=path, path_b=path)
        out[label] = {"method": m, "path": path, "depth_median_us": median_us(tm, "depth", path, clock=clock),
                      "median_us": median_us(tm, m, path, clock=clock), "depth_reduction_pct": red,
                      "depth_reduction_lo_pct": lo, "depth_reduction_hi_pct": hi}
    return out


def less_time_text(reduction_pct: float) -> str:
    """A :func:`time_reduction` in words: ``"34.2 % less"``, a negative one ``"137.4 % more"``
    (not "-137.4 % less"); ``"n/a"`` if it is nan."""
    if not math.isfinite(reduction_pct):
        return "n/a"
    return f"{reduction_pct:.1f} % less" if reduction_pct >= 0 else f"{-reduction_pct:.1f} % more"


def method_summary(tm: dict) -> dict:
    """The replay's method in numbers (summary JSON, manuscript macros): calls
    replayed and recorded, ``max_calls``, the calls the paper's definition was
    timed on (``timed_calls_paper``, 0 if not timed) and ``max_calls_paper``,
    methods timed, own calls checked and pick mismatches."""
    return {"method": "replay", "timed_calls": int(len(tm["source"])), "recorded_calls": int(tm["n_pool"]),
            "max_calls": int(tm["max_calls"]), "all_calls": bool(len(tm["source"]) == int(tm["n_pool"])),
            "timed_calls_paper": _paper_calls(tm), "max_calls_paper": int(tm.get("max_calls_paper", 0)),
            "n_methods": int(len(tm["methods"])), "checked_calls": int(np.sum(tm["checked"])),
            "pick_mismatches": int(np.sum(tm["mismatch"])),
            "sources_text": ", ".join(str(x) for x in tm["sources"]), "clock": clock_share(tm)}


def _paper_calls(tm: dict) -> int:
    """Replayed calls on which the paper's definition was timed (on whichever
    path it is; 0 if it was not timed)."""
    paper = np.asarray(tm["variant_eval_path"]).astype(str) == "paper"
    return int(np.sum(timed(tm)[:, paper].any(axis=1))) if paper.any() else 0


def method_text(tm: dict) -> str:
    """One sentence stating how the times were measured (captions, paper)."""
    n, pool = len(tm["source"]), int(tm["n_pool"])
    srcs = ", ".join(str(x) for x in tm["sources"])
    subset = (f"all {pool} recorded planning calls" if n == pool else
              f"{n} of the {pool} recorded planning calls (every {pool / n:.1f}th by index, "
              f"landing.timing.max_calls = {int(tm['max_calls'])})")
    mis = int(np.sum(tm["mismatch"]))
    npaper = _paper_calls(tm)
    paper = ("" if npaper in (0, n) else
             f"; the paper's definition (interpreted, CasADi H) on {npaper} of them, evenly spaced "
             f"(landing.timing.max_calls_paper = {int(tm.get('max_calls_paper', 0))}), its medians "
             "and its comparisons on those calls")
    cs = clock_share(tm)
    clock = ("" if cs["share_pct_max"] is None else
             f" Each call is timed as the mean of back-to-back repetitions (a doubling count, "
             f"{cs['reps_min']} to {cs['reps_max']}) until the clock's own cost "
             f"({cs['clock_ns']:.0f} ns a bracket, measured) is below 5 % of the bracket: "
             f"{cs['share_pct_median']:.2f} % median, {cs['share_pct_max']:.2f} % at most.")
    load = ("" if "load_avg" not in tm else
            " The machine's 1-minute load average was {:.1f} at the start and {:.1f} at the end of the "
            "replay ({} cores): other processes sharing the cores lengthen microsecond calls and "
            "narrow their differences, so timing readings compare between builds at a like load."
            .format(*np.asarray(tm["load_avg"], float)[:2], int(tm.get("n_cpu", 0))))
    return (f"Planning times by replay: {subset} of the Monte Carlo of {srcs} replayed through "
            "every method's planning call, one call at a time, interleaved across methods in one "
            f"process (order rotated per call), the same states for every method{paper}; wall clock "
            "perf_counter_ns, CPU clock thread_time_ns; replayed picks equal to the recorded ones "
            f"in {int(np.sum(tm['checked'])) - mis} of {int(np.sum(tm['checked']))} own calls." + clock + load)


def summary_frame(tm: dict):
    """One row per timed variant: method, path, evaluation path, calls timed on
    it (:func:`timed`), median and 5-95 % quantiles of the wall and CPU times
    (us) and median evaluations over those calls; the method's own-call check
    (checked, mismatch) on its main row."""
    import pandas as pd

    methods = [str(m) for m in tm["methods"]]
    ok = timed(tm)
    rows = []
    for j, (m, p, e) in enumerate(zip(tm["variant_method"], tm["variant_path"], tm["variant_eval_path"])):
        w, c = np.asarray(tm["wall_ns"])[ok[:, j], j] / 1e3, np.asarray(tm["cpu_ns"])[ok[:, j], j] / 1e3
        row = {"method": str(m), "path": str(p), "eval_path": str(e), "calls": int(len(w))}
        for name, x in (("wall", w), ("cpu", c)):
            q = np.quantile(x, [0.05, 0.5, 0.95]) if len(x) else [math.nan] * 3
            row.update({f"{name}_median_us": float(q[1]), f"{name}_p05_us": float(q[0]),
                        f"{name}_p95_us": float(q[2])})
        row["median_evals"] = median_evals(tm, str(m), str(p))
        if str(p) == "main":
            i = methods.index(str(m))
            row["checked"], row["mismatch"] = int(tm["checked"][i]), int(tm["mismatch"][i])
        rows.append(row)
    return pd.DataFrame(rows)


def clock_share(tm: dict) -> dict:
    """The clock's measured cost (ns) and its share of the timed brackets (%, ``clock / (reps x
    call)``): median and maximum over the timed cells, and the repetition counts' range."""
    reps = np.asarray(tm.get("reps", []))
    ok = timed(tm) & (reps > 0) if reps.size else np.zeros(0, bool)
    if not ok.any():
        return {"clock_ns": float(tm.get("clock_ns", math.nan)), "share_pct_median": None,
                "share_pct_max": None, "reps_min": None, "reps_max": None}
    cpu = np.maximum(np.asarray(tm["cpu_ns"])[ok], 1)
    share = 100.0 * float(tm["clock_ns"]) / (reps[ok] * cpu)
    return {"clock_ns": float(tm["clock_ns"]), "share_pct_median": float(np.median(share)),
            "share_pct_max": float(share.max()), "reps_min": int(reps[ok].min()), "reps_max": int(reps[ok].max())}


def per_run_median_us(tm: dict, method: str, clock: str = "wall", path: str = "main") -> dict[int, float]:
    """Median replayed planning time (us) per run (the run of the recorded call),
    over the calls timed on ``path``."""
    t = times_ns(tm, method, path, clock)
    j = variant_index(tm, method, path)
    run = np.asarray(tm["run"])[timed(tm)[:, j]] if j is not None else np.zeros(0, np.int64)
    return {int(r): float(np.median(t[run == r]) / 1e3) for r in np.unique(run)}
