"""Ranking of landmark-planning methods on a paired Monte Carlo (B-X1).

Description
-----------
Every method flies the same runs: run ``i`` uses ``SeedSequence([base_seed,
i])`` for its initial error, IMU and pixel noise (``opnav.landing.descent``),
so per-run differences between two methods remove the run-to-run spread that
the initial errors cause (paired design). For a per-run quantity ``x`` (e.g.
the RMS position error norm, m) and methods ``a``, ``b`` the paired
difference is ``d_i = x_a,i - x_b,i``; :func:`paired_difference` gives its
mean with a two-sided paired-t interval (``mean +- t_{n-1} s_d / sqrt(n)``,
Student's t with ``n - 1`` degrees of freedom) and a percentile bootstrap
interval over runs, the t-test p-value, and the share of runs in which ``a``
is lower. :func:`competition_rank` ranks with ties sharing the best rank
(1, 2, 2, 4); methods that share a rank are listed by name, never by a
timing. :func:`ranking_table` builds the B-X1 table: per method the
accuracy (mean and 3-sigma of final and RMS position and velocity error
norms, NEES, landmarks used, share of planning calls that chose no landmark), planning time (median wall and CPU time of a planning call, us, and
the ratio to the reference's, from the replay of the recorded planning calls,
:mod:`opnav.landing.timing`), ranks by accuracy (mean position error at the
last landmark update, :data:`RANK_BY`; ties share a rank and the headline names
every method of rank 1)
and by time (median CPU time, which other processes on a shared machine do
not inflate), and the paired comparison against the reference method.
All functions are pure (no I/O).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
# Student's t by its special functions (what scipy.stats.t calls, same bits, tested):
# scipy.stats is a heavier import than scipy.special (docs/performance.md).
from scipy import special

from opnav.landing.montecarlo import MonteCarlo, per_run_stats, same_pick_pct
from opnav.landing.records import Replay

from opnav.core.tables import JSON_SKIP, OMIT_NONE

__all__ = ["paired_t_interval", "bootstrap_mean_interval", "paired_difference",
           "competition_rank", "ranking_table", "headline", "median_abs_dbeta_deg",
           "pair_comparison", "pair_table", "PairedDifference", "ErrorDifference", "PairComparison", "Headline"]


@dataclass(frozen=True)
class PairedDifference:
    """A paired comparison of per-run values ``a - b`` (:func:`paired_difference`): the mean, its
    paired-t interval and p-value, the bootstrap interval, the share of runs with ``a < b`` and with
    ``a == b`` (%) and the runs."""

    mean: float
    t_lo: float
    t_hi: float
    p: float
    boot_lo: float
    boot_hi: float
    a_lower_pct: float
    equal_pct: float
    n: int


@dataclass(frozen=True)
class ErrorDifference:
    """One per-run error's paired difference ``a - b`` in a :class:`PairComparison` (m): mean, its
    interval and p-value, and the same relative to b's mean (%)."""

    m: float
    lo_m: float
    hi_m: float
    p: float
    rel_pct: float
    rel_lo_pct: float
    rel_hi_pct: float


@dataclass(frozen=True)
class PairComparison:
    """What a comparison of two methods' accuracy rests on (:func:`pair_comparison`): the same-pick
    rate (%), the median |delta beta*| (deg) and per error (``rms_pos``, ``final_pos``, ``lastlm_pos``,
    ``lmrms_pos``: those the runs record) its :class:`ErrorDifference`."""

    same_pick_pct: float
    median_abs_dbeta_deg: float
    diffs: dict[str, ErrorDifference]

    def columns(self):
        """The comparison as table columns, in order (``same_pick_pct``, ..., ``d_<error>_m``,
        ``d_<error>_lo_m``, ...: B-T3's pairs, ``pair_table``)."""
        yield "same_pick_pct", self.same_pick_pct
        yield "median_abs_dbeta_deg", self.median_abs_dbeta_deg
        for name, d in self.diffs.items():
            yield from ((f"d_{name}_m", d.m), (f"d_{name}_lo_m", d.lo_m), (f"d_{name}_hi_m", d.hi_m),
                        (f"d_{name}_p", d.p), (f"d_{name}_rel_pct", d.rel_pct),
                        (f"d_{name}_rel_lo_pct", d.rel_lo_pct), (f"d_{name}_rel_hi_pct", d.rel_hi_pct))


