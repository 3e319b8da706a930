"""Paper A's convergence label of one run (SPEC A.3c, labels from the data).

A run's seeds carry :func:`opnav.approach.em.convergence_labels`; :func:`row_label` takes the
majority and :func:`label_columns` gives the A-T1 columns built from it. :func:`variant_label`
names a row (scenario, window mode, EM scheme): its identifier in A-T1 and A-summary.json. What
a label means in words (the reading) is the report's (:mod:`opnav.report.approach.text`).
Units: arcsec, samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def variant_label(variant: str, method: str, mode: str = "sliding") -> str:
    """Row label: the scenario name, with '+growing' for growing windows and '+squarem'
    for the accelerated EM (plain EM on sliding windows is the paper's scheme)."""
    return variant + ("+growing" if mode == "growing" else "") + ("" if method == "plain" else f"+{method}")


LABEL_ORDER = ("converged", "not converged", "stalled")  # em.CONVERGED, em.UNFINISHED, em.STALLED


def row_label(labels) -> tuple[str, dict[str, int]]:
    """A row's convergence label from its seeds' (:func:`opnav.approach.em.convergence_labels`):
    the label more than half of the seeds carry, else ``not converged``; and the count of each."""
    labels = np.asarray(labels, str)
    counts = {lab: int(np.sum(labels == lab)) for lab in LABEL_ORDER}
    major = [lab for lab in LABEL_ORDER if counts[lab] > labels.size / 2]
    return (major[0] if major else "not converged"), counts


@dataclass(frozen=True)
class LabelColumns:
    """A-T1's label columns of one run (SPEC A.3c, labels from the data; :func:`label_columns`):
    the row label and the seeds of each label, ``stalled`` (kept for readers of the old column),
    the distance moved from the start, the contraction per map (median), the distance to and in
    bounds of (mean) and the ML estimate (mean tx, ty) of the data used, whether the bound of the
    data used reaches the target (``identifiable``) and the data to converge (median over the
    converged seeds). The field order is A-T1's (its ``reading`` column, the report's, follows
    ``identifiable``)."""

    label: str
    converged_seeds: int
    stalled: bool
    stalled_seeds: int
    moved_arcsec: float
    contraction_per_map: float
    dist_to_ml_arcsec: float
    dist_to_ml_over_bound: float
    ml_x_mean: float
    ml_y_mean: float
    identifiable: bool
    data_to_converge_samples: float


def label_columns(r, target_arcsec: float) -> LabelColumns:
    """:class:`LabelColumns` of one run, ``r``: a :class:`opnav.approach.cases.CaseRun` with its
    bounds (:func:`opnav.approach.pipeline.run_group`); ``target_arcsec``: the claimed accuracy."""
    lab, counts = row_label(r.label)
    conv = np.asarray(r.data_to_converge, float)
    ok = conv[np.isfinite(conv)]
    crlb = r.bounds.crlb_arcsec
    bound = float(max(crlb[0], crlb[1]))
    rate = (float(np.nanmedian(r.contraction_per_map)) if np.isfinite(r.contraction_per_map).any()
            else math.nan)
    return LabelColumns(
        label=lab, converged_seeds=counts["converged"], stalled=lab == "stalled", stalled_seeds=counts["stalled"],
        moved_arcsec=float(np.mean(r.moved_arcsec)), contraction_per_map=rate,
        dist_to_ml_arcsec=float(np.mean(r.dist_to_ml_arcsec)),
        # the label's scale (issue 44): the distance in 1-sigma bounds of the data used (max of tx, ty)
        dist_to_ml_over_bound=float(np.mean(r.dist_to_ml_over_bound)),
        ml_x_mean=float(np.mean(r.theta_ml_arcsec[:, 0])), ml_y_mean=float(np.mean(r.theta_ml_arcsec[:, 1])),
        identifiable=bound <= target_arcsec,
        data_to_converge_samples=float(np.median(ok)) if ok.size else math.nan)
