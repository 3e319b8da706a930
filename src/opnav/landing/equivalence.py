"""Paper B's accuracy claims as tests that can fail: "almost the same accuracy"
(depth vs the SVD baseline) as a paired equivalence test with negative
controls, and "converges a bit faster" as a paired time-to-threshold rule.

Description
-----------
Every method flies the same runs (paired design, ``opnav.landing.descent``),
so per-run differences ``d_i = x_a,i - x_b,i`` of a per-run error ``x`` (m)
remove the run-to-run spread of the initial errors.

Equivalence (:func:`tost`): two one-sided paired t-tests at level ``alpha``
(Schuirmann's TOST): ``a`` and ``b`` are *equivalent* within the margin
``delta`` (m) when both ``H0: mean d <= -delta`` and ``H0: mean d >= +delta``
are rejected, i.e. when the ``1 - 2 alpha`` paired-t interval of the mean
difference lies inside ``(-delta, +delta)``. Not rejecting is "not shown
equivalent" (the test must show equivalence, not fail to refute it).

Margin (:func:`margins`): a fixed fraction ``margin_rel`` of the reference's
own mean of the same metric (m). The fraction is the analysis plan's (B-C1
``margin_rel``, ``data/analysis_plan.yaml``: "almost the same" read as within
10 % of the baseline's mean error), passed in by the caller, so the scorecard,
the landing summary and the claims table use one number; no other method's
runs (the controls' in particular) move it. A reference mean that is not
positive gives margin 0 and nothing is shown equivalent.

Metrics (per run, ``montecarlo.per_run_stats``): the position error norm at
the last update with a landmark bearing (``lastlm_pos_err_m``) and its RMS
over the landmark-tracking phase (``lmrms_pos_err_m``), the errors a landmark
choice can move; the verdict needs both. The touchdown error
(``final_pos_err_m``), set mostly by what follows the landmark phase, is
tested beside them and reported, not part of the verdict.

Negative controls: the same rule applied to ``random``, ``center`` and
``closest`` (pickers without a metric, ``opnav.landing.planner.PICKERS``)
against the same reference; if a control is "equivalent" the claim may hold but
the test cannot credit the metric (a picker without one meets it too).

Converges faster (:func:`converges_faster`): per run, the first time the
position error is below a threshold (``montecarlo.time_below``); the paired
difference ``a - b`` over runs where both get there, with its two-sided
``1 - alpha`` paired-t interval: "faster" if the interval is below 0 and the
mean difference is at least ``min_difference_s`` (the analysis plan's B-C2: one
filter step; a smaller difference is below the time resolution), "slower" in
the mirror case, else "no difference shown".

The results are typed records (:class:`PairedTest`, :class:`Margin`, :class:`MetricMargin`,
:class:`MethodEquivalence`, :class:`EquivalenceSection`, :class:`ConvergesFaster`) holding numbers
and outcomes; their sentences are the report layer's (``opnav.report.landing.equivalence_text``).
B-summary.json writes them with their fields as keys (``core.tables.json_ready``) and the
sentences beside them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
from scipy import special

from opnav.core.tables import JSON_SKIP

__all__ = ["tost", "margins", "equivalence", "converges_faster", "PRIMARY_METRICS", "TOUCHDOWN_METRIC",
           "PairedTest", "Margin", "MetricMargin", "MethodEquivalence", "EquivalenceSection", "ConvergesFaster"]

#: the per-run metrics the equivalence verdict needs (both), m
PRIMARY_METRICS = ("lastlm_pos_err_m", "lmrms_pos_err_m")
#: reported beside them, not part of the verdict, m
TOUCHDOWN_METRIC = "final_pos_err_m"


@dataclass(frozen=True)
class PairedTest:
    """A paired TOST of ``|mean d| < margin`` (:func:`tost`; m): the mean difference, its
    ``level`` interval ``lo``/``hi``, the larger one-sided p-value, the outcome, the margin, the
    runs and the standard error."""

    mean: float
    lo: float
    hi: float
    p: float
    equivalent: bool
    margin: float
    n: int
    se: float
    level: float


@dataclass(frozen=True)
class Margin:
    """The equivalence margin of one metric (:func:`margins`; m): ``rel`` times the reference's
    mean, that mean, and the methods sharing the smallest mean (ties are ties)."""

    margin: float
    rel: float
    reference_mean: float
    best: list[str]


@dataclass(frozen=True, kw_only=True)
class MetricMargin(Margin):
    """One metric of an equivalence section: its :class:`Margin` and every method's mean (m)."""

    means: dict[str, float]


