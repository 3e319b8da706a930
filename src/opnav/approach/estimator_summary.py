"""A user's own misalignment estimators (``approach.custom_estimators``, :mod:`opnav.approach.estimators`)
in numbers: the A-T1-style table, one row per variant x estimator x Table-1 case.

Pure functions of :func:`opnav.approach.estimators.run_case`'s results. Columns: the truth and the
initial value (arcsec); the final estimate's mean and sd over seeds and its error about the truth
(tx, ty; arcsec); the Cramér-Rao bound of the data the estimate used (``bound_``: the growing data
after N0 from the variant's start, at the truth) and the RMS error over seeds in units of it
(``err_over_bound_``: about 1 for an efficient estimator); the estimator's own sigma where it
returns a covariance (mean over seeds; NaN if not); data to converge (median over seeds, samples;
Table 1's rule); the navigation error before and after compensation (mean over seeds, km; Table
1's rule) and the run time per call (s, this machine). Units: arcsec, samples, km, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from .summaries import seed_sd

if TYPE_CHECKING:
    from .estimators import CaseRun

__all__ = ["long_frame", "curves"]


def long_frame(results: "list[CaseRun]") -> pd.DataFrame:
    """One row per variant x estimator x case of the results (module docstring)."""
    rows = []
    for r in results:
        truth, b = np.asarray(r.truth_arcsec, float), np.asarray(r.bound_seg_arcsec, float)[-1]
        for name, e in r.estimators.items():
            th = np.asarray(e.theta_final_arcsec, float)
            err = th[:, :2] - truth[:2]
            sig = np.asarray(e.sigma_final_arcsec, float)
            row = {"variant": r.variant, "estimator": name, "label": e.label, "group": r.case.group,
                   "case_id": r.case_id, "truth_x_arcsec": truth[0], "truth_y_arcsec": truth[1],
                   "init_x_arcsec": float(r.init_arcsec[0]), "init_y_arcsec": float(r.init_arcsec[1]),
                   "n_seeds": th.shape[0], "data_used_samples": int(r.seg_data_used[-1])}
            for j, ax in enumerate("xy"):
                row[f"est_{ax}_mean_arcsec"] = float(th[:, j].mean())
                row[f"est_{ax}_sd_arcsec"] = seed_sd(th[:, j])
                row[f"err_{ax}_mean_arcsec"] = float(err[:, j].mean())
                row[f"bound_{ax}_arcsec"] = float(b[j])
                row[f"err_over_bound_{ax}"] = float(np.sqrt(np.mean(err[:, j] ** 2)) / b[j]) if b[j] > 0 else math.nan
                row[f"sigma_{ax}_mean_arcsec"] = float(np.mean(sig[:, j])) if np.isfinite(sig[:, j]).all() else math.nan
            row["rmse_xy_arcsec"] = float(np.sqrt(np.mean(err ** 2)))
            dtc = np.asarray(e.data_to_converge, float)
            row["data_to_converge_samples"] = float(np.median(dtc)) if dtc.size else math.nan
            row["nav_err_before_km"] = float(np.mean(r.nav_err_before_km))
            row["nav_err_after_km"] = float(np.mean(e.nav_err_after_km))
            row["runtime_s_per_call"] = float(e.runtime_s_per_call)
            row["path"] = e.path
            rows.append(row)
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class Curves:
    """The convergence curves of one case and variant (:func:`curves`): data used (samples after
    N0), the truth (3,), the bound per window (L, 3), and per estimator its estimates (seeds, L, 3;
    arcsec) and its legend label."""

    data: np.ndarray
    truth: np.ndarray
    bound: np.ndarray
    estimators: dict[str, np.ndarray]
    labels: dict[str, str]


def curves(results: "list[CaseRun]", case_id: str = "T1-01") -> dict[str, Curves]:
    """:class:`Curves` of case ``case_id`` per variant, from the estimators' runs
    (:func:`opnav.approach.estimators.run_case`)."""
    out = {}
    for r in results:
        if r.case_id != case_id:
            continue
        out[r.variant] = Curves(data=np.asarray(r.seg_data_used), truth=np.asarray(r.truth_arcsec, float),
                                   bound=np.asarray(r.bound_seg_arcsec, float),
                                   estimators={n: np.asarray(e.theta_seg_arcsec, float)
                                               for n, e in r.estimators.items()},
                                   labels={n: e.label for n, e in r.estimators.items()})
    return out