@dataclass(frozen=True)
class Headline:
    """The headline of a B-X1 ranking (:func:`headline`; B-X1-summary.json): the reference, each
    method's table row by column (NaN as None), the orders by accuracy and by time, the methods of
    accuracy rank 1 (and whether several tie), the fastest, the reference's ranks, methods and runs,
    the methods the reference is shown more / less accurate than or not significantly different
    from, those it is faster than, each searching method's median |beta*| (deg) and the bootstrap
    resamples behind the intervals (set by the caller)."""

    reference: str
    methods: dict[str, dict]
    ranking_by_accuracy: list[str]
    ranking_by_time: list[str]
    best_accuracy_methods: list[str]
    best_accuracy_tie: bool
    fastest_method: str
    reference_rank_accuracy: int
    reference_rank_time: int
    n_methods: int
    n_runs: int
    reference_more_accurate_than: list[str]
    reference_less_accurate_than: list[str]
    not_significant_vs_reference: list[str]
    reference_faster_than: list[str]
    median_abs_beta_deg: dict[str, float] = field(metadata=JSON_SKIP)   # for the words, not the document
    n_boot: int | None = field(default=None, metadata=OMIT_NONE)


def paired_t_interval(d, level: float = 0.95) -> tuple[float, float, float, float]:
    """Mean of the paired differences ``d`` with its two-sided paired-t
    interval at ``level`` and the p-value of ``mean = 0``:
    ``(mean, lo, hi, p)``. Zero spread gives the degenerate interval
    ``(mean, mean)`` with ``p = 1`` if the mean is 0 else ``0``; fewer than two
    differences give NaN bounds."""
    d = np.asarray(d, float).ravel()
    if d.size == 0 or not np.all(np.isfinite(d)):
        raise ValueError("paired_t_interval: need finite paired differences")
    if not 0.0 < level < 1.0:
        raise ValueError(f"paired_t_interval: level must be in (0, 1), got {level}")
    m = float(d.mean())
    n = d.size
    if n < 2:
        return m, math.nan, math.nan, math.nan
    s = float(d.std(ddof=1))
    if s == 0.0:
        return m, m, m, 1.0 if m == 0.0 else 0.0
    se = s / math.sqrt(n)
    q = float(special.stdtrit(n - 1, 0.5 + level / 2.0))  # t_{n-1} quantile: stats.t.ppf
    p = float(2.0 * special.stdtr(n - 1, -(abs(m) / se)))  # upper tail: stats.t.sf
    return m, m - q * se, m + q * se, p