@dataclass(frozen=True)
class MethodEquivalence:
    """One tested method against the section's reference: a :class:`PairedTest` per metric
    (``tests``, by metric key: written as the method's own keys), ``equivalent`` (both primary
    metrics), the same-pick rate (%) and the outcome word."""

    tests: dict[str, PairedTest] = field(metadata={"json_flatten": True})
    equivalent: bool
    same_pick_pct: float
    verdict: str


@dataclass(frozen=True)
class EquivalenceSection:
    """Every tested method against one ``reference`` (:func:`equivalence`): the one-sided tests'
    alpha, the relative margin, per metric its :class:`MetricMargin` and per method its
    :class:`MethodEquivalence`."""

    reference: str
    alpha: float
    margin_rel: float
    metrics: dict[str, MetricMargin]
    methods: dict[str, MethodEquivalence]

    def with_methods(self, methods: Mapping[str, MethodEquivalence]) -> "EquivalenceSection":
        """This section with more tested methods (the same reference, margins and alpha)."""
        import dataclasses

        return dataclasses.replace(self, methods={**self.methods, **methods})


@dataclass(frozen=True)
class ConvergesFaster:
    """First time below ``threshold_m``, ``method`` minus ``versus`` (:func:`converges_faster`; s):
    the mean over the runs where both get there, its ``level`` paired-t interval and standard
    error, the runs used and flown, the smallest difference counted and the outcome."""

    mean_s: float
    lo_s: float
    hi_s: float
    se_s: float
    level: float
    versus: str
    n_runs: int
    n_total: int
    threshold_m: float
    min_difference_s: float
    verdict: str
    method: str = field(default="", metadata=JSON_SKIP)


def _t_interval(d: np.ndarray, level: float) -> tuple[float, float, float, float]:
    """(mean, standard error, lo, hi) of the two-sided paired-t interval."""
    n = d.size
    m = float(d.mean())
    se = float(d.std(ddof=1)) / math.sqrt(n)
    q = float(special.stdtrit(n - 1, 0.5 + level / 2.0)) if se > 0 else 0.0
    return m, se, m - q * se, m + q * se


def tost(d, margin: float, alpha: float = 0.05) -> PairedTest:
    """Paired two-one-sided test of ``|mean d| < margin`` (``d``: per-run
    differences, m; ``margin``: m). Returns ``mean``, the ``1 - 2 alpha``
    interval ``lo``/``hi`` (its ``level``) and the standard error ``se``, ``p`` (the larger one-sided p-value; equivalence
    shown iff ``p < alpha``), ``equivalent`` (bool), ``margin`` and ``n``.
    Zero spread: equivalent iff ``|mean| < margin``. A margin <= 0 is never
    met."""
    d = np.asarray(d, float).ravel()
    if d.size < 2 or not np.all(np.isfinite(d)):
        raise ValueError("tost: need at least two finite paired differences")
    if not 0.0 < alpha < 0.5:
        raise ValueError(f"tost: alpha must be in (0, 0.5), got {alpha}")
    m, se, lo, hi = _t_interval(d, 1.0 - 2.0 * alpha)
    margin = float(margin)
    if se == 0.0:
        p = 0.0 if abs(m) < margin else 1.0
    else:
        p_low = float(special.stdtr(d.size - 1, -((m + margin) / se)))   # H0: mean <= -margin
        p_high = float(special.stdtr(d.size - 1, (m - margin) / se))     # H0: mean >= +margin
        p = max(p_low, p_high)
    ok = margin > 0.0 and p < alpha
    return PairedTest(mean=m, lo=lo, hi=hi, p=p, equivalent=bool(ok), margin=margin, n=int(d.size), se=se,
                      level=1.0 - 2.0 * alpha)


def margins(means: Mapping[str, float], reference: str, margin_rel: float) -> Margin:
    """The equivalence margin of one metric (m): ``margin_rel`` times the
    reference's mean of ``means`` (method -> mean, m), 0 if that mean is not
    positive. Returns ``margin``, ``rel``, ``reference_mean`` and ``best`` (the
    methods sharing the smallest mean, a list: ties are ties; reported, it does
    not set the margin)."""
    if reference not in means:
        raise ValueError(f"equivalence margin: the reference {reference!r} was not flown "
                         f"(methods: {sorted(means)})")
    if not (math.isfinite(float(margin_rel)) and float(margin_rel) > 0.0):
        raise ValueError(f"equivalence margin: margin_rel must be a positive fraction, got {margin_rel!r}")
    lo = min(means.values())
    best = sorted(m for m, v in means.items() if v == lo)
    r = float(means[reference])
    return Margin(margin=float(margin_rel) * r if r > 0 else 0.0, rel=float(margin_rel), reference_mean=r, best=best)


