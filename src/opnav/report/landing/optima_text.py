"""B-C8's optima count in words (``opnav.landing.optima.count_summary``'s record): one sentence
per scenario (:func:`optima_text`), written beside the count in ``optima/<camera>.json``
(``report.landing.equivalence_text.Worded``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from opnav.landing.optima import OptimaSummary

__all__ = ["optima_text"]


def optima_text(s: "OptimaSummary") -> str:
    """How many planning calls show more than one local minimum of the depth error on a side of
    the velocity, on how many angles a side, and the calls left out."""
    return (f"{s.scenario} camera: {s.calls_multi_minimum} of {s.n_calls} planning calls ({s.method}) show more "
            f"than one local minimum of the depth error on a side of the velocity ({s.n_grid} angles a side; "
            f"{s.calls_skipped} calls without a plane or baseline left out)")
