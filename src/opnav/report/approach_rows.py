"""Paper A's variants and A-T1 rows as the claims read them (:mod:`opnav.report.approach_claims`).

A variant label (the A-T1 ``variant`` column, ``roll+growing+squarem``) names the scenario and
the additions to the paper as written; :func:`addition` and :func:`short_addition` say them in
words. The row readers take one A-T1 row (a ``pandas.Series``) or the rows of one variant.
Units: arcsec, samples.
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from opnav.approach.summaries import AS_WRITTEN
from opnav.report.claims import Outcome, fmt, join

__all__ = ["BEYOND", "DIAGNOSTIC", "HEADLINE_CASE", "addition", "bound_arcsec", "bound_text", "converged_seeds",
           "headline_row", "is_beyond", "is_diagnostic", "label_text", "rms_err_arcsec", "run_label",
           "short_addition", "truthy", "variant_labels", "variant_outcome", "variant_rows", "worst_vs_bound"]

DIAGNOSTIC = "reference-start"
HEADLINE_CASE = "T1-01"

_ADDITIONS = {
    "prior": "EM segments started from the prior (another reading of the paper's EM start)",
    "roll": "a camera that rolls about its boresight (not in the paper)",
    "squarem": "SQUAREM-accelerated EM",
    "growing": "growing data windows instead of sliding segments",
    "reference-start": "the true state as the E-step reference (diagnostic)",
    "stars": "star-field images that calibrate the camera (beyond the paper)",
}
#: variants beyond the paper (what practitioners do): reported, never a best faithful variant
BEYOND = ("stars",)


_SHORT = {"prior": "a prior start", "roll": "a boresight roll", "squarem": "SQUAREM", "growing": "growing windows",
          "reference-start": "the true reference", "stars": "star images"}


def short_addition(label: str) -> str:
    """The additions of a variant label in a few words ('a boresight roll, growing windows and SQUAREM')."""
    return join([_SHORT.get(p, p) for p in label.split("+") if p != AS_WRITTEN], none="nothing")


def addition(label: str) -> str:
    """What a variant label (``roll+growing+squarem``) adds to the paper as written."""
    parts = [p for p in label.split("+") if p != AS_WRITTEN]
    return join([_ADDITIONS.get(p, p) for p in parts], none="nothing")


def truthy(x: Any) -> bool:
    return str(x).strip().lower() in ("true", "1", "1.0") if not isinstance(x, bool) else x


def variant_rows(t1: pd.DataFrame, label: str) -> pd.DataFrame:
    return t1[t1["variant"] == label]


def headline_row(t1: pd.DataFrame, label: str) -> pd.Series | None:
    h = t1[(t1["variant"] == label) & (t1["case_id"] == HEADLINE_CASE)]
    return h.iloc[0] if len(h) else None


def run_label(r) -> str:
    """The run's label from the data (A-T1 ``label``: converged | stalled | not converged);
    older tables without it: stalled or converged from the stall flag."""
    lab = r.get("label") if hasattr(r, "get") else None
    if isinstance(lab, str) and lab:
        return lab
    return "stalled" if truthy(r["stalled"]) else "converged"


def converged_seeds(r) -> int:
    c = r.get("converged_seeds") if hasattr(r, "get") else None
    if c is not None and not pd.isna(c):
        return int(c)
    return int(r["n_seeds"]) - int(r["stalled_seeds"])


def label_text(r) -> str:
    """'converged, 3/3 seeds' / 'stalled, 1/3 seeds converged'."""
    lab, n = run_label(r), int(r["n_seeds"])
    c = converged_seeds(r)
    return f"{lab}, {c}/{n} seeds" if lab == "converged" else f"{lab}, {c}/{n} seeds converged"


def variant_labels(t1: pd.DataFrame, full_only: bool = False) -> list[str]:
    """Variant labels in table order; ``full_only``: those with every case of the literal rows."""
    labels = list(dict.fromkeys(t1["variant"]))
    if full_only:
        n = len(variant_rows(t1, AS_WRITTEN)) or max(len(variant_rows(t1, v)) for v in labels)
        labels = [v for v in labels if len(variant_rows(t1, v)) >= n]
    return labels


def is_diagnostic(label: str) -> bool:
    return label.split("+")[0] == DIAGNOSTIC


def is_beyond(label: str) -> bool:
    return label.split("+")[0] in BEYOND


def variant_outcome(label: str, ok: bool, text: str, score: float, err: float = math.nan, bound: float = math.nan,
             n: int = 0) -> Outcome:
    """An outcome with the variant's kind (diagnostic, beyond the paper) set from its label."""
    return Outcome(label, ok, text, score=score, diagnostic=is_diagnostic(label), beyond=is_beyond(label),
                   err=err, bound=bound, n=n)


def rms_err_arcsec(r) -> float:
    """RMS error about the truth over the seeds, the larger axis (arcsec)."""
    return max(float(r["rmse_x_arcsec"]), float(r["rmse_y_arcsec"]))


def bound_arcsec(r) -> float:
    """The bound of the data used, the larger axis (arcsec)."""
    return max(float(r["crlb_x_arcsec"]), float(r["crlb_y_arcsec"]))


def bound_text(r) -> str:
    """'CRLB 20.6 arcsec (data used), 20.6 with Q = 0' (the larger axis)."""
    b = bound_arcsec(r)
    q0 = r.get("crlb_q0_x_arcsec") if hasattr(r, "get") else None
    q0s = "" if q0 is None or pd.isna(q0) else f", {fmt(float(q0))} with Q = 0"
    return f"CRLB {fmt(b)} arcsec (data used){q0s}"


def worst_vs_bound(g: pd.DataFrame) -> tuple[float, float, int]:
    """(err, bound, seeds) of the row of ``g`` whose error is furthest below its bound
    (the row the bound guard judges)."""
    best = max(g.iterrows(), key=lambda ir: bound_arcsec(ir[1]) / max(rms_err_arcsec(ir[1]), 1e-300))[1]
    return rms_err_arcsec(best), bound_arcsec(best), int(best["n_seeds"])
