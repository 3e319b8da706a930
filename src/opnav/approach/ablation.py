"""A-X3: one-value ablations of the headline case, pixel noise and EM segment length.

Description
    A user changes one config value and reruns one Snakemake target:

    * ``approach.ablation.sigma3_px`` (rule ``approach_ablation_pixel``): the
      centroid 3-sigma pixel error of the headline case (the radius error is
      ``camera.radius_to_centroid_ratio`` times it, as in Table 1's pixel group);
    * ``approach.ablation.segment_N`` (rule ``approach_ablation_segment``): the
      EM segment length ``N``; the segment count becomes
      ``L = max(1, round(L0 N0_len / N))`` so the data length ``L N`` stays
      (nearly) that of the config, and only the EM's segmentation changes.

    For every scenario variant of ``approach.ablation.variants`` and every
    swept value it runs, on ``approach.ablation.n_seeds`` seeds (streams
    ``SeedSequence([base_seed, 1, seed])``, the headline case's), the EM-EKF
    of the config (:func:`opnav.approach.cases.run_case`, ``em.method``), the
    augmented EKF (:mod:`opnav.approach.augmented`, from the same start), and
    the Cramér-Rao bound for the data used (:func:`opnav.approach.pipeline.bound_curve`).

Reported per row (arcsec): mean estimate, spread (sample sd over seeds) and
RMS error of tx and ty, and the 1-sigma CRLB of tx and ty.
"""

from __future__ import annotations

import copy
import math
from dataclasses import replace

import numpy as np
import pandas as pd

from . import alternatives as alt
from . import cases
from . import scenario as sc
from .pipeline import segment_bounds, total_bound
from .setup import Setup

SWEEPS = {"pixel": "sigma3_px", "segment": "segment_N",
          # sensitivity sweeps (A-X5): prior 1-sigma, initial range, roll rate
          "prior": "prior_scale", "range": "range_km", "roll_rate": "roll_rate_deg_s"}
#: sweeps whose figure of merit is a power law: the log-log slope of the bound is reported
#: (literal case: the bound should follow sigma_prior / rho, slopes +1 and -1)
SLOPE_SWEEPS = ("prior", "range", "roll_rate")


def sweep_configs(cfg: dict, sweep: str) -> list[tuple[float, dict, cases.Case]]:
    """(value, config, headline case) for every value of the sweep. Every run draws its
    initial error from the prior (``initial_error.mode = sampled``): the spread over seeds
    is then comparable with the Bayesian bound beside it.

    ``prior``: both prior 1-sigmas (position and velocity) scaled by the value (the
    position sigma is ``value * prior_sigma.r_km``); ``range``: ``geometry.range_km``;
    ``roll_rate``: ``roll.rate_deg_s`` (deg/s; acts in the roll variant only).
    """
    if sweep not in SWEEPS:
        raise ValueError(f"unknown ablation sweep {sweep!r}; use one of {sorted(SWEEPS)}")
    abl = cfg["ablation"]  # the sweep derives configs (dicts) at the edge; run_sweep parses each once
    setup = Setup.of(cfg)
    base = cases.headline_case(setup)
    out = []
    for v in abl[SWEEPS[sweep]]:
        c = copy.deepcopy(cfg)
        c["n_seeds"] = abl["n_seeds"]
        c["initial_error"]["mode"] = "sampled"
        case = base
        if sweep == "pixel":
            case = replace(base, sigma3_px=setup.camera.pixel_errors(v))
        elif sweep == "segment":
            s = c["segments"]
            total = s["L"] * s["N"]
            s["N"] = int(v)
            s["L"] = max(1, int(round(total / int(v))))
        elif sweep == "prior":
            c["prior_sigma"] = {k: float(v) * x for k, x in cfg["prior_sigma"].items()}
        elif sweep == "range":
            c["geometry"]["range_km"] = float(v)
        else:
            c["roll"]["rate_deg_s"] = float(v)
        out.append((float(v), c, case))
    return out


