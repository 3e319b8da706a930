"""A-X2 (the alternatives to the EM-EKF: augmented EKF, batch ML) in numbers: one row per
variant x method x case, the per-method table and A-X2-summary.json.

Pure functions of :func:`opnav.approach.alternatives.run_case_alternatives` and the EM-EKF
Monte Carlo (:func:`opnav.approach.pipeline.run_group`). Units: arcsec, km, samples, s.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from opnav.core.tables import OMIT_NONE

from . import scenario as sc
from .alternatives import AltRun, BatchMLResult
from .cases import CaseRun
from .labels import row_label
from .setup import Setup
from .summaries import seed_sd

#: A-X2's methods, in the table's order (their words: opnav.report.approach.text.METHOD_LABELS)
METHODS = ("em_plain", "em_squarem", "augmented", "batch_ml")


def long_frame(alt_results: list[AltRun], em_results: list[CaseRun], em_times: dict) -> pd.DataFrame:
    """One row per variant x method x case: error, spread, CRLB, nav error, data, run time (the
    methods' words, column ``method_label``, are the report's: :func:`opnav.report.approach.text.with_method_labels`).

    ``em_results``: the EM-EKF Monte-Carlo runs (:func:`opnav.approach.pipeline.run_group`);
    ``em_times``: {variant: {"em_plain": s, ...}} measured on the headline case.
    """
    nan3 = np.full(3, np.nan)
    crlb = {(r.variant, r.case_id): r.bounds.crlb_total_arcsec for r in em_results}
    crlb0 = {(r.variant, r.case_id): r.bounds.crlb_total_q0_arcsec for r in em_results}
    rows = []

    def add(variant, case, method, truth, th, nav, data, runtime, extra=None, used=None, used_q0=None):
        """``used``/``used_q0``: the bound of the data the estimate used (default: all the data)."""
        err = th[:, :2] - truth[:2]
        key = (variant, case.case_id)
        cb = crlb.get(key, nan3) if used is None else used
        cb0 = crlb0.get(key, nan3) if used_q0 is None else used_q0
        row = {
            "variant": variant, "method": method,
            "group": case.group, "case_id": case.case_id,
            "truth_x_arcsec": truth[0], "truth_y_arcsec": truth[1],
            "n_seeds": th.shape[0],
            "err_x_mean_arcsec": float(err[:, 0].mean()), "err_x_std_arcsec": seed_sd(err[:, 0]),
            "err_y_mean_arcsec": float(err[:, 1].mean()), "err_y_std_arcsec": seed_sd(err[:, 1]),
            "rmse_xy_arcsec": float(np.sqrt(np.mean(err**2))),
            # the bound of the data this estimate used (one window for sliding EM; all the data for
            # the augmented EKF and batch ML), Q = 0 beside it (the truth has no process noise)
            "crlb_x_arcsec": float(cb[0]), "crlb_y_arcsec": float(cb[1]),
            "crlb_q0_x_arcsec": float(cb0[0]), "crlb_q0_y_arcsec": float(cb0[1]),
            "crlb_all_x_arcsec": float(crlb.get(key, nan3)[0]),
            "nav_err_after_km": float(np.mean(nav)),
            "data_to_converge_samples": float(np.median(data)) if data is not None else math.nan,
            "runtime_s_per_seed": runtime,
        }
        row.update(extra or {})
        rows.append(row)

    for r in em_results:
        if r.mode != "sliding":
            continue
        m = f"em_{r.method}"
        if m not in METHODS:
            continue
        rt = em_times.get(r.variant, {}).get(m, math.nan) if r.case_id == "T1-01" else math.nan
        add(r.variant, r.case, m, np.asarray(r.truth_arcsec, float), r.theta_final_arcsec,
            r.nav_err_after_km, r.data_to_converge, rt,
            {"nav_err_before_km": float(np.mean(r.nav_err_before_km)),
             "label": row_label(r.label)[0], "stalled_seeds": int(np.sum(r.stalled))},
            used=r.bounds.crlb_arcsec, used_q0=r.bounds.crlb_q0_arcsec)
    for r in alt_results:
        for m, d in r.methods():
            extra = {}
            if isinstance(d, BatchMLResult):
                extra = {"ipopt_max_grad_norm": float(np.max(d.grad_norm)),
                         "ipopt_all_success": bool(np.all(d.ipopt_success)),
                         "ipopt_iterations_median": float(np.median(d.ipopt_iterations)),
                         "runtime_solve_s_per_seed": d.runtime_solve_s_per_seed,
                         "runtime_build_s": d.runtime_build_s,
                         "runtime_checkpoints_s_per_seed": d.runtime_checkpoints_s_per_seed,
                         "data_seeds": d.checkpoint_seeds}
            add(r.variant, r.case, m, r.truth_arcsec, d.theta_final_arcsec,
                d.nav_err_after_km, d.data_to_converge, d.runtime_s_per_seed, extra)
    df = pd.DataFrame(rows)
    vorder = {v: i for i, v in enumerate(sc.VARIANTS)}
    morder = {m: i for i, m in enumerate(METHODS)}
    df = df.assign(_v=df["variant"].map(vorder), _m=df["method"].map(morder))
    return df.sort_values(["_v", "_m", "case_id"], kind="stable").drop(columns=["_v", "_m"]).reset_index(drop=True)


@dataclass(frozen=True)
class MethodSummary:
    """A-X2 for one variant and method (one of :data:`METHODS`), by meaning (issue 41
    item 4): the headline case (T1-01; NaN, label '' without it) and the all-case aggregates.
    The page's column names and method labels are the report's
    (:func:`opnav.report.approach_views.x2_table`).

    ``head_err_*``: estimate minus truth, seed mean and sd (arcsec); ``head_crlb_x*``: the
    bound of the data the estimate used, with Q = 0, and of all the data (arcsec);
    ``rmse_xy_all_arcsec``: RMS error over every case; ``median_sd_all_arcsec`` /
    ``median_crlb_all_arcsec``: medians over the cases' tx and ty; navigation errors after
    compensation (km), data to converge (samples), run time (s per Monte-Carlo seed).
    """

    variant: str
    method: str
    n_cases: int
    n_seeds: int
    head_err_x_mean_arcsec: float
    head_err_x_sd_arcsec: float
    head_err_y_mean_arcsec: float
    head_err_y_sd_arcsec: float
    head_crlb_x_arcsec: float
    head_crlb_q0_x_arcsec: float
    head_crlb_all_x_arcsec: float
    head_label: str
    rmse_xy_all_arcsec: float
    median_sd_all_arcsec: float
    median_crlb_all_arcsec: float
    head_nav_err_after_km: float
    nav_err_after_all_km: float
    head_data_to_converge_samples: float
    median_data_to_converge_samples: float
    head_runtime_s_per_seed: float


def _headline_value(h: pd.Series | None, col: str) -> float:
    """``col`` of the headline-case row ``h`` (NaN without one)."""
    return float(h[col]) if h is not None else math.nan


def method_summaries(long: pd.DataFrame) -> tuple[MethodSummary, ...]:
    """A-X2 per variant and method (:class:`MethodSummary`), in the long frame's order."""
    out = []
    for (v, m), g in long.groupby(["variant", "method"], sort=False):
        h = g[g["case_id"] == "T1-01"]
        h = h.iloc[0] if len(h) else None
        head = functools.partial(_headline_value, h)
        out.append(MethodSummary(
            variant=v, method=m, n_cases=len(g), n_seeds=int(g["n_seeds"].max()),
            head_err_x_mean_arcsec=head("err_x_mean_arcsec"), head_err_x_sd_arcsec=head("err_x_std_arcsec"),
            head_err_y_mean_arcsec=head("err_y_mean_arcsec"), head_err_y_sd_arcsec=head("err_y_std_arcsec"),
            head_crlb_x_arcsec=head("crlb_x_arcsec"), head_crlb_q0_x_arcsec=head("crlb_q0_x_arcsec"),
            head_crlb_all_x_arcsec=head("crlb_all_x_arcsec"),
            head_label=(h["label"] if h is not None and isinstance(h.get("label"), str) else ""),
            rmse_xy_all_arcsec=float(np.sqrt(np.mean(g["rmse_xy_arcsec"] ** 2))),
            median_sd_all_arcsec=float(np.median(np.r_[g["err_x_std_arcsec"], g["err_y_std_arcsec"]])),
            median_crlb_all_arcsec=float(np.median(np.r_[g["crlb_x_arcsec"], g["crlb_y_arcsec"]])),
            head_nav_err_after_km=head("nav_err_after_km"),
            nav_err_after_all_km=float(g["nav_err_after_km"].mean()),
            head_data_to_converge_samples=head("data_to_converge_samples"),
            median_data_to_converge_samples=float(np.nanmedian(g["data_to_converge_samples"]))
            if g["data_to_converge_samples"].notna().any() else math.nan,
            head_runtime_s_per_seed=head("runtime_s_per_seed")))
    return tuple(out)