def equivalence(stats: Mapping, reference: str, tested: list[str], margin_rel: float,
                alpha: float = 0.05, same_pick_pct: Mapping[str, float] | None = None) -> EquivalenceSection:
    """Equivalence of each method of ``tested`` with ``reference`` on paired
    runs. ``stats``: method -> per-run table (``montecarlo.per_run_stats``, the
    same runs in the same order) of every method flown; ``margin_rel``: the
    plan's fraction of the reference's mean (:func:`margins`); ``same_pick_pct``: method -> share of
    planning calls picking the reference's landmark (%). Returns per metric its
    margin (:func:`margins`) and every method's mean, and per tested method the :func:`tost` of
    every metric (primary and touchdown), ``equivalent`` (both primary metrics) and
    ``same_pick_pct``."""
    if reference not in stats:
        raise ValueError(f"equivalence: reference {reference!r} not among {sorted(stats)}")
    runs = stats[reference].index
    for m, s in stats.items():
        if not s.index.equals(runs):
            raise ValueError(f"equivalence: {m!r} did not fly the runs of {reference!r}")
    same_pick_pct = same_pick_pct or {}
    metrics = {}
    for q in PRIMARY_METRICS + (TOUCHDOWN_METRIC,):
        means = {m: float(s[q].mean()) for m, s in stats.items()}
        mg = margins(means, reference, margin_rel)
        metrics[q] = MetricMargin(mg.margin, mg.rel, mg.reference_mean, mg.best, means=means)
    ref = stats[reference]
    methods = {}
    for m in tested:
        res = {q: tost(stats[m][q].to_numpy() - ref[q].to_numpy(), metrics[q].margin, alpha) for q in metrics}
        eq = all(res[q].equivalent for q in PRIMARY_METRICS)
        methods[m] = MethodEquivalence(tests=res, equivalent=bool(eq), same_pick_pct=same_pick_pct.get(m, math.nan),
                                       verdict="equivalent" if eq else "not equivalent")
    return EquivalenceSection(reference=reference, alpha=float(alpha), margin_rel=float(margin_rel), metrics=metrics,
                              methods=methods)


def converges_faster(t_a, t_b, a: str, b: str, threshold_m: float, alpha: float = 0.05, *,
                     min_difference_s: float) -> ConvergesFaster:
    """Paired comparison of the first times below ``threshold_m`` (s; NaN:
    never) of methods ``a`` and ``b`` on the same runs: mean of ``t_a - t_b``
    over the runs where both get there, its two-sided ``1 - alpha`` paired-t
    interval (s, its ``level``, the standard error ``se_s``), the runs used, and ``verdict``: "faster" (interval below 0
    and mean at most ``-min_difference_s``: ``a`` converges faster by at least
    that, s; the analysis plan's B-C2 number, passed in), "slower" (the mirror)
    or "no difference shown"."""
    t_a, t_b = np.asarray(t_a, float), np.asarray(t_b, float)
    if t_a.shape != t_b.shape:
        raise ValueError("converges_faster: the two methods must have flown the same runs")
    both = np.isfinite(t_a) & np.isfinite(t_b)
    d = t_a[both] - t_b[both]
    if d.size < 2:
        m, se, lo, hi = (float(d.mean()) if d.size else math.nan), math.nan, math.nan, math.nan
    else:
        m, se, lo, hi = _t_interval(d, 1.0 - alpha)
    step = float(min_difference_s)
    if not (math.isfinite(step) and step >= 0.0):
        raise ValueError(f"converges_faster: min_difference_s must be >= 0 s, got {min_difference_s!r}")
    verdict = ("faster" if hi < 0 and m <= -step else "slower" if lo > 0 and m >= step
               else "no difference shown")
    return ConvergesFaster(mean_s=m, lo_s=lo, hi_s=hi, se_s=se, level=1.0 - alpha, versus=b, n_runs=int(d.size),
                           n_total=int(t_a.size), threshold_m=float(threshold_m), min_difference_s=step,
                           verdict=verdict, method=a)
