"""Readers of a planning-time replay (``opnav.landing.timing.replay``): which calls each
variant was timed on, its times, medians and evaluations, depth's time reduction against
another method with its paired cluster-bootstrap interval over the replayed calls, the
clock's share of the timed brackets, and the sentence and table stating how the times were
measured (B-T3, B-F7, B-X1, the summary and the manuscript read these).

A replay is the record :func:`opnav.landing.timing.replay` returns (or ``timing.load``
reads; ``opnav.landing.records.Replay``); the measurement itself and its rules live in
:mod:`opnav.landing.timing`. Times are ns in the arrays, us in what these return. What they
return are typed records (:class:`ClockShare`, :class:`VsDepthReading`, :class:`MethodSummary`,
:class:`Between`, :class:`CallParts`, :class:`PlanningTimeEvidence`); the summary job writes them
into B-summary.json with their fields as keys (``core.tables.json_ready``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from opnav.core.tables import OMIT_NONE
from opnav.landing.records import Replay

#: The one clock of every planning time the pipeline reports (verdict inputs, tables, macros,
#: figures and text): the calling thread's CPU time (``time.thread_time_ns``; ``cpu_ns`` in a
#: replay), which other processes' work does not add to. The replay also records the wall clock
#: (``wall_ns``, perf_counter_ns) for diagnosis; nothing reported reads it unless asked by name.
CLOCK = "cpu"
#: :data:`CLOCK` as the evidence names it (``planning_time_evidence``'s ``clock``; in words:
#: ``opnav.report.landing.timing_text.CLOCK_WORDS``)
CLOCK_NAME = "thread_cpu"

__all__ = ["clock_share", "per_run_median_us", "variant_index", "timed", "times_ns", "timed_calls", "median_evals", "median_us", "time_reduction", "time_reduction_interval", "VS_DEPTH", "vs_depth", "method_summary", "paper_calls",
           "CLOCK", "CLOCK_NAME", "n_replays", "replay_calls", "replay_ids", "one_replay",
           "replayed_methods", "BETWEEN_LEVEL", "between", "median_interval", "decomposition", "reduction_at", "shared_at",
           "planning_time_evidence", "cell_times_ns", "ClockShare", "VsDepthReading", "MethodSummary", "Between", "CallParts",
           "PooledCallParts", "ReplayReading", "OverheadCurve", "PlanningTimeEvidence"]


def cell_times_ns(tm: Replay, clock: str) -> np.ndarray:
    """The per-cell times (ns) of ``clock`` (``"cpu"``: thread CPU, ``"wall"``: perf_counter)."""
    return tm.cpu_ns if clock == "cpu" else tm.wall_ns


def variant_index(tm: Replay, method: str, path: str) -> int | None:
    vm, vp = [str(x) for x in tm.variant_method], [str(x) for x in tm.variant_path]
    for j, (m, p) in enumerate(zip(vm, vp)):
        if m == method and p == path:
            return j
    return None


def timed(tm: Replay) -> np.ndarray:
    """``(calls, variants)``: whether the replay ran that variant on that call
    (false for the paper path's calls outside its subset; a replay saved before
    the flag: every entry with a time >= 0)."""
    if tm.timed is not None:
        return np.asarray(tm.timed, bool)
    return np.asarray(tm.wall_ns) >= 0


def times_ns(tm: Replay, method: str, path: str = "main", clock: str = CLOCK) -> np.ndarray:
    """The planning times (ns) of ``method`` on ``path`` (``"main"`` /
    ``"alt"``) by ``clock`` (:data:`CLOCK`, thread CPU; ``"wall"``: perf_counter, diagnosis only),
    one per replayed call timed on that variant (:func:`timed`), in replay
    order; empty if that variant was not timed."""
    if clock not in ("wall", "cpu"):
        raise ValueError(f"clock must be 'wall' or 'cpu', got {clock!r}")
    j = variant_index(tm, method, path)
    if j is None:
        return np.zeros(0, np.int64)
    return np.asarray(cell_times_ns(tm, clock))[timed(tm)[:, j], j]


def timed_calls(tm: Replay, method: str, path: str = "main") -> int:
    """Replayed calls timed on ``method``'s ``path`` variant (0 if none)."""
    j = variant_index(tm, method, path)
    return 0 if j is None else int(np.sum(timed(tm)[:, j]))