@dataclass(frozen=True)
class X2Head:
    """One variant and method of A-X2-summary.json: the headline case's error (seed mean and sd),
    bounds, label, navigation error, data to converge and run time, and the RMS error over every
    case (:class:`MethodSummary`'s fields under the summary's names)."""

    err_x_mean_arcsec: float
    err_x_sd_arcsec: float
    err_y_mean_arcsec: float
    err_y_sd_arcsec: float
    crlb_x_arcsec: float
    crlb_q0_x_arcsec: float
    crlb_all_x_arcsec: float
    label: str
    rmse_xy_all_cases_arcsec: float
    nav_err_after_km: float
    data_to_converge_samples: float
    runtime_s_per_seed: float


@dataclass(frozen=True)
class X2Summary:
    """A-X2-summary.json (:func:`summary_json`): the segments and alternatives' settings, per
    variant and method its :class:`X2Head`, the EM's navigation error before compensation per
    variant (headline case), batch ML's largest gradient norm and whether IPOPT succeeded
    everywhere (None: not run, left out), and the build's profile (set by the workflow)."""

    segments: Any
    alternatives: Any
    variants: dict[str, dict[str, X2Head]]
    nav_err_before_km: dict[str, float] | None = field(default=None, metadata=OMIT_NONE)
    batch_ml_max_grad_norm: float | None = field(default=None, metadata=OMIT_NONE)
    batch_ml_all_success: bool | None = field(default=None, metadata=OMIT_NONE)
    profile: str | None = field(default=None, metadata=OMIT_NONE)


