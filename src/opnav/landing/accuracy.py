"""Paper B's accuracy claims as tests that can fail, on one camera scenario's Monte Carlo:
the paired equivalence test of "almost the same accuracy" (B-C1) against the reference and
the H baselines, "converges faster" (B-C2) at the threshold and its sweep, the error
statistics behind B-C10's envelopes and the held-out NEES (:func:`accuracy_tests`; the
tests themselves: :mod:`opnav.landing.equivalence`). The numbers only: the verdict and its
words are the report layer's (``opnav.report.landing.summary``).

Units: m, s, deg.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping

from opnav.core.tables import json_key
from opnav.landing.equivalence import ConvergesFaster, EquivalenceSection
from opnav.landing.montecarlo import NeesConsistency

if TYPE_CHECKING:
    from opnav.landing.records import MonteCarlo
    from opnav.landing.setup import Equivalence

__all__ = ["accuracy_tests", "ErrorStat", "AccuracyTests"]


@dataclass(frozen=True)
class ErrorStat:
    """Mean, median and 3-sigma over the runs of one per-run error (m, m/s or deg; 3-sigma NaN
    below two runs)."""

    mean: float
    median: float
    sigma3: float = field(metadata=json_key("3sigma"))


@dataclass(frozen=True)
class AccuracyTests:
    """The accuracy claims of one scenario (:func:`accuracy_tests`): the equivalence section against
    the reference and against each H baseline, the plan's same-pick threshold, the controls and
    those that passed, converges-faster per method (at the threshold and per threshold of the
    sweep), per method its error statistics by quantity and its held-out NEES. B-summary.json
    writes its fields at the top level."""

    equivalence: EquivalenceSection
    equivalence_vs_baselines: dict[str, EquivalenceSection]
    same_pick_max_pct: float
    controls: list[str]
    controls_equivalent: list[str]
    converges_faster: dict[str, ConvergesFaster]
    converges_faster_by_threshold: dict[str, dict[str, ConvergesFaster]]
    errors: dict[str, dict[str, ErrorStat]]
    nees: dict[str, NeesConsistency]

    def with_baselines(self, sections: Mapping[str, EquivalenceSection]) -> "AccuracyTests":
        """These tests with more sections against baselines (a baseline's existing section gains
        the new section's methods)."""
        by_base = dict(self.equivalence_vs_baselines)
        for b, sec in sections.items():
            by_base[b] = by_base[b].with_methods(sec.methods) if b in by_base else sec
        return dataclasses.replace(self, equivalence_vs_baselines=by_base)


def accuracy_tests(data: dict[str, MonteCarlo], eq: Equivalence, converged_pos_err_m: float, *,
                   margin_rel: float, same_pick_max_pct: float, min_difference_s: float,
                   thresholds_m: tuple[float, ...] = ()) -> AccuracyTests:
    """The accuracy claims of one scenario as tests that can fail
    (:mod:`opnav.landing.equivalence`), from the gathered Monte Carlo of every
    method flown (``data``, the controls included), ``landing.equivalence``
    (``eq``: reference, methods, controls, alpha) and the analysis plan's B-C1
    numbers, passed in by the caller (the landing package does not read the plan):
    ``margin_rel`` (margin = that fraction of the reference's mean error) and
    ``same_pick_max_pct`` (same picks in that share of the calls or more: not
    tested), both recorded in the result for the verdict
    (``opnav.report.landing.summary.same_accuracy_verdict``), and
    B-C2's ``min_difference_s`` (s: "converges faster" needs at least that).
    Returns ``equivalence`` (each method of ``methods`` and each control
    against ``reference``: margin, metric, paired intervals, same-pick rate),
    ``controls_equivalent`` (the controls that passed: the test is void if any
    did), ``converges_faster`` (each method of ``methods`` vs ``reference``,
    first time below ``converged_pos_err_m``), ``errors`` (per method: mean,
    median and 3-sigma of the error at the last landmark update, RMS over the
    landmark phase and at touchdown, m), ``nees`` (per method,
    ``montecarlo.nees_consistency``) and ``equivalence_vs_baselines``: the same paired
    test of each method of ``methods`` against each of the paper's H baselines flown
    (svd, gdop, cond: the claim names all three; same margins, alpha and runs);
    ``converges_faster_by_threshold``: the same paired first-time rule at each threshold of
    ``thresholds_m`` (m; the analysis plan's sweep, for what B-C2 would take), keyed by the
    threshold. ``errors`` also holds the RMS velocity and attitude errors over the descent
    (mean, median, 3-sigma; B-C10's envelopes for every method, controls included)."""
    from opnav.landing import equivalence as eqv
    from opnav.landing.montecarlo import nees_consistency, per_run_stats, same_pick_pct, time_below

    ref = eq.reference
    tested = list(eq.methods) + list(eq.controls)
    missing = [m for m in [ref, *tested] if m not in data]
    if missing:
        raise ValueError(f"landing.equivalence: methods {missing} were not flown")
    stats = {m: per_run_stats(d) for m, d in data.items()}
    picks = {m: same_pick_pct(data[m], data[ref]) for m in tested}
    alpha = float(eq.alpha)
    res = eqv.equivalence(stats, ref, tested, float(margin_rel), alpha, picks)
    errors = {}
    for m, st in stats.items():
        errors[m] = {}
        for q in eqv.PRIMARY_METRICS + (eqv.TOUCHDOWN_METRIC, "rms_vel_err_mps", "rms_att_err_deg"):
            if q not in st:
                continue
            col = st[q]
            errors[m][q] = ErrorStat(float(col.mean()), float(col.median()),
                                     float(3.0 * col.std(ddof=1)) if len(col) > 1 else math.nan)
    t_ref = time_below(data[ref], converged_pos_err_m)
    faster = {m: eqv.converges_faster(time_below(data[m], converged_pos_err_m), t_ref, m, ref,
                                      converged_pos_err_m, alpha,
                                      min_difference_s=float(min_difference_s))
              for m in eq.methods}
    by_thr = {}
    for thr in dict.fromkeys(float(x) for x in thresholds_m):
        t_ref_k = time_below(data[ref], thr)
        by_thr[f"{thr:g}"] = {m: eqv.converges_faster(time_below(data[m], thr), t_ref_k, m, ref, thr,
                                                      alpha, min_difference_s=float(min_difference_s))
                              for m in eq.methods}
    by_base = {}
    for b in ("svd", "gdop", "cond"):
        if b in data:
            tested_b = [m for m in eq.methods if m != b]
            by_base[b] = eqv.equivalence(stats, b, tested_b, float(margin_rel), alpha,
                                         {m: same_pick_pct(data[m], data[b]) for m in tested_b})
    return AccuracyTests(equivalence=res, equivalence_vs_baselines=by_base,
                         same_pick_max_pct=float(same_pick_max_pct), controls=list(eq.controls),
                         controls_equivalent=[c for c in eq.controls if res.methods[c].equivalent],
                         converges_faster=faster, converges_faster_by_threshold=by_thr, errors=errors,
                         nees={m: nees_consistency(d) for m, d in data.items()})