def median_evals(tm: Replay, method: str, path: str = "main") -> float:
    """Median objective evaluations per timed replayed call (nan if none)."""
    j = variant_index(tm, method, path)
    if j is None:
        return math.nan
    ev = np.asarray(tm.n_evals)[timed(tm)[:, j], j]
    return float(np.median(ev)) if ev.size else math.nan


def median_us(tm: Replay, method: str, path: str = "main", clock: str = CLOCK) -> float:
    """Median planning time (us) over the replayed calls (nan if none)."""
    t = times_ns(tm, method, path, clock)
    return float(np.median(t) / 1e3) if t.size else math.nan


def _reductions(tm: Replay, a: str, b: str, clock: str, path_a: str, path_b: str, n_boot: int,
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
    t = np.asarray(cell_times_ns(tm, clock))[both]
    ta, tb = t[:, ja], t[:, jb]
    red = 100.0 * (1.0 - float(np.median(ta)) / float(np.median(tb)))
    key = (np.asarray(tm.source) * (1 << 32) + np.asarray(tm.run))[both]
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


def time_reduction(tm: Replay, a: str, b: str, *, clock: str = CLOCK, path_a: str = "main",
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


def time_reduction_interval(tm: Replay, a: str, b: str, *, clock: str = CLOCK, path_a: str = "main",
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


@dataclass(frozen=True)
class VsDepthReading:
    """Depth against one baseline in one replay (:func:`vs_depth`): the baseline ``method`` and
    ``path``, the median call (us) of both on the calls timed on both, and depth's reduction (%)
    with its paired bootstrap interval."""

    method: str
    path: str
    depth_median_us: float
    median_us: float
    depth_reduction_pct: float
    depth_reduction_lo_pct: float
    depth_reduction_hi_pct: float


def vs_depth(tm: Replay, clock: str = CLOCK) -> dict[str, VsDepthReading]:
    """Depth's planning time against each of :data:`VS_DEPTH` timed in ``tm``: per label the
    median call (us) of both on the calls timed on both, and depth's reduction (%) with its
    95 % paired bootstrap interval over the replayed calls (clusters by run); depth on the
    same path as the baseline (the paper path against svd's paper path)."""
    out = {}
    for m, path, label in VS_DEPTH:
        if variant_index(tm, m, path) is None or variant_index(tm, "depth", path) is None:
            continue
        red, lo, hi = time_reduction_interval(tm, "depth", m, clock=clock, path_a=path, path_b=path)
        out[label] = VsDepthReading(m, path, median_us(tm, "depth", path, clock=clock),
                                    median_us(tm, m, path, clock=clock), red, lo, hi)
    return out


def n_replays(tm: Replay) -> int:
    """Independent replays (separate processes) merged in ``tm`` (``timing.merge``; 1 for one
    replay)."""
    return int(tm.n_replays) if tm.n_replays is not None else 1


def replay_calls(tm: Replay) -> int:
    """Distinct replayed calls (each replay times the same ones)."""
    return int(len(tm.source)) // max(n_replays(tm), 1)


@dataclass(frozen=True)
class ClockShare:
    """The clock's measured cost (ns; the largest over the merged replays) and its share of the
    timed brackets (%): median and maximum over the timed cells, and the repetition counts'
    range (None: no repetitions recorded)."""

    clock_ns: float
    share_pct_median: float | None = None
    share_pct_max: float | None = None
    reps_min: int | None = None
    reps_max: int | None = None


@dataclass(frozen=True)
class MethodSummary:
    """The replay's method in numbers (:func:`method_summary`; B-summary ``timing``)."""

    method: str
    timed_calls: int
    recorded_calls: int
    max_calls: int
    all_calls: bool
    timed_calls_paper: int
    max_calls_paper: int
    n_methods: int
    checked_calls: int
    pick_mismatches: int
    n_replays: int
    clock_name: str
    sources: tuple[str, ...]
    clock: ClockShare


def method_summary(tm: Replay) -> MethodSummary:
    """The replay's method in numbers (summary JSON, manuscript macros): calls
    replayed and recorded, ``max_calls``, the calls the paper's definition was
    timed on (``timed_calls_paper``, 0 if not timed) and ``max_calls_paper``,
    methods timed, own calls checked and pick mismatches, the independent replays
    (``n_replays``), the clock (:data:`CLOCK_NAME`), the methods whose calls were replayed
    (``sources``) and the clock's share (:func:`clock_share`)."""
    n = replay_calls(tm)
    return MethodSummary(method="replay", timed_calls=n, recorded_calls=int(tm.n_pool),
                         max_calls=int(tm.max_calls), all_calls=bool(n == int(tm.n_pool)),
                         timed_calls_paper=paper_calls(tm),
                         max_calls_paper=int(tm.max_calls_paper) if tm.max_calls_paper is not None else 0,
                         n_methods=int(len(tm.methods)), checked_calls=int(np.sum(tm.checked)),
                         pick_mismatches=int(np.sum(tm.mismatch)), n_replays=n_replays(tm),
                         clock_name=CLOCK_NAME, sources=tuple(str(x) for x in tm.sources), clock=clock_share(tm))


def paper_calls(tm: Replay) -> int:
    """Replayed calls on which the paper's definition was timed (on whichever
    path it is; 0 if it was not timed)."""
    paper = np.asarray(tm.variant_eval_path).astype(str) == "paper"
    return int(np.sum(timed(tm)[:, paper].any(axis=1))) if paper.any() else 0


def clock_share(tm: Replay) -> ClockShare:
    """The clock's measured cost (ns; the largest over the merged replays) and its share of the
    timed brackets (%, ``clock / (reps x call)``, each bracket's own replay's clock): median and
    maximum over the timed cells, and the repetition counts' range."""
    reps = np.asarray(tm.reps if tm.reps is not None else [])
    ok = timed(tm) & (reps > 0) if reps.size else np.zeros(0, bool)
    if not ok.any():
        return ClockShare(float(tm.clock_ns) if tm.clock_ns is not None else math.nan)
    cpu = np.maximum(np.asarray(tm.cpu_ns), 1)
    row_clock = np.asarray(tm.row_clock_ns if tm.row_clock_ns is not None
                           else np.full(len(cpu), float(tm.clock_ns)), float)
    share = 100.0 * (row_clock[:, None] / (reps * cpu))[ok]
    return ClockShare(float(tm.clock_ns), float(np.median(share)), float(share.max()), int(reps[ok].min()),
                      int(reps[ok].max()))


def per_run_median_us(tm: Replay, method: str, clock: str = CLOCK, path: str = "main") -> dict[int, float]:
    """Median replayed planning time (us) per run (the run of the recorded call),
    over the calls timed on ``path``."""
    t = times_ns(tm, method, path, clock)
    j = variant_index(tm, method, path)
    run = np.asarray(tm.run)[timed(tm)[:, j]] if j is not None else np.zeros(0, np.int64)
    return {int(r): float(np.median(t[run == r]) / 1e3) for r in np.unique(run)}


# ------------------------------------------------------------ independent replays (issue 53)

def replay_ids(tm: Replay) -> list[int]:
    """The replays merged in ``tm`` (``timing.merge``: ``replay`` per row; [0] for one replay)."""
    return sorted(int(r) for r in np.unique(tm.replay)) if tm.replay is not None else [0]


def one_replay(tm: Replay, r: int) -> Replay:
    """Replay ``r``'s rows of a merged ``tm`` as one replay (every variant; those timed on replay
    0's rows only are untimed in the others)."""
    import dataclasses

    if tm.replay is None:
        return tm
    rows = np.asarray(tm.replay) == r
    out = {}
    for f in dataclasses.fields(tm):
        k, v = f.name, getattr(tm, f.name)
        if v is None:
            continue
        a = np.asarray(v)
        if a.ndim >= 1 and a.shape[0] == rows.size and k not in ("methods", "sources", "mismatch", "checked") \
                and not k.startswith("variant_") and not k.startswith("replay_"):
            out[k] = a[rows]
    out["n_replays"] = 1
    out["clock_ns"] = float(np.asarray(tm.replay_clock_ns if tm.replay_clock_ns is not None else [tm.clock_ns])[r])
    return tm.replace(**out)


def replayed_methods(tm: Replay, path: str = "main") -> list[str]:
    """Methods whose ``path`` variant is timed in every replay of ``tm`` (the ones a timing claim
    can be judged on between replays), in variant order."""
    ok = timed(tm)
    rid = np.asarray(tm.replay) if tm.replay is not None else np.zeros(len(ok), np.int64)
    out = []
    for j, (m, p) in enumerate(zip(tm.variant_method, tm.variant_path)):
        if str(p) == path and all(ok[rid == r, j].any() for r in replay_ids(tm)):
            out.append(str(m))
    return out


#: interval level of the between-replay intervals (mean +- t sd / sqrt(n))
BETWEEN_LEVEL = 0.95


@dataclass(frozen=True)
class Between:
    """Per-replay readings and their mean, sample standard deviation (ddof 1) and Student-t
    interval at ``level`` (:func:`between`); in the evidence also how the interval was made
    (``interval``: ``between_replays``, or ``bootstrap`` over one replay's calls, with its
    ``path`` and the calls timed on both, ``n_calls``). None: not part of this reading."""

    per_replay: list[float]
    mean: float
    sd_between: float
    lo: float
    hi: float
    level: float
    interval: str | None = field(default=None, metadata=OMIT_NONE)
    path: str | None = field(default=None, metadata=OMIT_NONE)
    n_calls: int | None = field(default=None, metadata=OMIT_NONE)

    def replace(self, **changes) -> "Between":
        import dataclasses

        return dataclasses.replace(self, **changes)


def between(values, level: float = BETWEEN_LEVEL) -> Between:
    """``per_replay``, ``mean``, ``sd_between``, ``lo``, ``hi``, ``level`` of per-replay readings:
    their mean, sample standard deviation (ddof 1) and the Student-t interval of the mean at
    ``level`` over the replays (nan below two finite readings)."""
    from scipy import stats

    v = [float(x) for x in values]
    f = np.array([x for x in v if math.isfinite(x)])
    mean = float(f.mean()) if f.size else math.nan
    if f.size >= 2:
        sd = float(f.std(ddof=1))
        h = float(stats.t.ppf(0.5 + level / 2.0, f.size - 1)) * sd / math.sqrt(f.size)
        lo, hi = mean - h, mean + h
    else:
        sd = lo = hi = math.nan
    return Between(v, mean, sd, lo, hi, float(level))


def median_interval(x, level: float = BETWEEN_LEVEL) -> tuple[float, float]:
    """Distribution-free interval of a median (the order statistics ``k`` and ``n + 1 - k`` with
    ``k`` the largest count a Binomial(n, 1/2) stays below with probability ``(1 - level) / 2``:
    covers the median with at least ``level``); (nan, nan) below 6 values."""
    from scipy import stats

    v = np.sort(np.asarray(x, float))
    n = v.size
    k = int(stats.binom.ppf((1.0 - level) / 2.0, n, 0.5)) if n else 0
    if n < 6 or k < 1:
        return math.nan, math.nan
    return float(v[k - 1]), float(v[n - k])


_NAN = math.nan


@dataclass(frozen=True)
class CallParts:
    """A compiled call's two parts for one method (:func:`decomposition`; us, :data:`CLOCK`): the
    median shared part, the median call's evaluations, one evaluation, evaluations per call
    (median), the calls, and the least-squares line's shared part and per-evaluation cost."""

    shared_us: float = _NAN
    eval_us: float = _NAN
    per_eval_us: float = _NAN
    evals_per_call: float = _NAN
    n_calls: int = 0
    fit_shared_us: float = _NAN
    fit_per_eval_us: float = _NAN


#: the :class:`CallParts` numbers averaged over replays (:class:`PooledCallParts`)
_PARTS = ("shared_us", "eval_us", "per_eval_us", "evals_per_call", "fit_shared_us", "fit_per_eval_us")


@dataclass(frozen=True, kw_only=True)
class PooledCallParts(CallParts):
    """:class:`CallParts` over independent replays: each number the mean over the replays (NaN
    where none is finite), the calls summed, and each replay's shared part and evaluations."""

    shared_us_per_replay: list[float]
    eval_us_per_replay: list[float]


def decomposition(tm: Replay, method: str, path: str = "main") -> CallParts:
    """A compiled planning call = its shared part + evaluations x cost of one (one replay's calls
    of ``method`` whose evaluations were timed alone, ``timing.replay(decompose=True)``):
    ``shared_us`` the median over calls of call minus its evaluations (numba's dispatch, argument
    unpacking, the plane, the visible interval, the searches' and the edge rule's own steps),
    ``eval_us`` the median call's evaluations, ``per_eval_us`` one evaluation (all calls'
    evaluation time over their evaluations), ``evals_per_call`` (median), ``n_calls``; and, as a
    check by another route, the least-squares line of call time on evaluation count over the
    same calls (``fit_shared_us``, ``fit_per_eval_us``: nan below 10 calls or a count sd below 1).
    Times in us, :data:`CLOCK`."""
    j = variant_index(tm, method, path)
    if j is None or tm.eval_ns is None:
        return CallParts()
    ev = np.asarray(tm.eval_ns)[:, j]
    ok = timed(tm)[:, j] & (ev >= 0)
    if not ok.any():
        return CallParts()
    call = np.asarray(cell_times_ns(tm, CLOCK))[ok, j].astype(float) / 1e3
    e = ev[ok].astype(float) / 1e3
    n = np.asarray(tm.n_evals)[ok, j].astype(float)
    fit_s = fit_e = math.nan
    if n.size >= 10 and np.std(n) >= 1.0:      # counts that vary: the line is defined
        fit_e, fit_s = (float(x) for x in np.polyfit(n, call, 1))
    return CallParts(shared_us=float(np.median(call - e)), eval_us=float(np.median(e)),
                     per_eval_us=float(e.sum() / n.sum()) if n.sum() > 0 else math.nan,
                     evals_per_call=float(np.median(n)), n_calls=int(ok.sum()),
                     fit_shared_us=fit_s, fit_per_eval_us=fit_e)


def reduction_at(shared_us, eval_a_us: float, eval_b_us: float):
    """Method a's time reduction against b (%) when both calls share ``shared_us`` (us, scalar
    or array) beside their own evaluations ``eval_a_us``, ``eval_b_us``: ``100 (1 - (S + E_a) /
    (S + E_b))``."""
    s = np.asarray(shared_us, float)
    return 100.0 * (1.0 - (s + eval_a_us) / (s + eval_b_us))


def shared_at(reduction_pct: float, eval_a_us: float, eval_b_us: float) -> float:
    """The shared part (us) at which :func:`reduction_at` equals ``reduction_pct``:
    ``S = ((1 - p) E_b - E_a) / p``; nan where no shared part >= 0 gives it (the evaluations
    alone give less, or ``p`` <= 0)."""
    p = float(reduction_pct) / 100.0
    if not (p > 0 and math.isfinite(eval_a_us) and math.isfinite(eval_b_us)):
        return math.nan
    s = ((1.0 - p) * eval_b_us - eval_a_us) / p
    return float(s) if s >= 0 else math.nan


@dataclass(frozen=True)
class ReplayReading:
    """One independent replay in the evidence: each method's median call (us) and its
    distribution-free interval, the calls, the load average (start, end) and numba's dispatch
    alone (us)."""

    median_us: dict[str, float]
    median_interval_us: dict[str, list[float]]
    n_calls: int
    load_avg: list[float]
    dispatch_us: float


@dataclass(frozen=True)
class OverheadCurve:
    """Method ``a``'s reduction against ``b`` (%) as a function of the shared part (us), each
    replay's reading at its own shared part, and (where both unshared parts are positive) the mean
    shared part, the unshared parts and the reduction without a shared part (None: not drawn)."""

    a: str
    b: str
    shared_us: list[float] = field(default_factory=list)
    reduction_pct: list[float] = field(default_factory=list)
    replay_shared_us: list[float] = field(default_factory=list)
    replay_reduction_pct: list[float] = field(default_factory=list)
    mean_shared_us: float | None = field(default=None, metadata=OMIT_NONE)
    unshared_a_us: float | None = field(default=None, metadata=OMIT_NONE)
    unshared_b_us: float | None = field(default=None, metadata=OMIT_NONE)
    no_shared_reduction_pct: float | None = field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class PlanningTimeEvidence:
    """The planning-time evidence of one camera scenario (:func:`planning_time_evidence`; B-summary
    ``scenarios.<cam>.planning_time``)."""

    clock: str
    path: str
    eval_path: str
    n_replays: int
    methods: list[str]
    replays: list[ReplayReading]
    reduction_pct: dict[str, Between]
    eval_reduction_pct: dict[str, Between]
    median_us: dict[str, Between]
    decomposition: dict[str, PooledCallParts]
    overhead_curve: OverheadCurve
    shared_us_at_published: float
    published_pct: float


def planning_time_evidence(tm: Replay, published_pct: float, *, a: str = "depth", b: str = "svd",
                           path: str = "main", level: float = BETWEEN_LEVEL, n_curve: int = 21) -> PlanningTimeEvidence:
    """The planning-time evidence of one camera scenario (B-summary ``scenarios.<cam>.planning_time``;
    the timing claims B-C4 and B-C9 read it), from a merged replay (``timing.merge``) on
    :data:`CLOCK`: per independent replay of ``path`` (``replays``: each method's median call,
    calls, the load average, numba's dispatch alone), per pair of replayed methods ``x_vs_y``
    (``x`` before ``y`` in variant order) the reduction ``100 (1 - median_x / median_y)`` per
    replay with its mean, between-replay sd and t interval (:func:`between`), per method its
    median call likewise, per method the call's shared part and evaluations (:func:`decomposition`,
    averaged over the replays, each replay's shared part kept), and for ``a`` against ``b`` the
    reduction as a function of the shared part (``overhead_curve``): each median call is its
    method's unshared part (the median call, mean over replays, less the mean of the two methods'
    shared parts, ``unshared_a_us``, ``unshared_b_us``) plus a shared part ``S`` common to both
    (:func:`reduction_at`; a common added cost shifts a median by itself, so the curve passes
    through the measured mean reduction at the measured shared part), each replay's reading at its
    own shared part beside it, and the ``S`` at which the reduction would equal ``published_pct``
    (``shared_us_at_published``, :func:`shared_at`; nan if none would, not even ``S = 0``).
    ``eval_reduction_pct``: the same pairs on each replay's median evaluations alone (the shared part
    taken out: what the metrics themselves cost), per replay and between replays (full interior,
    200 calls: depth vs SVD 50.9 % sd 0.02; a slow process moves these too, so they explain, they do
    not replace, the reduction the claims read)."""
    ids = replay_ids(tm)
    parts = [one_replay(tm, r) for r in ids]
    methods = replayed_methods(tm, path)
    replays = []
    for r, t in zip(ids, parts):
        ok = timed(t)
        j0 = variant_index(t, methods[0], path) if methods else None
        la = (np.asarray(tm.replay_load_avg, float)[r] if tm.replay_load_avg is not None
              else np.asarray(tm.load_avg if tm.load_avg is not None else [math.nan] * 2, float)[:2])
        disp = (float(np.asarray(tm.replay_dispatch_ns)[r]) if tm.replay_dispatch_ns is not None
                else float(tm.dispatch_ns) if tm.dispatch_ns is not None else math.nan)
        replays.append(ReplayReading(
            median_us={m: median_us(t, m, path) for m in methods},
            median_interval_us={m: [x / 1e3 for x in median_interval(times_ns(t, m, path), level)] for m in methods},
            n_calls=int(ok[:, j0].sum()) if j0 is not None else 0,
            load_avg=[float(x) for x in la], dispatch_us=disp / 1e3))
    reduction: dict[str, Between] = {}
    for i, x in enumerate(methods):
        for y in methods[i + 1:]:
            reduction[f"{x}_vs_{y}"] = between([time_reduction(t, x, y, path_a=path, path_b=path, n_boot=0)[0]
                                                for t in parts], level).replace(interval="between_replays")
    # depth against the baselines timed once (the LAPACK SVD, the paper's definition: the job beside
    # others): one reading, its interval a paired bootstrap over that replay's calls (by run)
    for m, p_, label in VS_DEPTH:
        key = f"{a}_vs_{label}" if label != "svd_closed_form" else None
        pa = p_ if variant_index(tm, a, p_) is not None else path
        if key is None or key in reduction or variant_index(tm, m, p_) is None or variant_index(tm, a, pa) is None:
            continue
        if m in methods and p_ == path:
            continue
        red, lo, hi = time_reduction_interval(tm, a, m, path_a=pa, path_b=p_, level=level)
        reduction[key] = Between([red], red, math.nan, lo, hi, float(level), interval="bootstrap", path=p_,
                                 n_calls=int(np.sum(timed(tm)[:, variant_index(tm, m, p_)]
                                                    & timed(tm)[:, variant_index(tm, a, pa)])))
    med = {m: between([rp.median_us[m] for rp in replays], level) for m in methods}
    dec: dict[str, PooledCallParts] = {}
    for m in methods:
        per = [decomposition(t, m, path) for t in parts]
        pooled = {k: float(np.nanmean([getattr(d, k) for d in per])) if any(math.isfinite(getattr(d, k)) for d in per)
                  else math.nan for k in _PARTS}
        dec[m] = PooledCallParts(**pooled, n_calls=int(sum(d.n_calls for d in per)),
                                 shared_us_per_replay=[d.shared_us for d in per],
                                 eval_us_per_replay=[d.eval_us for d in per])
    curve = OverheadCurve(a, b)
    at_pub = math.nan
    # the same pairs on the calls' evaluations alone (the shared part taken out: what the metrics
    # themselves cost, which a machine's load moves least), per replay and between replays
    eval_red: dict[str, Between] = {}
    for i, x in enumerate(methods):
        for y in methods[i + 1:]:
            ex, ey = dec[x].eval_us_per_replay, dec[y].eval_us_per_replay
            vals = [100.0 * (1.0 - u / w) if (math.isfinite(u) and math.isfinite(w) and w > 0) else math.nan
                    for u, w in zip(ex, ey)]
            if any(math.isfinite(v) for v in vals):
                eval_red[f"{x}_vs_{y}"] = between(vals, level).replace(interval="between_replays")
    rs = ([0.5 * (x + y) for x, y in zip(dec[a].shared_us_per_replay, dec[b].shared_us_per_replay)]
          if a in dec and b in dec else [])
    sbar = float(np.nanmean(rs)) if rs and any(math.isfinite(x) for x in rs) else math.nan
    # the part of the median calls that is not shared (the median call less the mean shared part):
    # medians shift with a common added cost, so the curve passes through the measured reduction
    ea = med[a].mean - sbar if a in med else math.nan
    eb = med[b].mean - sbar if b in med else math.nan
    if math.isfinite(ea) and math.isfinite(eb) and ea > 0 and eb > 0:
        at_pub = shared_at(published_pct, ea, eb)
        top = max([1.0] + [2.0 * x for x in rs if math.isfinite(x)] + ([1.5 * at_pub] if math.isfinite(at_pub) else []))
        grid = np.linspace(0.0, top, int(n_curve))
        ab = reduction.get(f"{a}_vs_{b}")
        curve = OverheadCurve(a, b, shared_us=[float(x) for x in grid],
                              reduction_pct=[float(x) for x in reduction_at(grid, ea, eb)],
                              replay_shared_us=rs, replay_reduction_pct=list(ab.per_replay) if ab else [],
                              mean_shared_us=sbar, unshared_a_us=ea, unshared_b_us=eb,
                              no_shared_reduction_pct=float(reduction_at(0.0, ea, eb)))
    ep = [str(e) for m, p, e in zip(tm.variant_method, tm.variant_path, tm.variant_eval_path) if str(p) == path]
    return PlanningTimeEvidence(clock=CLOCK_NAME, path=path, eval_path=ep[0] if ep else "", n_replays=len(ids),
                                methods=methods, replays=replays, reduction_pct=reduction,
                                eval_reduction_pct=eval_red, median_us=med, decomposition=dec,
                                overhead_curve=curve, shared_us_at_published=at_pub,
                                published_pct=float(published_pct))