def bootstrap_mean_interval(d, n_boot: int = 2000, seed: int = 0, level: float = 0.95
                            ) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of ``d`` (runs resampled with
    replacement, ``n_boot`` times, generator ``default_rng(seed)``); NaN if
    ``n_boot < 2`` or fewer than two values."""
    d = np.asarray(d, float).ravel()
    if n_boot < 2 or d.size < 2:
        return math.nan, math.nan
    rng = np.random.default_rng(seed)
    means = d[rng.integers(0, d.size, size=(int(n_boot), d.size))].mean(axis=1)
    a = (1.0 - level) / 2.0
    lo, hi = np.quantile(means, [a, 1.0 - a])
    return float(lo), float(hi)


def paired_difference(a, b, n_boot: int = 2000, seed: int = 0, level: float = 0.95) -> PairedDifference:
    """Paired comparison of per-run values ``a`` and ``b`` (same runs, same
    order): ``mean`` of ``a - b``, paired-t ``t_lo``/``t_hi``/``p``, bootstrap
    ``boot_lo``/``boot_hi``, ``a_lower_pct`` (share of runs with ``a < b``,
    %), ``equal_pct`` (share with ``a == b``, %) and ``n``."""
    a = np.asarray(a, float).ravel()
    b = np.asarray(b, float).ravel()
    if a.shape != b.shape:
        raise ValueError(f"paired_difference: {a.size} vs {b.size} runs (must be the same runs)")
    d = a - b
    m, lo, hi, p = paired_t_interval(d, level)
    blo, bhi = bootstrap_mean_interval(d, n_boot, seed, level)
    return PairedDifference(mean=m, t_lo=lo, t_hi=hi, p=p, boot_lo=blo, boot_hi=bhi,
                            a_lower_pct=float(100.0 * np.mean(a < b)), equal_pct=float(100.0 * np.mean(a == b)),
                            n=int(d.size))


def _calls(d: MonteCarlo) -> dict[tuple[int, float], tuple[int, float]]:
    """The planning calls of ``d`` by (run, filter time): (picked landmark, optimum beta (rad))."""
    beta = d.plan_beta if d.has("plan_beta") else np.full(len(d.plan_index), np.nan)
    return {(int(r), float(t)): (int(i), float(b)) for r, t, i, b in
            zip(d.plan_run, d.plan_t, d.plan_index, beta)}


def median_abs_dbeta_deg(a: MonteCarlo, b: MonteCarlo) -> float:
    """Median over planning calls matched by (run, time) of |beta*_a - beta*_b|
    (deg), the in-plane optima of two methods; NaN if no call has both."""
    ka, kb = _calls(a), _calls(b)
    d = [abs(ka[k][1] - kb[k][1]) for k in set(ka) & set(kb)
         if math.isfinite(ka[k][1]) and math.isfinite(kb[k][1])]
    return float(np.degrees(np.median(d))) if d else math.nan


def pair_comparison(a: MonteCarlo, b: MonteCarlo, level: float = 0.95) -> PairComparison:
    """What a comparison of two methods' accuracy rests on (same paired runs):
    the share of planning calls where they chose the same landmark (%), the
    median |delta beta*| (deg), and the paired difference a - b of the per-run
    RMS and final (touchdown) position error norms (m) with its paired-t
    interval at ``level``, also relative to b's mean (%); the same of the error at the last
    landmark update (``d_lastlm_pos``) and RMS over the landmark phase (``d_lmrms_pos``) where
    the runs record landmark updates."""
    sa, sb = per_run_stats(a), per_run_stats(b)
    diffs = {}
    for key, name in (("rms_pos_err_m", "rms_pos"), ("final_pos_err_m", "final_pos"),
                      ("lastlm_pos_err_m", "lastlm_pos"), ("lmrms_pos_err_m", "lmrms_pos")):
        if key not in sa or key not in sb:
            continue
        x, y = sa[key].to_numpy(), sb[key].to_numpy()
        if x.shape != y.shape or x.size == 0:
            raise ValueError("pair_comparison: the two methods must have flown the same runs")
        m, lo, hi, p = paired_t_interval(x - y, level)
        base = float(np.mean(y))
        diffs[name] = ErrorDifference(m, lo, hi, p, 100.0 * m / base, 100.0 * lo / base, 100.0 * hi / base)
    return PairComparison(same_pick_pct(a, b), median_abs_dbeta_deg(a, b), diffs)


def pair_table(data: dict[str, MonteCarlo], level: float = 0.95) -> pd.DataFrame:
    """:func:`pair_comparison` for every unordered pair of methods (in order)."""
    names = list(data)
    rows = [{"method_a": a, "method_b": b, **dict(pair_comparison(data[a], data[b], level).columns())}
            for i, a in enumerate(names) for b in names[i + 1:]]
    return pd.DataFrame(rows)


def competition_rank(values, rtol: float = 0.0) -> np.ndarray:
    """Ranks (1 = smallest) with ties sharing the best rank (``1, 2, 2, 4``).

    Values within ``rtol`` (relative, of the larger magnitude) of the previous
    value in sorted order tie with it; NaN ranks last (all NaN share a rank).
    """
    v = np.asarray(values, float).ravel()
    if rtol < 0:
        raise ValueError("competition_rank: rtol must be >= 0")
    order = np.argsort(np.where(np.isnan(v), np.inf, v), kind="stable")
    ranks = np.empty(v.size, np.int64)
    prev = None
    for pos, i in enumerate(order):
        x = v[i]
        if prev is not None:
            px = v[prev]
            same = (np.isnan(x) and np.isnan(px)) or (
                not np.isnan(x) and not np.isnan(px)
                and abs(x - px) <= rtol * max(abs(x), abs(px)))
            if same:
                ranks[i] = ranks[prev]
                prev = i
                continue
        ranks[i] = pos + 1
        prev = i
    return ranks


#: the accuracy ranking's statistic (mean over runs): the position error at the
#: last landmark update, what a landmark choice can move (the RMS over the whole
#: descent is set by the 1 km initial error, the touchdown error by what follows
#: the landmark phase)
RANK_BY = "lastlm_pos"


def _rank_by(stats: pd.DataFrame) -> str:
    """:data:`RANK_BY`, or the RMS over the descent for records without the
    landmark-update flags (``lm_updated``, e.g. hand-made runs)."""
    return RANK_BY if f"{RANK_BY}_err_m" in stats else "rms_pos"


def ranking_table(data: dict[str, MonteCarlo], timing: Replay, reference: str = "depth", n_boot: int = 2000,
                  seed: int = 0, level: float = 0.95, rtol: float = 0.0,
                  converged_pos_err_m: float = 100.0) -> pd.DataFrame:
    """B-X1: one row per method of ``data`` (gathered Monte Carlo records, same
    runs), ranked; see the module docstring for the columns. Paired columns
    ``d_rms_pos_vs_ref_*`` / ``d_final_pos_vs_ref_*`` / ``d_lastlm_pos_vs_ref_*``
    / ``d_lmrms_pos_vs_ref_*`` are method minus
    reference (m; negative = the method is more accurate); ``converged_runs_pct``
    counts runs whose final position error is below ``converged_pos_err_m`` (m),
    as in B-T3; ``median_abs_beta_deg`` is the median over calls of the optimum's |beta| (deg),
    its in-plane angle to the estimated velocity (0: no parallax; ``planning.reference`` says why the
    whitened baselines sit near it). Time columns (median wall and CPU time of a planning call, us)
    come from ``timing``, the replay of the recorded planning calls
    (``opnav.landing.timing.replay``: every method on the same calls)."""
    from opnav.landing import timing_summary as tsum

    if reference not in data:
        raise ValueError(f"landing.extra.reference {reference!r} not among the methods {list(data)}")
    st = {m: per_run_stats(d) for m, d in data.items()}
    ref_runs = st[reference].index
    for m, s in st.items():
        if not s.index.equals(ref_runs):
            raise ValueError(f"method {m!r} flew runs {list(s.index)[:5]}..., reference "
                             f"{reference!r} flew {list(ref_runs)[:5]}...: not paired")
    ref_cpu = tsum.median_us(timing, reference, clock="cpu")
    rank_by = _rank_by(st[reference])
    rows = []
    for m, d in data.items():
        s = st[m]
        n = len(s)
        row = {"method": m, "n_runs": n}
        for q in ("pos_err_m", "vel_err_mps"):    # attitude: see the envelopes (yaw unobservable)
            for kind in ("rms", "final", "lastlm", "lmrms"):
                if f"{kind}_{q}" not in s:
                    continue
                col = s[f"{kind}_{q}"]
                row[f"{kind}_{q}_mean"] = float(col.mean())
                row[f"{kind}_{q}_3sigma"] = float(3.0 * col.std(ddof=1)) if n > 1 else math.nan
                if q == "pos_err_m":
                    row[f"{kind}_{q}_median"] = float(col.median())
        row["converged_runs_pct"] = float(100.0 * (s["final_pos_err_m"] < converged_pos_err_m).mean())
        row["mean_nees_pos"] = float(s["mean_nees_pos"].mean())
        row["landmarks_per_run"] = float(s["n_landmarks"].mean())
        row["plan_calls"] = int(len(d.plan_index))
        idx = np.asarray(d.plan_index)
        row["no_pick_pct"] = float(100.0 * np.mean(idx < 0)) if idx.size else math.nan
        row["median_plan_time_us"] = tsum.median_us(timing, m)
        row["median_plan_cpu_us"] = tsum.median_us(timing, m, clock="cpu")
        row["cpu_time_ratio_to_ref"] = row["median_plan_cpu_us"] / ref_cpu
        for key, name in (("rms_pos_err_m", "rms_pos"), ("final_pos_err_m", "final_pos"),
                          ("lastlm_pos_err_m", "lastlm_pos"), ("lmrms_pos_err_m", "lmrms_pos")):
            if key not in s:
                continue
            pdiff = paired_difference(s[key].to_numpy(), st[reference][key].to_numpy(),
                                      n_boot=n_boot, seed=seed, level=level)
            for k in ("mean", "t_lo", "t_hi", "boot_lo", "boot_hi", "p"):
                row[f"d_{name}_vs_ref_{k}"] = getattr(pdiff, k)
            if name == rank_by:
                row["ref_better_pct"] = 100.0 - pdiff.a_lower_pct - pdiff.equal_pct
                row["equal_to_ref_pct"] = pdiff.equal_pct
        row["same_pick_as_ref_pct"] = (100.0 if m == reference
                                       else same_pick_pct(d, data[reference]))
        row["median_abs_dbeta_vs_ref_deg"] = (0.0 if m == reference
                                              else median_abs_dbeta_deg(d, data[reference]))
        # the optimum's in-plane angle to the estimated velocity (0: no parallax; planning.reference)
        beta = np.abs(np.asarray(d.plan_beta if d.has("plan_beta") else [], float))
        row["median_abs_beta_deg"] = (float(np.degrees(np.median(beta[np.isfinite(beta)])))
                                      if np.isfinite(beta).any() else math.nan)
        lo, hi = row[f"d_{rank_by}_vs_ref_t_lo"], row[f"d_{rank_by}_vs_ref_t_hi"]
        row["vs_ref"] = ("reference" if m == reference else
                         "n/a" if math.isnan(lo) else
                         "worse" if lo > 0 else "better" if hi < 0 else "not significant")
        rows.append(row)
    df = pd.DataFrame(rows)
    df.insert(1, "rank_accuracy", competition_rank(df[f"{rank_by}_err_m_mean"], rtol))
    df["rank_accuracy_by"] = f"{rank_by}_err_m_mean"
    df.insert(2, "rank_time", competition_rank(df["median_plan_cpu_us"], rtol))
    # ties broken by method name, never by a timing (identical rebuilds, same order)
    return df.sort_values(["rank_accuracy", "method"], kind="stable").reset_index(drop=True)


def headline(df: pd.DataFrame, reference: str = "depth") -> Headline:
    """Headline numbers of a :func:`ranking_table` for the manuscript macros (their lists in words:
    ``opnav.report.landing.ranking_text.worded_headline``)."""
    def clean(x):
        if isinstance(x, (float, np.floating)):
            return None if math.isnan(float(x)) else float(x)
        if isinstance(x, np.integer):
            return int(x)
        return x

    t = df.set_index("method")
    others = [m for m in t.index if m != reference]
    ref = t.loc[reference]
    # orders: by rank, ties by method name (never by the other ranking: timings
    # change from build to build)
    by_acc = list(t.reset_index().sort_values(["rank_accuracy", "method"], kind="stable")["method"])
    by_time = list(t.reset_index().sort_values(["rank_time", "method"], kind="stable")["method"])
    # the optimum's median angle to the estimated velocity (0: no parallax), methods that search
    beta = {m: float(t.loc[m, "median_abs_beta_deg"]) for m in by_acc if "median_abs_beta_deg" in t
            and math.isfinite(float(t.loc[m, "median_abs_beta_deg"]))}
    return Headline(
        reference=reference,
        methods={m: {k: clean(v) for k, v in t.loc[m].items()} for m in t.index},
        ranking_by_accuracy=by_acc,
        ranking_by_time=by_time,
        # ties are ties: every method of rank 1, never one chosen by its name
        best_accuracy_methods=[m for m in by_acc if int(t.loc[m, "rank_accuracy"]) == 1],
        best_accuracy_tie=sum(int(t.loc[m, "rank_accuracy"]) == 1 for m in by_acc) > 1,
        fastest_method=by_time[0],
        reference_rank_accuracy=int(ref["rank_accuracy"]),
        reference_rank_time=int(ref["rank_time"]),
        n_methods=int(len(t)),
        n_runs=int(ref["n_runs"]),
        reference_more_accurate_than=[m for m in others if t.loc[m, "vs_ref"] == "worse"],
        reference_less_accurate_than=[m for m in others if t.loc[m, "vs_ref"] == "better"],
        not_significant_vs_reference=[m for m in others if t.loc[m, "vs_ref"] == "not significant"],
        reference_faster_than=[m for m in others if t.loc[m, "median_plan_cpu_us"] > ref["median_plan_cpu_us"]],
        median_abs_beta_deg=beta)
