"""Paper B's accuracy tests in words (``opnav.landing.equivalence``'s records): what each metric
is (:data:`METRIC_TEXT`), a method's equivalence result in one sentence
(:func:`equivalence_text`), a time-to-threshold comparison (:func:`converges_text`), and the
records with their sentences as B-summary.json writes them (:class:`Worded`,
:class:`WordedSection`, :func:`worded_section`: the record's fields and ``text``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from opnav.landing.equivalence import ConvergesFaster, EquivalenceSection

__all__ = ["METRIC_TEXT", "equivalence_text", "converges_text", "Worded", "WordedSection", "worded_section"]

#: the equivalence metrics in words (``equivalence.PRIMARY_METRICS`` and the touchdown metric)
METRIC_TEXT = {"lastlm_pos_err_m": "position error at the last landmark update",
               "lmrms_pos_err_m": "RMS position error over the landmark-tracking phase",
               "final_pos_err_m": "position error at touchdown"}


def equivalence_text(method: str, section: "EquivalenceSection") -> str:
    """One method's equivalence result against the section's reference: the outcome, each primary
    metric's paired interval against its margin, the margin's rule and the same-pick rate."""
    from opnav.landing.equivalence import PRIMARY_METRICS

    ref, alpha, rel = section.reference, section.alpha, section.margin_rel
    r = section.methods[method]
    parts = "; ".join(
        f"{METRIC_TEXT[q]} {r.tests[q].mean:+.3g} m [{r.tests[q].lo:+.3g}, {r.tests[q].hi:+.3g}] "
        f"vs margin +-{r.tests[q].margin:.3g} m" for q in PRIMARY_METRICS)
    return (f"{method} vs {ref}: {'equivalent' if r.equivalent else 'not equivalent'} "
            f"({100 * (1 - 2 * alpha):.0f} % paired intervals, {method} minus {ref}: {parts}; "
            f"margin {rel:g} x {ref}'s mean error; same landmark as "
            f"{ref} in {r.same_pick_pct:.3g} % of the planning calls)")


def converges_text(cf: "ConvergesFaster") -> str:
    """A time-to-threshold comparison in words: the mean difference with its interval, the runs and
    the smallest difference counted, and the outcome."""
    alpha = 1.0 - cf.level
    return (f"first time below {cf.threshold_m:g} m, {cf.method} minus {cf.versus}: {cf.mean_s:+.3g} s "
            f"[{cf.lo_s:+.3g}, {cf.hi_s:+.3g}] ({100 * (1 - alpha):.0f} % paired interval, "
            f"{cf.n_runs} of {cf.n_total} runs; smallest difference counted {cf.min_difference_s:g} s): "
            f"{cf.verdict}")


@dataclass(frozen=True)
class Worded:
    """A record and its sentence, written as the record's fields and ``text``."""

    record: Any = field(metadata={"json_flatten": True})
    text: str


@dataclass(frozen=True)
class WordedSection:
    """An :class:`~opnav.landing.equivalence.EquivalenceSection` with each metric and each method
    worded (:func:`worded_section`), written with the section's keys."""

    reference: str
    alpha: float
    margin_rel: float
    metrics: dict[str, Worded]
    methods: dict[str, Worded]


def worded_section(section: "EquivalenceSection") -> WordedSection:
    """``section`` with its sentences: each metric named (:data:`METRIC_TEXT`), each method's
    result in words (:func:`equivalence_text`)."""
    return WordedSection(section.reference, section.alpha, section.margin_rel,
                         {q: Worded(v, METRIC_TEXT[q]) for q, v in section.metrics.items()},
                         {m: Worded(v, equivalence_text(m, section)) for m, v in section.methods.items()})
