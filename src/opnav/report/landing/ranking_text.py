"""B-X1's headline in words (``opnav.landing.ranking.headline``'s record): its lists of methods
as the manuscript macros quote them (``"svd, gdop"``, ``"none"``), the methods of accuracy rank 1
joined by ``=``, and each searching method's median |beta*| (``"depth 60 deg"``), written beside
the record's fields in B-X1-summary.json (:class:`WordedHeadline`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from opnav.landing.ranking import Headline

__all__ = ["names_text", "WordedHeadline", "worded_headline"]


def names_text(names) -> str:
    """Methods in words: ``"svd, gdop"``; ``"none"`` for none."""
    return ", ".join(names) if names else "none"


@dataclass(frozen=True)
class WordedHeadline:
    """A B-X1 :class:`~opnav.landing.ranking.Headline` (its fields at the top level) with its lists
    in words."""

    headline: "Headline" = field(metadata={"json_flatten": True})
    best_accuracy_method: str
    ranking_by_accuracy_text: str
    ranking_by_time_text: str
    reference_more_accurate_than_text: str
    reference_less_accurate_than_text: str
    not_significant_vs_reference_text: str
    reference_faster_than_text: str
    median_abs_beta_text: str


def worded_headline(h: "Headline") -> WordedHeadline:
    """``h`` with its words: every list by :func:`names_text`, the best-accuracy methods joined by
    ``" = "`` (ties are ties) and each searching method's median |beta*| to 3 significant digits."""
    return WordedHeadline(
        h, " = ".join(h.best_accuracy_methods), names_text(h.ranking_by_accuracy), names_text(h.ranking_by_time),
        names_text(h.reference_more_accurate_than), names_text(h.reference_less_accurate_than),
        names_text(h.not_significant_vs_reference), names_text(h.reference_faster_than),
        ", ".join(f"{m} {v:.3g} deg" for m, v in h.median_abs_beta_deg.items()) or "none")
