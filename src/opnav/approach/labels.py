"""Paper A's convergence label and reading of one run (SPEC A.3c, labels from the data).

A run's seeds carry :func:`opnav.approach.em.convergence_labels`; :func:`row_label` takes the
majority, :func:`reading_text` says what the label and the bound of the data used mean, and
:func:`label_columns` gives the A-T1 columns built from them. :func:`variant_label` names a
row (scenario, window mode, EM scheme). Units: arcsec, samples.
"""

from __future__ import annotations

import math

import numpy as np

from . import scenario as sc


def variant_label(variant: str, method: str, mode: str = "sliding") -> str:
    """Row label: the scenario name, with '+growing' for growing windows and '+squarem'
    for the accelerated EM (plain EM on sliding windows is the paper's scheme)."""
    return variant + ("+growing" if mode == "growing" else "") + ("" if method == "plain" else f"+{method}")


LABEL_ORDER = ("converged", "not converged", "stalled")  # em.CONVERGED, em.UNFINISHED, em.STALLED


def row_label(labels) -> tuple[str, dict]:
    """A row's convergence label from its seeds' (:func:`opnav.approach.em.convergence_labels`):
    the label more than half of the seeds carry, else ``not converged``; and the count of each."""
    labels = np.asarray(labels, str)
    counts = {lab: int(np.sum(labels == lab)) for lab in LABEL_ORDER}
    major = [lab for lab in LABEL_ORDER if counts[lab] > labels.size / 2]
    return (major[0] if major else "not converged"), counts


def bound_cause(start: str, mode: str, window: int) -> str:
    """Why the data used cannot tell theta apart (the cause half of the identifiability reading)."""
    if start == "filter":
        return "the window's start, from the theta = 0 filter, has absorbed rho*theta"
    if mode == "sliding":
        return f"one {window}-sample window holds too little information"
    return "the data and prior cannot separate theta from a lateral position error"


def reading_text(label: str, counts: dict, n: int, bound_arcsec: float, target_arcsec: float,
                 dist_ml_arcsec: float, rate: float, cause: str = "") -> str:
    """One run's reading: its convergence label (what the iteration reached on its data) and,
    for a converged one, what the bound of that data says the estimate can mean:
    ``converged (3/3); not identifiable from this data (bound 20.6 arcsec): <cause>``."""
    k = counts.get(label, 0)
    if label == "converged":
        if bound_arcsec > target_arcsec:
            return (f"converged ({k}/{n}); not identifiable from this data (bound {bound_arcsec:.3g} arcsec)"
                    + (f": {cause}" if cause else ""))
        return f"converged ({k}/{n}); bound {bound_arcsec:.3g} arcsec"
    rate_txt = "n/a" if rate is None or not math.isfinite(rate) else f"{rate:.4g}"
    return (f"{label} ({k}/{n}): {dist_ml_arcsec:.3g} arcsec from the ML estimate of its data, "
            f"contraction {rate_txt} per map")


def label_columns(r, target_arcsec: float) -> dict:
    """A-T1 label columns of one run (SPEC A.3c, labels from the data): the row label and the
    seeds of each label, ``stalled`` (kept for readers of the old column), the distance to and
    the ML estimate of the data used, the contraction per map, whether the bound of the data
    used reaches ``target_arcsec`` (``identifiable``), the reading sentence, and the data to
    converge (median over the converged seeds). ``r``: a :class:`opnav.approach.cases.CaseRun`
    with its bounds (:func:`opnav.approach.pipeline.run_group`)."""
    lab, counts = row_label(r.label)
    conv = np.asarray(r.data_to_converge, float)
    ok = conv[np.isfinite(conv)]
    crlb = r.bounds.crlb_arcsec
    bound = float(max(crlb[0], crlb[1]))
    rate = (float(np.nanmedian(r.contraction_per_map)) if np.isfinite(r.contraction_per_map).any()
            else math.nan)
    dist = float(np.mean(r.dist_to_ml_arcsec))
    seg = np.asarray(r.seg_data_used)
    cause = bound_cause(sc.START_OF[r.variant], r.mode, int(seg[0]))
    return {
        "label": lab,
        "converged_seeds": counts["converged"],
        "stalled": lab == "stalled",
        "stalled_seeds": counts["stalled"],
        "moved_arcsec": float(np.mean(r.moved_arcsec)),
        "contraction_per_map": rate,
        "dist_to_ml_arcsec": dist,
        # the label's scale (issue 44): the distance in 1-sigma bounds of the data used (max of tx, ty)
        "dist_to_ml_over_bound": float(np.mean(r.dist_to_ml_over_bound)),
        "ml_x_mean": float(np.mean(r.theta_ml_arcsec[:, 0])),
        "ml_y_mean": float(np.mean(r.theta_ml_arcsec[:, 1])),
        "identifiable": bound <= target_arcsec,
        "reading": reading_text(lab, counts, len(conv), bound, target_arcsec, dist, rate, cause),
        "data_to_converge_samples": float(np.median(ok)) if ok.size else math.nan,
    }
