"""The reproduced-vs-published scorecard.

Every number either paper publishes is set beside ours (mean and spread over
our Monte-Carlo seeds), with the difference and a verdict:

``reproduced``
    The published value lies inside our Monte-Carlo band:
    ``|ours - published| <= max(K_SPREAD * spread, REL_TOL * |published|, abs_tol)``
    with ``K_SPREAD = 2`` (about a 95 % band of our run-to-run spread),
    ``REL_TOL = 0.10`` (10 % of the published value) and ``abs_tol`` a
    per-quantity floor for values published with few digits (0.5 arcsec for
    bias estimates, 1 sample-segment for data lengths; 0 otherwise).
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

import pandas as pd

K_SPREAD = 2.0
REL_TOL = 0.10

REPRODUCED = "reproduced"
NOT_REPRODUCED = "not reproduced"
NOT_REPRODUCIBLE = "not reproducible under stated assumptions"


@dataclass(frozen=True)
class Verdict:
    verdict: str
    reason: str


def tolerance(published: float, spread: float | None, abs_tol: float = 0.0) -> float:
    """Half-width of the 'reproduced' band around our mean (see module docstring)."""
    s = 0.0 if spread is None or math.isnan(spread) else K_SPREAD * abs(spread)
    return max(s, REL_TOL * abs(published), abs_tol)


def judge(published: float, ours: float, spread: float | None = None, abs_tol: float = 0.0,
          truth: float | None = None, crlb: float | None = None, unit: str = "") -> Verdict:
    """Verdict for one published number against our mean (and spread, CRLB where known)."""
    if ours is None or (isinstance(ours, float) and math.isnan(ours)):
        return Verdict(NOT_REPRODUCED, "no value computed")
    tol = tolerance(published, spread, abs_tol)
    diff = ours - published
    u = f" {unit}" if unit else ""
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


def score_rows(rows: list[dict]) -> pd.DataFrame:
    """Score a list of dicts with keys paper, item, published, ours, spread, unit
    (and optional truth, crlb, abs_tol, verdict/reason for pre-judged claims)."""
    out = []
    for r in rows:
        if "verdict" in r:
            v = Verdict(r["verdict"], r["reason"])
        else:
            v = judge(r["published"], r["ours"], r.get("spread"), r.get("abs_tol", 0.0),
                      r.get("truth"), r.get("crlb"), r.get("unit", ""))
        pub, ours = r.get("published"), r.get("ours")
        diff = (ours - pub) if isinstance(pub, (int, float)) and isinstance(ours, (int, float)) else float("nan")
        out.append({
            "paper": r["paper"],
            "item": r["item"],
            "unit": r.get("unit", ""),
            "published": pub,
            "ours (mean)": ours,
            "ours (spread)": r.get("spread", float("nan")),
            "difference": diff,
            "verdict": v.verdict,
            "reason": v.reason,
        })
    return pd.DataFrame(out)
