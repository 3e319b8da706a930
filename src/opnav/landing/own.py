"""A user's own planning methods (``landing.custom_methods``, ``opnav.landing.methods``) compared
with the paper's: the paired comparison behind their evidence rows (role ``beyond``, no verdict)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Mapping

if TYPE_CHECKING:
    from opnav.landing.accuracy import AccuracyTests
    from opnav.landing.equivalence import EquivalenceSection
    from opnav.landing.records import MonteCarlo

__all__ = ["VERSUS", "compare_own", "with_own"]


#: the baselines a user's own method is compared with (paired, on the same runs): the paper's
#: reference (SVD) and its method (depth)
VERSUS = ("svd", "depth")


def compare_own(data: Mapping[str, "MonteCarlo"], names, margin_rel: float, alpha: float,
                versus=VERSUS) -> dict[str, "EquivalenceSection"]:
    """The paired comparison of each of a user's own methods ``names`` against each baseline of
    ``versus`` flown in ``data`` (method -> gathered Monte Carlo): per baseline the
    equivalence section of ``opnav.landing.equivalence.equivalence`` (the B-C1 test's paired
    differences, intervals and same-pick rate, with the plan's margin and alpha) of those
    methods. No verdict reads it: its evidence rows carry role ``beyond``
    (``report.landing_claims``, from ``equivalence_vs_baselines``)."""
    from opnav.landing import equivalence as eqv
    from opnav.landing.montecarlo import per_run_stats, same_pick_pct

    names = [m for m in names if m in data]
    stats = {m: per_run_stats(d) for m, d in data.items()}
    out = {}
    for b in versus:
        if b not in data or not names:
            continue
        tested = [m for m in names if m != b]
        out[b] = eqv.equivalence(stats, b, tested, float(margin_rel), float(alpha),
                                 {m: same_pick_pct(data[m], data[b]) for m in tested})
    return out


def with_own(accuracy: "AccuracyTests", own: Mapping[str, "EquivalenceSection"]) -> "AccuracyTests":
    """``accuracy`` (``landing.accuracy.accuracy_tests``) with :func:`compare_own`'s sections in
    its ``equivalence_vs_baselines`` (a baseline's existing section gains the own methods)."""
    return accuracy.with_baselines(own)