def loglog_slopes(df: pd.DataFrame, columns=("crlb_x_arcsec", "sd_x_arcsec")) -> pd.DataFrame:
    """Least-squares slope of log(column) against log(value) per variant and estimator
    (a power-law exponent: +1 means proportional). Rows with non-positive values are skipped."""
    rows = []
    for (v, est), g in df.groupby(["variant", "estimator"], sort=False):
        row = {"variant": v, "estimator": est, "sweep": g["sweep"].iloc[0]}
        for col in columns:
            ok = (g["value"] > 0) & (g[col] > 0)
            x, y = np.log(g.loc[ok, "value"].to_numpy(float)), np.log(g.loc[ok, col].to_numpy(float))
            row[f"slope_{col}"] = float(np.polyfit(x, y, 1)[0]) if ok.sum() >= 2 and np.ptp(x) > 0 else math.nan
        rows.append(row)
    return pd.DataFrame(rows)


def _row(variant, sweep, value, estimator, th, truth, crlb_xy, data_used):
    err = th[:, :2] - truth[:2]
    sd = th[:, :2].std(axis=0, ddof=1) if th.shape[0] > 1 else np.full(2, math.nan)
    rmse = np.sqrt(np.mean(err**2, axis=0))
    return {"variant": variant, "sweep": sweep, "value": value, "estimator": estimator,
            "n_seeds": th.shape[0], "data_samples": data_used,
            "est_x_mean": th[:, 0].mean(), "est_y_mean": th[:, 1].mean(),
            "sd_x_arcsec": sd[0], "sd_y_arcsec": sd[1],
            "rmse_x_arcsec": rmse[0], "rmse_y_arcsec": rmse[1],
            "crlb_x_arcsec": crlb_xy[0], "crlb_y_arcsec": crlb_xy[1],
            "sd_over_crlb_x": sd[0] / crlb_xy[0] if crlb_xy[0] > 0 else math.nan}


def run_sweep(cfg: dict, sweep: str, log=None) -> pd.DataFrame:
    """The ablation table of one sweep (module docstring)."""
    rows = []
    variants = cfg["ablation"]["variants"]
    if sweep == "roll_rate":  # the roll rate acts in the roll variant only
        variants = [v for v in variants if v == "roll"] or ["roll"]
    for variant in variants:
        for value, c, case in sweep_configs(cfg, sweep):
            c = Setup.of(c)  # the edge: each swept config parsed once
            geo = sc.build_geometry(c, variant)
            seeds = range(c.n_seeds)
            em = cases.run_case(c, variant, case, seeds, geo=geo, method=c.em.method)
            Rvar = geo.measurement_variance(case.sigma3_px)
            used = c.segments.data_samples
            cb = total_bound(c, geo, Rvar, case.truth_arcsec, variant)  # all data: the augmented EKF's bound
            cb_em = segment_bounds(c, geo, Rvar, case.truth_arcsec, variant)[-1]  # the data EM used
            truth = np.asarray(case.truth_arcsec, float)
            rows.append(_row(variant, sweep, value, f"EM-EKF ({c.em.method})",
                             em["theta_final_arcsec"], truth, cb_em, used)
                        | {"stalled_seeds": int(np.sum(em["stalled"]))})
            ra = alt.run_case_alternatives(c, variant, case, seeds, geo, methods=("augmented",))
            rows.append(_row(variant, sweep, value, "augmented EKF",
                             ra["methods"]["augmented"]["theta_final_arcsec"], truth, cb, used))
            if log:
                log.info("%s %s=%g: EM sd %s aug sd %s CRLB %s", variant, sweep, value,
                         np.round(rows[-2]["sd_x_arcsec"], 4), np.round(rows[-1]["sd_x_arcsec"], 4),
                         np.round(cb[:2], 4))
    return pd.DataFrame(rows)
