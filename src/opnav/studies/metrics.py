"""What a parameter study can tabulate, per paper, and which statistic its figure shows."""

from __future__ import annotations

from collections.abc import Mapping

__all__ = [
    "APPROACH_METHODS",
    "CONSTANT_METRICS",
    "DEFAULT_METHODS",
    "DEFAULT_METRICS",
    "METRICS",
    "SHARE_METRICS",
    "STATISTICS",
    "TIMING_METRICS",
    "shown_statistic",
    "table_metrics",
]

#: Per-run metrics a study can tabulate: name -> (label with unit, CRLB column or None).
METRICS: dict[str, dict[str, tuple[str, str | None]]] = {
    "landing": {
        "final_pos_err_m": ("final position error (m)", None),
        "rms_pos_err_m": ("RMS position error (m)", None),
        "final_vel_err_mps": ("final velocity error (m/s)", None),
        "rms_vel_err_mps": ("RMS velocity error (m/s)", None),
        "final_att_err_deg": ("final attitude error (deg)", None),
        "rms_att_err_deg": ("RMS attitude error (deg)", None),
        "mean_nees_pos": ("mean position NEES (-)", None),
        "mean_nees_vel": ("mean velocity NEES (-)", None),
        "n_landmarks": ("landmarks used per run (-)", None),
        "converged_pct": ("runs converged (%)", None),
        "median_plan_time_us": ("median planning time (us)", None),
        "median_plan_cpu_us": ("median planning CPU time (us)", None),
        "no_pick_pct": ("plans choosing no landmark (%)", None),
    },
    "approach": {
        "err_x_arcsec": ("tx estimate - truth (arcsec)", "crlb_x_arcsec"),
        "err_y_arcsec": ("ty estimate - truth (arcsec)", "crlb_y_arcsec"),
        "err_z_arcsec": ("tz estimate - truth (arcsec)", None),
        "crlb_x_arcsec": ("1-sigma CRLB of tx, all data (arcsec)", None),
        "crlb_y_arcsec": ("1-sigma CRLB of ty, all data (arcsec)", None),
        "crlb_used_x_arcsec": ("1-sigma CRLB of tx, data the estimator used (arcsec)", None),
        "crlb_used_y_arcsec": ("1-sigma CRLB of ty, data the estimator used (arcsec)", None),
        "stalled_pct": ("EM seeds the stall rule flags (%)", None),
        "converged_pct": ("EM seeds labelled converged (%)", None),
        "nav_err_after_km": ("RMS nav. error after compensation (km)", None),
        "data_to_converge_samples": ("data needed to converge (samples)", None),
    },
}
#: Metrics that are one number per value and method (the same for every run): tables and
#: figures show their value (the mean), whatever the study's statistic.
CONSTANT_METRICS = frozenset({"crlb_x_arcsec", "crlb_y_arcsec", "crlb_used_x_arcsec", "crlb_used_y_arcsec"})
#: Per-run 0/100 indicators: their mean is the share of runs, whatever the study's statistic.
SHARE_METRICS = frozenset({"converged_pct", "stalled_pct"})
DEFAULT_METRICS = {"landing": ["final_pos_err_m", "rms_pos_err_m", "mean_nees_pos"],
                   "approach": ["err_x_arcsec", "err_y_arcsec", "nav_err_after_km"]}
DEFAULT_METHODS = {"landing": ["depth", "svd"], "approach": ["em", "augmented"]}
#: Paper-A estimators: em = EM-EKF with approach.em.method; augmented = augmented EKF.
APPROACH_METHODS = ("em", "em_plain", "em_squarem", "em_growing_squarem", "augmented")
STATISTICS = ("mean", "sd", "rms")
#: per-run metrics measured by replaying the runs' planning calls (opnav.landing.timing)
TIMING_METRICS = ("median_plan_time_us", "median_plan_cpu_us")


def table_metrics(study: Mapping) -> list[str]:
    """The study's metrics and, after them, the bounds they are compared with (paper A CRLB)."""
    mets = list(study["metrics"])
    bounds = [METRICS[study["paper"]][m][1] for m in mets]
    return mets + [b for b in dict.fromkeys(bounds) if b and b not in mets]


def shown_statistic(study: Mapping, metric: str) -> str:
    """The statistic a figure draws for ``metric``: the study's; the value (mean) of a
    metric that is the same for every run (:data:`CONSTANT_METRICS`); the share (mean) of a
    0/100 indicator (:data:`SHARE_METRICS`)."""
    return "mean" if metric in CONSTANT_METRICS | SHARE_METRICS else study["statistic"]
