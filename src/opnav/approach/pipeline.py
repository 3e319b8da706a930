"""Paper-A pipeline steps called by the thin workflow scripts and the CLI.

Description
    * :func:`bound_curve` - the CRLB of theta versus data used after ``N0``
      for a variant's information set (see :mod:`opnav.approach.crlb`).
    * :func:`run_group` - the Monte Carlo of one case group, variant and EM
      scheme (a Snakemake job), each case with its bound attached.
    Tables, the verdict text and the summary live in :mod:`opnav.approach.report`.
Units: arcsec, km, samples.
"""

from __future__ import annotations

import numpy as np

from . import cases, crlb
from . import scenario as sc
from .ekf import predict_only, run_filter


def bound_curve(cfg: dict, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, variant: str) -> np.ndarray:
    """1-sigma CRLB (arcsec) of theta after d = 0..n-N0 samples from N0, (n-N0+1, 3).

    ``literal``: all data from t0 with the prior P_X0 (the literal filter start
    re-uses the data before N0, so this is its honest bound); ``prior`` and
    ``roll``: data after N0 with the prior propagated to N0; ``reference-start``
    (diagnostic): data after N0 with the true state known to the filter's P_N0.
    """
    N0 = cfg["segments"]["N0"]
    win = geo.window(Rvar)
    th = sc.rad(theta_arcsec)
    sig = cfg["crlb"]["theta_prior_sigma_rad"]
    start = sc.START_OF[variant]
    if start == "filter":
        return sc.arcsec(crlb.crlb_curve(win, geo.u_true, geo.P0, th, sig)[N0:])
    if start == "prior":
        P = predict_only(np.zeros(6), geo.P0, win.slice(0, N0))[1]
    else:
        z = np.zeros((1, N0 + 1, 3))
        P = run_filter(z, np.zeros((1, 3)), np.zeros((1, 6)), geo.P0, win.slice(0, N0)).Pf[0, -1]
    return sc.arcsec(crlb.crlb_curve(win.slice(N0, win.n), geo.u_true[N0:], P, th, sig))


def groups_for(cfg: dict, variant: str) -> list[str]:
    """Case groups a variant runs (Snakemake jobs): the five groups (or "all" in one job when
    ``scatter: variant``) for ``table1_variants``, else the headline case only."""
    if variant not in cfg["table1_variants"]:
        return ["headline"]
    return list(cases.GROUPS) if cfg["scatter"] == "group" else ["all"]


def cases_in(cfg: dict, group: str) -> list[cases.Case]:
    allc = cases.table1_cases(cfg)
    if group == "headline":
        return [allc[0]]
    if group == "all":
        return allc
    return [c for c in allc if c.group == group]


def run_group(cfg: dict, variant: str, group: str, method: str, log=None) -> list[dict]:
    """Monte Carlo of every case of ``group`` under ``variant`` and EM ``method``."""
    geo = sc.build_geometry(cfg, variant)
    seeds = range(cfg["n_seeds"])
    out = []
    s = cfg["segments"]
    clist = cases_in(cfg, group)
    for case, r in zip(clist, cases.run_cases(cfg, variant, clist, seeds, geo=geo, method=method)):
        Rvar = sc.measurement_variance(geo, cfg, case.sigma3_px)
        curve = bound_curve(cfg, geo, Rvar, case.truth_arcsec, variant)
        used = s["L"] * s["N"]
        r["crlb_total_arcsec"] = curve[min(used, len(curve) - 1)]
        r["crlb_window_arcsec"] = curve[min(s["N"], len(curve) - 1)]
        r.update(method=method, group=group, case=case)
        if case.case_index != 1:  # time series only for the headline case (figures)
            for k in ("err_before_t_km", "err_after_t_km"):
                r.pop(k)
        out.append(r)
        if log:
            log.info("%s %s %s %s: est %s", variant, group, method, case.case_id,
                     np.round(r["theta_final_arcsec"].mean(0), 3))
    return out
