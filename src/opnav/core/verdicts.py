"""The verdict rule: is a published number reproduced by ours?

Every number either paper publishes is set beside ours (mean and spread over
our Monte-Carlo seeds), with the difference and a verdict:

``reproduced``
    The published value lies inside our Monte-Carlo band:
    ``|ours - published| <= max(K_SPREAD * spread, REL_TOL * |published|, abs_tol)``
    with ``K_SPREAD = 2`` (about a 95 % band of our run-to-run spread),
    ``REL_TOL = 0.10`` (10 % of the published value) and ``abs_tol`` a
    per-quantity floor for values published with few digits (0.5 arcsec for
    bias estimates; 0 otherwise), *and* our band is narrow enough to mean
    something: ``K_SPREAD * spread <= max(MAX_BAND_REL * |published|, abs_tol)``
    with ``MAX_BAND_REL = 0.5``. A published value that falls inside a band wider
    than that is only "consistent because our runs scatter widely" and is
    scored *not reproduced*, with that reason.
``not reproducible under stated assumptions``
    Not reproduced, and the information bound says it cannot be: the published
    accuracy |published - truth| is finer than the Cramér-Rao 1-sigma bound of
    the variant (no unbiased estimator using the stated measurements and
    prior could reach it except by luck).
``not reproduced``
    Anything else; the reason states the numbers.

A qualitative claim (e.g. "errors almost the same") is scored by a stated
numeric reading of it, written in the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

K_SPREAD = 2.0
REL_TOL = 0.10
MAX_BAND_REL = 0.5

REPRODUCED = "reproduced"
NOT_REPRODUCED = "not reproduced"
NOT_REPRODUCIBLE = "not reproducible under stated assumptions"


@dataclass(frozen=True)
class Verdict:
    verdict: str
    reason: str


def tolerance(published: float, spread: float | None, abs_tol: float = 0.0, *,
              rel_tol: float = REL_TOL, k_spread: float = K_SPREAD) -> float:
    """Half-width of the 'reproduced' band around our mean (see module docstring); a
    claim whose analysis-plan entry states its own rel_tol / spread_k passes them."""
    s = 0.0 if spread is None or math.isnan(spread) else k_spread * abs(spread)
    return max(s, rel_tol * abs(published), abs_tol)


def judge(published: float, ours: float, spread: float | None = None, abs_tol: float = 0.0,
          truth: float | None = None, crlb: float | None = None, unit: str = "", *,
          rel_tol: float = REL_TOL, k_spread: float = K_SPREAD, max_band_rel: float = MAX_BAND_REL) -> Verdict:
    """Verdict for one published number against our mean (and spread, CRLB where known);
    ``rel_tol``, ``k_spread``, ``max_band_rel``: the band's numbers (default: this module's)."""
    if ours is None or (isinstance(ours, float) and math.isnan(ours)):
        return Verdict(NOT_REPRODUCED, "no value computed")
    tol = tolerance(published, spread, abs_tol, rel_tol=rel_tol, k_spread=k_spread)
    diff = ours - published
    u = f" {unit}" if unit else ""
    band = 0.0 if spread is None or math.isnan(spread) else k_spread * abs(spread)
    if abs(diff) <= tol and band > max(max_band_rel * abs(published), abs_tol):
        return Verdict(NOT_REPRODUCED, f"inside our band only because it is wide: {k_spread:g} sd = {band:.3g}{u} "
                                       f"> {100 * max_band_rel:.0f} % of the published value")
    if abs(diff) <= tol:
        return Verdict(REPRODUCED, f"|diff| {abs(diff):.3g}{u} within tolerance {tol:.3g}{u}")
    if truth is not None and crlb is not None and not math.isnan(crlb):
        pub_err = abs(published - truth)
        if crlb > pub_err:
            return Verdict(
                NOT_REPRODUCIBLE,
                f"published error {pub_err:.3g}{u} is below the CRLB 1-sigma {crlb:.3g}{u}",
            )
    return Verdict(NOT_REPRODUCED, f"|diff| {abs(diff):.3g}{u} exceeds tolerance {tol:.3g}{u}")