def summary_json(long: pd.DataFrame, rows: Sequence[MethodSummary], setup: Setup) -> X2Summary:
    """Headline numbers per variant and method for the manuscript macros (A-X2-summary.json);
    ``rows``: :func:`method_summaries` of ``long``."""
    variants: dict[str, dict[str, X2Head]] = {}
    for r in rows:
        variants.setdefault(r.variant, {})[r.method] = X2Head(
            err_x_mean_arcsec=r.head_err_x_mean_arcsec, err_x_sd_arcsec=r.head_err_x_sd_arcsec,
            err_y_mean_arcsec=r.head_err_y_mean_arcsec, err_y_sd_arcsec=r.head_err_y_sd_arcsec,
            crlb_x_arcsec=r.head_crlb_x_arcsec, crlb_q0_x_arcsec=r.head_crlb_q0_x_arcsec,
            crlb_all_x_arcsec=r.head_crlb_all_x_arcsec, label=r.head_label,
            rmse_xy_all_cases_arcsec=r.rmse_xy_all_arcsec, nav_err_after_km=r.head_nav_err_after_km,
            data_to_converge_samples=r.head_data_to_converge_samples, runtime_s_per_seed=r.head_runtime_s_per_seed)
    nav_before = None
    if "nav_err_before_km" in long:
        nb = long[long.case_id == "T1-01"].dropna(subset=["nav_err_before_km"])
        nav_before = {v: float(g.nav_err_before_km.iloc[0]) for v, g in nb.groupby("variant", sort=False)}
    ml = long[long.method == "batch_ml"]
    return X2Summary(segments=setup.segments, alternatives=setup.alternatives, variants=variants,
                     nav_err_before_km=nav_before,
                     batch_ml_max_grad_norm=float(ml.ipopt_max_grad_norm.max()) if len(ml) else None,
                     batch_ml_all_success=bool(ml.ipopt_all_success.all()) if len(ml) else None)
