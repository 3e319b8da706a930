"""Paper A's numbers from the simulation results: A-T1 in long form, the A-X1 bound table,
the roll-rate and stars studies, and A-summary.json.

Pure functions of the results of :mod:`opnav.approach.pipeline` and
:mod:`opnav.approach.alternatives`; editing this module reruns only the table rules, never
the Monte Carlo. The sentences the manuscript makes from these numbers are in
:mod:`opnav.report.approach_text`. Units: arcsec, km, samples.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from . import cases
from . import scenario as sc
from .labels import label_columns, row_label, variant_label
from .setup import Setup

if TYPE_CHECKING:  # the records only (alternatives imports CasADi)
    from .alternatives import StarsRow


def seed_sd(x: np.ndarray) -> float:
    return float(x.std(ddof=1)) if x.shape[0] > 1 else math.nan


#: A-T1 navigation-error columns (km, RMS over the last nav_error.last_fraction of the arc):
#: before / after compensation / with the true theta, total and lateral / range parts.
NAV_SPLIT_KEYS = ("nav_err_true_theta_km", "nav_err_consider_km") + tuple(
    f"nav_err_{k}_{p}_km" for k in ("before", "after", "true_theta") for p in ("lat", "rng"))


def table1_frame(results: list[cases.CaseRun], published: dict, target_arcsec: float) -> pd.DataFrame:
    """A-T1 long form: one row per case x variant x EM scheme (:func:`opnav.approach.pipeline.run_group`'s
    runs), published values beside; ``target_arcsec`` (the claimed accuracy, the analysis plan's
    A-C1 target) sets the ``identifiable`` column."""
    pub = {r["case_id"]: r for r in published["table1"]}
    target = float(target_arcsec)
    rows = []
    for r in results:
        c, b, smp = r.case, r.bounds, r.sampled
        th = r.theta_final_arcsec
        truth = np.asarray(c.truth_arcsec)
        p = pub.get(c.case_id, {})
        ct = smp.consistency_t if smp else None
        rows.append({
            "variant": variant_label(r.variant, r.method, r.mode),
            "scenario": r.variant,
            "method": r.method,
            "mode": r.mode,
            "maps_per_segment": r.maps_per_segment,
            "group": c.group,
            "case_id": c.case_id,
            "truth_x_arcsec": truth[0], "truth_y_arcsec": truth[1], "truth_z_arcsec": truth[2],
            "init_x_arcsec": c.init_arcsec[0], "init_y_arcsec": c.init_arcsec[1],
            "pixel_sigma3_px": c.sigma3_px[0], "install_deg": c.install_deg,
            "n_seeds": th.shape[0],
            "est_x_mean": th[:, 0].mean(), "est_x_std": th[:, 0].std(ddof=1) if th.shape[0] > 1 else math.nan,
            "est_y_mean": th[:, 1].mean(), "est_y_std": th[:, 1].std(ddof=1) if th.shape[0] > 1 else math.nan,
            "rmse_x_arcsec": float(np.sqrt(np.mean((th[:, 0] - truth[0]) ** 2))),
            "rmse_y_arcsec": float(np.sqrt(np.mean((th[:, 1] - truth[1]) ** 2))),
            # the bound of the data the estimate used (last window when sliding, cumulative when
            # growing), with Q = 0 beside (the truth has no process noise), and of all the data
            "crlb_x_arcsec": b.crlb_arcsec[0], "crlb_y_arcsec": b.crlb_arcsec[1],
            "crlb_q0_x_arcsec": b.crlb_q0_arcsec[0], "crlb_q0_y_arcsec": b.crlb_q0_arcsec[1],
            "crlb_all_x_arcsec": b.crlb_total_arcsec[0], "crlb_all_y_arcsec": b.crlb_total_arcsec[1],
            "tz_observable": not r.tz_unobservable,
            **label_columns(r, target),
            # initial error drawn from the prior (headline case only): the spread to set beside the bound
            "est_x_mean_sampled": smp.theta_final_arcsec[:, 0].mean() if smp else math.nan,
            "est_x_std_sampled": seed_sd(smp.theta_final_arcsec[:, 0]) if smp else math.nan,
            "est_y_std_sampled": seed_sd(smp.theta_final_arcsec[:, 1]) if smp else math.nan,
            "label_sampled": row_label(smp.label)[0] if smp else "",
            "rmse_x_sampled": float(np.sqrt(np.mean((smp.theta_final_arcsec[:, 0] - truth[0]) ** 2)))
            if smp else math.nan,
            # filter consistency (sampled initial error): mean over time and seeds, 3 dof each
            "nees_pos_before_mean": float(np.nanmean(ct.before.nees_pos)) if ct else math.nan,
            "nees_pos_after_mean": float(np.nanmean(ct.after.nees_pos)) if ct else math.nan,
            "nis_before_mean": float(np.nanmean(ct.before.nis)) if ct else math.nan,
            "nis_after_mean": float(np.nanmean(ct.after.nis)) if ct else math.nan,
            # position NEES of the Schmidt (consider) EKF and of the true-theta filter (issue 44)
            "nees_pos_consider_mean": float(np.nanmean(ct.consider.nees_pos)) if ct else math.nan,
            "nees_pos_true_theta_mean": float(np.nanmean(ct.true_theta.nees_pos)) if ct else math.nan,
            # each compensated filter against the true-theta filter of the same runs (issue 54: the truth has
            # no process noise while the filters' Q > 0, so the reference is that filter's NEES, not 3)
            **dataclasses.asdict(nees_paired(ct)),
            "nav_err_before_km": r.nav_err_before_km.mean(),
            "nav_err_before_km_std": r.nav_err_before_km.std(ddof=1) if th.shape[0] > 1 else math.nan,
            "nav_err_after_km": r.nav_err_after_km.mean(),
            "nav_err_after_km_std": r.nav_err_after_km.std(ddof=1) if th.shape[0] > 1 else math.nan,
            # split across (lat) / along (rng) the line of sight, and the floor with the true theta
            # (diagnostic: the filter given the true misalignment), mean over seeds
            **{k: float(np.mean(getattr(r, k))) for k in NAV_SPLIT_KEYS},
            "pub_est_x_mean": p.get("est_x_arcsec", math.nan),
            "pub_est_y_mean": p.get("est_y_arcsec", math.nan),
            "pub_data_to_converge_samples": p.get("data_to_converge_samples", math.nan),
            "pub_nav_err_before_km": p.get("nav_err_before_km", math.nan),
            "pub_nav_err_after_km": p.get("nav_err_after_km", math.nan),
        })
    df = pd.DataFrame(rows)
    order = {v: i for i, v in enumerate(sc.VARIANTS)}
    df["_v"] = df["scenario"].map(order)
    df = df.sort_values(["_v", "mode", "method", "case_id"], kind="stable").drop(columns="_v").reset_index(drop=True)
    return df


@dataclass(frozen=True)
class NeesPaired:
    """Per compensated filter (``after``: theta_hat as exact; ``consider``: the Schmidt filter), the
    seed mean of (its time-mean position NEES minus the true-theta filter's of the same seed) and
    its standard error over seeds, and the seeds (sampled initial error; NaN without). The field
    names are A-T1's columns."""

    nees_n_seeds: float = math.nan
    nees_pos_after_minus_true_theta_mean: float = math.nan
    nees_pos_after_minus_true_theta_se: float = math.nan
    nees_pos_consider_minus_true_theta_mean: float = math.nan
    nees_pos_consider_minus_true_theta_se: float = math.nan


def nees_paired(ct: cases.ConsistencySeries | None) -> NeesPaired:
    """:class:`NeesPaired` of a sampled rerun's filter consistency (all NaN without one)."""
    if ct is None:
        return NeesPaired()
    ref = np.nanmean(ct.true_theta.nees_pos, axis=1)  # (S,) time means
    d_after = np.nanmean(ct.after.nees_pos, axis=1) - ref
    d_cons = np.nanmean(ct.consider.nees_pos, axis=1) - ref

    def se(d):
        return float(d.std(ddof=1) / np.sqrt(d.size)) if d.size > 1 else math.nan

    return NeesPaired(int(ref.size), float(d_after.mean()), se(d_after), float(d_cons.mean()), se(d_cons))


def nees_summary(t1: pd.DataFrame) -> dict:
    """Filter consistency of the headline rows (T1-01, initial error drawn from the prior, whole arc)
    for the summary (issue 54, item 5): per row (its A-T1 ``variant``), the position NEES of the filter
    compensated with the estimate taken as exact (``nees_mean``) and of the Schmidt filter carrying its
    covariance (``consider_nees_mean``) beside the NEES of the filter given the true theta on the same
    runs (``reference_nees_mean``: the truth has no process noise while the filters' Q > 0, so that
    filter's NEES, not 3, is what a consistent compensation would show), with the paired difference
    to it (seed mean and standard error) and ``n_seeds``."""
    out = {}
    for _, r in t1[t1["case_id"] == "T1-01"].iterrows():
        ref = _num(r, "nees_pos_true_theta_mean")
        if ref is None:
            continue
        out[r["variant"]] = {
            "nees_mean": _num(r, "nees_pos_after_mean"), "reference_nees_mean": ref,
            "consider_nees_mean": _num(r, "nees_pos_consider_mean"),
            "before_nees_mean": _num(r, "nees_pos_before_mean"),
            "n_seeds": int(r["nees_n_seeds"]) if _num(r, "nees_n_seeds") is not None else None,
            **{f"{k}_minus_reference_{q}": _num(r, f"nees_pos_{k}_minus_true_theta_{q}")
               for k in ("after", "consider") for q in ("mean", "se")},
            "scenario": r["scenario"], "method": r["method"], "mode": r.get("mode", "sliding")}
    return out


def crlb_rows(setup: Setup, curves: dict, conv: Mapping[str, cases.ConvergenceStudy], t1: pd.DataFrame,
              target_arcsec: float,
              curves_q0: dict | None = None) -> pd.DataFrame:
    """A-X1 table: the bound per variant beside the EM estimates' spread and EM iterations.

    The EM errors set beside the bound come from the headline case rerun with the initial
    error drawn from the prior (``*_sampled`` columns of A-T1): with the paper's fixed
    initial error the spread over seeds is noise only and is not comparable with a
    Bayesian bound. ``crlb_q0_*``: the bound if the truth, like ours, had no process noise.
    ``target_arcsec``: the claimed accuracy (the analysis plan's A-C1 target).
    """
    s = setup.segments
    target = float(target_arcsec)
    cs = setup.convergence_study
    rows = []
    for v, curve in curves.items():
        d_total = min(s.data_samples, len(curve) - 1)
        c0 = (curves_q0 or {}).get(v)
        row = {
            "variant": v,
            "crlb_x_window_arcsec": _first_window_bound(t1, v, curve, s),
            "crlb_x_250_arcsec": curve[min(250, len(curve) - 1), 0],
            "crlb_x_total_arcsec": curve[d_total, 0],
            "crlb_y_total_arcsec": curve[d_total, 1],
            "crlb_q0_x_total_arcsec": c0[min(d_total, len(c0) - 1), 0] if c0 is not None else math.nan,
            "total_samples": d_total,
            "tz_observable": bool(curve[-1, 2] < 0.5 * sc.arcsec(setup.crlb_prior_sigma_rad)),
            "bound_reaches_target": bool(curve[d_total, :2].max() <= target),
            "samples_to_target": _first_below(curve[:, :2].max(1), target),
        }
        for r in t1[(t1.scenario == v) & (t1.case_id == "T1-01")].itertuples():
            tag = r.method if r.mode == "sliding" else f"growing_{r.method}"
            sampled = not pd.isna(r.rmse_x_sampled)
            label = r.label_sampled if sampled and r.label_sampled else r.label
            row.update({
                f"em_{tag}_est_x_mean": r.est_x_mean_sampled if sampled else r.est_x_mean,
                f"em_{tag}_est_x_std": r.est_x_std_sampled if sampled else r.est_x_std,
                f"em_{tag}_rmse_x_arcsec": r.rmse_x_sampled if sampled else r.rmse_x_arcsec,
                f"em_{tag}_crlb_x_arcsec": r.crlb_x_arcsec,  # the bound of the data it used
                f"em_{tag}_crlb_q0_x_arcsec": r.crlb_q0_x_arcsec,
                f"em_{tag}_label": label,
                f"em_{tag}_stalled": label == "stalled"})
        c = conv.get(v)
        if c is not None:
            ts, tr = c.theta_star_arcsec, c.truth_arcsec
            row.update(
                mle_samples=c.data_samples,
                crlb_x_at_mle_samples=curve[min(c.data_samples, len(curve) - 1), 0],
                mle_x_mean=ts[:, 0].mean(),
                mle_x_std=ts[:, 0].std(ddof=1) if ts.shape[0] > 1 else math.nan,
                mle_rmse_x_arcsec=float(np.sqrt(np.mean((ts[:, 0] - tr[0]) ** 2))),
                mle_rmse_y_arcsec=float(np.sqrt(np.mean((ts[:, 1] - tr[1]) ** 2))),
                maps_plain_median=float(np.median(c.plain.maps_to_converge)),
                maps_plain_extrapolated_median=float(np.median(c.plain.maps_extrapolated)),
                plain_rate_per_map=float(np.median(c.plain.rate_per_map)),
                maps_squarem_median=float(np.median(c.squarem.maps_to_converge)),
                max_maps=c.max_maps,
                tol_arcsec=cs.tol_arcsec)
        rows.append(row)
    return pd.DataFrame(rows)


def _first_window_bound(t1, variant, curve, s):
    """Bound of one segment's data: from the A-T1 sliding rows when present, else the
    cumulative curve after N samples."""
    h = t1[(t1.scenario == variant) & (t1.case_id == "T1-01") & (t1.mode == "sliding")]
    if len(h):
        return float(h.crlb_x_arcsec.iloc[0])
    return curve[min(s.N, len(curve) - 1), 0]


def prior_bound_arcsec(setup: Setup) -> float:
    """What the prior alone bounds theta to: the 1-sigma prior position error seen from the
    initial range, ``sigma_r / rho`` (arcsec), from the config."""
    return float(sc.arcsec(setup.prior_sigma.r_km / setup.geometry.range_km))


def _first_below(values: np.ndarray, target: float) -> float:
    """First data length whose bound is at or below ``target`` (NaN if never)."""
    idx = np.nonzero(values <= target)[0]
    return float(idx[0]) if idx.size else math.nan


def nav_note(r) -> str:
    """What sets a row's navigation error after compensation, from its split (A-T1 columns):
    ``after X km (lateral L, range R); with the true theta T km (lateral, range)`` (the filters'
    consistency is :func:`nees_summary`'s)."""
    def g(k):
        v = _num(r, k)
        return "n/a" if v is None else f"{v:.3g}"
    if _num(r, "nav_err_after_rng_km") is None:
        return ""
    lat, rng = _num(r, "nav_err_after_lat_km"), _num(r, "nav_err_after_rng_km")
    part = "range" if rng >= lat else "lateral"
    return (f"after compensation {g('nav_err_after_km')} km (lateral {g('nav_err_after_lat_km')}, range "
            f"{g('nav_err_after_rng_km')}: the {part} channel sets it); with the true theta "
            f"{g('nav_err_true_theta_km')} km (lateral {g('nav_err_true_theta_lat_km')}, range "
            f"{g('nav_err_true_theta_rng_km')})")


def roll_rate_summary(study: dict) -> dict:
    """The roll-rate study (:func:`opnav.approach.pipeline.roll_rate_study`) for the summary:
    per rate the worse of (tx, ty) bounds after the published data and after all the data (with
    Q and Q = 0), arcsec; the log-log slope; the rate reaching the target in that data, deg/s."""
    worst = {k: np.asarray(study[k])[:, :2].max(1) for k in
             ("bound_at_samples_arcsec", "bound_all_arcsec", "bound_all_q0_arcsec")}
    rate = study["rate_to_target_deg_s"]
    return {"rates_deg_s": [float(r) for r in study["rates_deg_s"]], "samples": int(study["samples"]),
            "total_samples": int(study["total_samples"]),
            **{k: [float(v) for v in w] for k, w in worst.items()},
            "slope_all": float(study["slope_all"]),
            "rate_to_target_deg_s": None if not math.isfinite(rate) else float(rate),
            "target_arcsec": float(study["target_arcsec"]), "config_rate_deg_s": float(study["config_rate_deg_s"])}


def mars_attitude_summary(setup: Setup, bounds: Mapping[str, Mapping[float, Any]] | None,
                          curves: Mapping[str, np.ndarray]) -> dict:
    """The Mars images' attitude knowledge (issue 54, item 3) for the summary: the configured
    value (``default_arcsec``) and why, and per variant the worse of (tx, ty) of the bound of all
    the data with it (``default``) and at each ``camera.attitude_study_arcsec`` value, arcsec."""
    a0 = float(setup.camera.attitude_sigma_arcsec)
    why = ("paper A's measurement (eq. 3) takes the camera attitude A_c^i as known: the reproduction keeps the "
           "paper's model, and the bound with an attitude error is shown beside it" if a0 == 0.0 else
           f"our choice: each Mars image's attitude is known to {a0:g} arcsec (1-sigma per axis, independent per "
           "image), which the paper's measurement (eq. 3) leaves out")
    d = setup.segments.data_samples
    out = {"default_arcsec": a0, "why": why, "values_arcsec": [float(a) for a in setup.camera.attitude_study_arcsec],
           "bound_all_arcsec": {}}
    for v, c in curves.items():
        row = {"default": float(np.asarray(c)[min(d, len(c) - 1), :2].max())}
        for a, b in (bounds or {}).get(v, {}).items():
            row[f"{float(a):g}"] = float(np.asarray(b)[:2].max())
        out["bound_all_arcsec"][v] = row
    return out


def roll_rate_bound_summary(study: dict) -> dict:
    """The roll variant's bound against the roll rate for the claims scorer (issue 54): on the log
    grid of :func:`opnav.approach.pipeline.roll_rate_study`, the worse of the (tx, ty) 1-sigma
    bounds after the published data (``samples`` after N0), arcsec; the scorer reads the rate at
    which it reaches the plan's target."""
    return {"rate_deg_s": [float(r) for r in study["grid_rates_deg_s"]],
            "bound_arcsec": [float(b) for b in np.asarray(study["bound_grid_arcsec"])[:, :2].max(1)],
            "samples": int(study["samples"]),
            "rule": (f"roll variant, headline case: the worse of the 1-sigma Cramer-Rao bounds of tx and ty after "
                     f"{int(study['samples'])} samples from N0 (the paper's data to converge), with the filter's Q, "
                     f"the camera rolling at each rate")}


def installation_summary(chk: dict) -> dict:
    """Whether the installation cases of Table 1 test anything (issue 54, item 7), from
    :func:`opnav.approach.readings.installation_check`: ``by_construction`` (the installation
    angle cancels from the measurement), ``why`` and the measured largest relative change."""
    why = ("the misalignment is defined in the camera frame and the body attitude is commanded to put the "
           "installed boresight on Mars (paper A eq. 3-5), so the installation matrix cancels from the "
           f"measurement (largest relative change over the angles {chk['max_rel_change']:.1g}, rounding): the "
           "installation rows are noise replicates" if chk["by_construction"] else
           f"the installation angle changes the measurement (largest relative change {chk['max_rel_change']:.2g})")
    return {"by_construction": bool(chk["by_construction"]), "why": why,
            "max_rel_change": float(chk["max_rel_change"]), "install_deg": list(chk["install_deg"])}


#: the keys of each nav_floor_by_arc row (the claims engineer's contract, issue 54)
NAV_FLOOR_ROW_KEYS = ("arc_s", "variant", "nav_err_km_rule", "nav_err_km_last", "true_theta_km_rule",
                      "true_theta_km_last", "n_seeds")


def nav_floor_summary(nf: dict) -> dict:
    """:func:`opnav.approach.navfloor.nav_floor_by_arc` for the summary: ``rule`` and ``rows``
    (:data:`NAV_FLOOR_ROW_KEYS` first, then the theta = 0 filter's, the seed medians and sds and the
    estimate's seed mean), without the per-seed arrays."""
    rows = [{**{k: r[k] for k in NAV_FLOOR_ROW_KEYS}, **{k: v for k, v in r.items() if k not in NAV_FLOOR_ROW_KEYS}}
            for r in nf["rows"]]
    return {"rule": nf["rule"], "variant": nf["variant"], "scenario": nf["scenario"], "scheme": nf["scheme"],
            "rows": rows}


def nav_floor_frame(nf: dict) -> pd.DataFrame:
    """A-X7: one row per arc length (:func:`nav_floor_summary`'s rows)."""
    return pd.DataFrame(nav_floor_summary(nf)["rows"])


def figures_5_6(results: list[cases.CaseRun]) -> dict:
    """Paper A's Figs. 5 and 6 (issue 54, item 7): what each states and the numbers of ours that
    answer it, from the headline (T1-01) runs of every variant and scheme. Fig. 5 (navigation
    accuracy during the estimation) states no number: the text reads it with Fig. 4 ("the algorithm
    estimates tx and ty effectively", A-C1); its rows are the position error at the end of the first
    and the last segment (the filter inside the EM, mean over seeds). Fig. 6 (navigation before and
    after compensation) carries the 79.13 km to 18.43 km of the text: A-C6 and A-C7 (Table 1's rule);
    its rows add the errors at the arc's last sample."""
    f5, f6 = [], []
    for r in results:
        if r.case_id != "T1-01":
            continue
        key = variant_label(r.variant, r.method, r.mode)
        seg, used = np.asarray(r.seg_pos_err_km), np.asarray(r.seg_data_used)
        f5.append({"variant": key, "samples_first": int(used[0]), "pos_err_km_first": float(seg[:, 0].mean()),
                   "samples_last": int(used[-1]), "pos_err_km_last": float(seg[:, -1].mean()),
                   "n_seeds": int(seg.shape[0])})
        row = {"variant": key, "before_km_rule": float(np.mean(r.nav_err_before_km)),
               "after_km_rule": float(np.mean(r.nav_err_after_km)), "n_seeds": int(seg.shape[0])}
        if r.err_before_t_km is not None:
            row.update(before_km_last_sample=float(np.asarray(r.err_before_t_km)[:, -1].mean()),
                       after_km_last_sample=float(np.asarray(r.err_after_t_km)[:, -1].mean()))
        f6.append(row)
    return {"A-F5": {"claims": [], "reason": ("states no number of its own: the text reads it together with Fig. 4 "
                                              "(tx and ty estimated effectively: A-C1); rows: the position error at "
                                              "the end of the first and the last EM segment"), "rows": f5},
            "A-F6": {"claims": ["A-C6", "A-C7"], "reason": ("its numbers (79.13 km before, 18.43 km after) are "
                                                            "Table 1's, judged as A-C6 and A-C7 by the table's rule; "
                                                            "rows add the errors at the arc's last sample"),
                     "rows": f6}}


def _stars_key(row: StarsRow) -> str:
    """Summary key of a stars-study row: ``m<k>`` (k stars in every image) or ``att<v>``
    (attitude knowledge, arcsec); '.' written 'p', '-' written 'n'."""
    if row.sweep == "per_image":
        return f"m{row.per_image}"
    tag = {"attitude_sigma_arcsec": "att"}[row.sweep]
    return tag + f"{row.value:g}".replace(".", "p").replace("-", "n")


def stars_summary(study: list[StarsRow], target_arcsec: float) -> dict:
    """The stars study (:func:`opnav.approach.alternatives.stars_study`) for the summary, per row
    (:func:`_stars_key`): its settings, stars per image along the arc, the bound of tx, ty, tz
    after all the data (Q and Q = 0) and of the star images alone, the attitude floor
    ``hypot(sigma_a / sqrt(images), drift)``, samples after N0 until the bound of tx and ty is at
    most ``target_arcsec``, and per estimator the seed mean and sd of (tx, ty, tz), its RMS error
    in tx, ty, and its label (EM); plus ``objection``: the attitude knowledge at which the bound
    reaches the target (``attitude_threshold_arcsec``)."""
    out = {}
    for row in study:
        curve = np.asarray(row.crlb_curve_arcsec)
        need = _first_below(curve[:, :2].max(1), target_arcsec)
        truth = np.asarray(row.truth_arcsec, float)
        est = {}
        for name, e in row.estimators.items():
            th = np.asarray(e.theta_final_arcsec, float)
            d = {"mean_arcsec": [float(x) for x in th.mean(0)],
                 "sd_arcsec": [float(x) for x in (th.std(0, ddof=1) if th.shape[0] > 1 else np.full(3, np.nan))],
                 "rmse_xy_arcsec": float(np.sqrt(np.mean((th[:, :2] - truth[:2]) ** 2)))}
            if e.label is not None:
                d["label"] = row_label(e.label)[0]
            if e.theta_ml_arcsec is not None:
                ml = np.asarray(e.theta_ml_arcsec, float)
                d["ml_rmse_xy_arcsec"] = float(np.sqrt(np.mean((ml[:, :2] - truth[:2]) ** 2)))
            est[name] = d
        out[_stars_key(row)] = {
            "sweep": row.sweep, "per_image": row.per_image, "every_K": row.every_K,
            "images": row.images, "total_samples": row.total_samples,
            "attitude_sigma_arcsec": row.attitude_sigma_arcsec, "mode_drift_arcsec": row.mode_drift_arcsec,
            "mag_limit": row.mag_limit, "field_deg": row.field_deg, "camera_field_deg": row.camera_field_deg,
            "stars_per_image": dataclasses.asdict(row.stars_per_image), "floor_arcsec": row.floor_arcsec,
            "crlb_arcsec": [float(x) for x in row.crlb_all_arcsec],
            "crlb_q0_arcsec": [float(x) for x in row.crlb_all_q0_arcsec],
            "crlb_stars_only_arcsec": [float(x) for x in row.crlb_stars_only_arcsec],
            "samples_to_target": None if math.isnan(need) else need, "estimators": est}
    if study:
        out["objection"] = {"attitude_threshold_arcsec": float(study[0].attitude_threshold_arcsec),
                            "target_arcsec": float(target_arcsec)}
    return out


def stars_frame(study: list[StarsRow]) -> pd.DataFrame:
    """A-X6: one row per stars-study row (:func:`opnav.approach.alternatives.stars_study`): the
    swept setting, stars per image along the arc, the bound of tx, ty (all data; star images
    alone), the attitude floor and the EM-EKF's (growing windows, SQUAREM) seed mean and RMS
    error of (tx, ty), arcsec."""
    rows = []
    for r in study:
        truth = np.asarray(r.truth_arcsec, float)
        e = r.estimators["em_growing_squarem"]
        th = np.asarray(e.theta_final_arcsec, float)
        n = r.stars_per_image
        rows.append({
            "sweep": r.sweep, "value": float(r.value),
            "per_image": int(r.per_image), "attitude_sigma_arcsec": r.attitude_sigma_arcsec,
            "mode_drift_arcsec": r.mode_drift_arcsec, "mag_limit": r.mag_limit,
            "field_deg": r.field_deg,
            "images": int(r.images),
            "stars_per_image_min": float(n.min), "stars_per_image_median": float(n.median),
            "stars_per_image_max": float(n.max),
            "crlb_x_arcsec": float(r.crlb_all_arcsec[0]), "crlb_y_arcsec": float(r.crlb_all_arcsec[1]),
            "crlb_stars_only_x_arcsec": float(r.crlb_stars_only_arcsec[0]),
            "crlb_stars_only_y_arcsec": float(r.crlb_stars_only_arcsec[1]),
            "floor_arcsec": r.floor_arcsec,
            "em_est_x_mean_arcsec": float(th[:, 0].mean()), "em_est_y_mean_arcsec": float(th[:, 1].mean()),
            "em_rmse_xy_arcsec": float(np.sqrt(np.mean((th[:, :2] - truth[:2]) ** 2))),
            "em_label": row_label(e.label)[0], "n_seeds": int(th.shape[0]),
        })
    return pd.DataFrame(rows)


def summary(setup: Setup, t1: pd.DataFrame, x1: pd.DataFrame, target_arcsec: float,
            roll_rate: dict | None = None) -> dict:
    """Headline numbers per variant and EM scheme for the manuscript macros; ``target_arcsec``: the
    claimed accuracy (the analysis plan's A-C1 target); ``roll_rate``: the roll-rate study
    (:func:`opnav.approach.pipeline.roll_rate_study`), if run."""
    out = {"profile_segments": setup.segments.as_dict(), "accuracy_target_arcsec": float(target_arcsec),
           "prior_bound_arcsec": prior_bound_arcsec(setup),
           "convergence_max_maps": setup.convergence_study.max_maps, "variants": {}}
    if roll_rate is not None:
        out["roll_rate"] = roll_rate_summary(roll_rate)
    for _, r in t1[t1["case_id"] == "T1-01"].iterrows():
        x = x1[x1["variant"] == r["scenario"]]
        x = x.iloc[0] if len(x) else {}
        out["variants"][r["variant"]] = {
            "scenario": r["scenario"], "method": r["method"], "mode": r.get("mode", "sliding"),
            "est_x_mean": r["est_x_mean"], "est_x_std": r["est_x_std"],
            "est_y_mean": r["est_y_mean"], "est_y_std": r["est_y_std"],
            "est_x_std_sampled": _num(r, "est_x_std_sampled"), "rmse_x_sampled": _num(r, "rmse_x_sampled"),
            "crlb_x_arcsec": r["crlb_x_arcsec"], "crlb_y_arcsec": r["crlb_y_arcsec"],
            "crlb_q0_x_arcsec": _num(r, "crlb_q0_x_arcsec"),
            "crlb_all_x_arcsec": _num(r, "crlb_all_x_arcsec"), "crlb_all_y_arcsec": _num(r, "crlb_all_y_arcsec"),
            "label": r["label"], "converged_seeds": int(r["converged_seeds"]),
            "stalled": bool(r["stalled"]), "stalled_seeds": int(r["stalled_seeds"]), "n_seeds": int(r["n_seeds"]),
            "identifiable": bool(r["identifiable"]), "reading": r["reading"],
            **{f"{q}_{k}_mean": _num(r, f"{q}_{k}_mean") for q in ("nees_pos", "nis") for k in ("before", "after")},
            "nees_pos_consider_mean": _num(r, "nees_pos_consider_mean"),
            "nees_pos_true_theta_mean": _num(r, "nees_pos_true_theta_mean"),
            "contraction_per_map": _num(r, "contraction_per_map"),
            "dist_to_ml_arcsec": _num(r, "dist_to_ml_arcsec"),
            "dist_to_ml_over_bound": _num(r, "dist_to_ml_over_bound"),
            "data_to_converge_samples": _num(r, "data_to_converge_samples"),
            "nav_err_before_km": r["nav_err_before_km"], "nav_err_after_km": r["nav_err_after_km"],
            **{k: _num(r, k) for k in NAV_SPLIT_KEYS},
            "nav_note": nav_note(r),
            "iterations_plain_median": _num(x, "maps_plain_median"),
            "iterations_plain_extrapolated_median": _num(x, "maps_plain_extrapolated_median"),
            "iterations_squarem_median": _num(x, "maps_squarem_median"),
            "mle_rmse_x_arcsec": _num(x, "mle_rmse_x_arcsec"),
            "bound_reaches_target": bool(x["bound_reaches_target"]) if len(x) else None,
        }
    return out


def _num(row, key):
    try:
        v = float(row[key])
    except (KeyError, TypeError, ValueError):
        return None
    return None if math.isnan(v) else (v if math.isfinite(v) else None)


#: the scenario that follows paper A as written (the EM start X_N0 from the theta = 0 filter)
AS_WRITTEN = "literal"


def _float_or_none(x) -> float | None:
    return None if x is None else float(x)


@dataclass(frozen=True)
class ClaimsSummary:
    """What paper A's claims (:mod:`opnav.report.approach_claims`) read of A-summary.json,
    by meaning instead of by a row's display label (issue 41 item 4).

    ``window_samples``             N, the samples of one sliding EM window (0 when absent);
    ``roll_rate_to_target_deg_s``  the roll rate at which the bound reaches the claimed
                                   accuracy within the published data (None: none in the
                                   searched range, or no roll-rate study), deg/s;
    ``roll_rate_config_deg_s``     the configured roll rate (None without the study), deg/s;
    ``nav_err_true_theta_km``      navigation error of the filter given the true theta in the
                                   as-written row (scenario :data:`AS_WRITTEN`, plain EM,
                                   sliding windows, headline case; None when absent), km.
    """

    window_samples: float
    roll_rate_to_target_deg_s: float | None = None
    roll_rate_config_deg_s: float | None = None
    nav_err_true_theta_km: float | None = None

    @classmethod
    def from_json(cls, summ: Mapping[str, Any]) -> ClaimsSummary:
        """From the dict :func:`summary` writes (A-summary.json); the as-written row is the
        one whose ``scenario``, ``method`` and ``mode`` say so, whatever its key."""
        rr = summ.get("roll_rate") or {}
        row = next((v for v in (summ.get("variants") or {}).values()
                    if v.get("scenario") == AS_WRITTEN and v.get("method") == "plain"
                    and v.get("mode", "sliding") == "sliding"), {})
        return cls(window_samples=float((summ.get("profile_segments") or {}).get("N", 0) or 0),
                   roll_rate_to_target_deg_s=_float_or_none(rr.get("rate_to_target_deg_s")),
                   roll_rate_config_deg_s=_float_or_none(rr.get("config_rate_deg_s")),
                   nav_err_true_theta_km=_float_or_none(row.get("nav_err_true_theta_km")))


def _opt(v: Mapping[str, Any], key: str) -> float | None:
    """``v[key]`` as a float, None when absent or None (NaN kept: the text says n/a)."""
    x = v.get(key)
    return None if x is None else float(x)


@dataclass(frozen=True)
class HeadlineRow:
    """One headline-case (T1-01) row of A-summary.json ``variants``: one scenario and EM
    scheme, read by meaning (issue 41 item 4); the sentences and their words are made in
    the report layer (:mod:`opnav.report.approach_text`, :mod:`opnav.report.approach_scorecard`).

    ``key`` is the row's identifier in A-T1 (``variant`` column) and A-summary.json
    (:func:`opnav.approach.labels.variant_label` of scenario, method, mode); ``method`` is the
    EM scheme (``plain`` | ``squarem``), ``mode`` the windows (``sliding`` | ``growing``).
    Estimates and bounds in arcsec (``est_*_std`` NaN below two seeds; a ``None`` is a value
    the summary does not hold); ``label`` the convergence label (None: an older summary
    without it, see ``stalled``); ``reading`` the label's reading; navigation errors in km;
    ``iterations_*``: EM maps of the convergence study (None without it).
    """

    key: str
    scenario: str
    method: str
    mode: str
    est_x_mean: float
    est_x_std: float | None
    est_y_mean: float
    est_y_std: float | None
    crlb_x_arcsec: float
    crlb_y_arcsec: float
    crlb_q0_x_arcsec: float | None = None
    crlb_all_x_arcsec: float | None = None
    label: str | None = None
    stalled: bool = False
    reading: str = ""
    data_to_converge_samples: float | None = None
    nav_err_before_km: float | None = None
    nav_err_after_km: float | None = None
    nav_note: str = ""
    iterations_plain_median: float | None = None
    iterations_plain_extrapolated_median: float | None = None
    iterations_squarem_median: float | None = None

    @property
    def as_written_scheme(self) -> bool:
        """Plain EM on sliding windows: the paper's scheme (the scenario may still add something)."""
        return self.method == "plain" and self.mode == "sliding"

    @classmethod
    def from_json(cls, key: str, v: Mapping[str, Any]) -> HeadlineRow:
        return cls(key=key, scenario=v["scenario"], method=v.get("method", "plain"), mode=v.get("mode", "sliding"),
                   est_x_mean=float(v["est_x_mean"]), est_x_std=_opt(v, "est_x_std"),
                   est_y_mean=float(v["est_y_mean"]), est_y_std=_opt(v, "est_y_std"),
                   crlb_x_arcsec=float(v.get("crlb_x_arcsec", math.nan)),
                   crlb_y_arcsec=float(v.get("crlb_y_arcsec", math.nan)),
                   crlb_q0_x_arcsec=_opt(v, "crlb_q0_x_arcsec"), crlb_all_x_arcsec=_opt(v, "crlb_all_x_arcsec"),
                   label=v.get("label"), stalled=bool(v.get("stalled", False)), reading=v.get("reading") or "",
                   data_to_converge_samples=_opt(v, "data_to_converge_samples"),
                   nav_err_before_km=_opt(v, "nav_err_before_km"), nav_err_after_km=_opt(v, "nav_err_after_km"),
                   nav_note=v.get("nav_note") or "",
                   iterations_plain_median=_opt(v, "iterations_plain_median"),
                   iterations_plain_extrapolated_median=_opt(v, "iterations_plain_extrapolated_median"),
                   iterations_squarem_median=_opt(v, "iterations_squarem_median"))


@dataclass(frozen=True)
class HeadlineSummary:
    """What the report layer reads of A-summary.json (:func:`summary`) for the manuscript's
    finding sentences and the scorecard's headline rows, by meaning (issue 41 item 4).

    ``rows``                  the headline rows in the summary's order (:class:`HeadlineRow`);
    ``prior_bound_arcsec``    what the prior alone bounds theta to (:func:`prior_bound_arcsec`);
    ``convergence_max_maps``  the EM maps the convergence study runs (None: not stated);
    ``roll_rate``             :func:`roll_rate_summary` (None: no roll-rate study);
    ``stars``                 :func:`stars_summary` (None: no stars study);
    ``mars_attitude``         :func:`mars_attitude_summary` (None: not computed);
    ``nees``                  :func:`nees_summary` (None: not computed);
    ``nav_floor_by_arc``      :func:`nav_floor_summary` (None: not computed);
    ``tz_nav_effect``         :func:`opnav.approach.navfloor.tz_nav_effect` (None: not computed).
    """

    rows: tuple[HeadlineRow, ...]
    prior_bound_arcsec: float = math.nan
    convergence_max_maps: int | None = None
    roll_rate: Mapping[str, Any] | None = None
    stars: Mapping[str, Any] | None = None
    mars_attitude: Mapping[str, Any] | None = None
    nees: Mapping[str, Any] | None = None
    nav_floor_by_arc: Mapping[str, Any] | None = None
    tz_nav_effect: Mapping[str, Any] | None = None

    @classmethod
    def from_json(cls, summ: Mapping[str, Any]) -> HeadlineSummary:
        """From the dict :func:`summary` returns (or A-summary.json as read back); a row
        without estimates (``est_x_mean``) is not a headline row and is left out."""
        rows = tuple(HeadlineRow.from_json(k, v) for k, v in (summ.get("variants") or {}).items()
                     if isinstance(v, Mapping) and "est_x_mean" in v)
        return cls(rows=rows, prior_bound_arcsec=float(summ.get("prior_bound_arcsec", math.nan)),
                   convergence_max_maps=summ.get("convergence_max_maps"),
                   roll_rate=summ.get("roll_rate"), stars=summ.get("stars"),
                   mars_attitude=summ.get("mars_attitude"), nees=summ.get("nees"),
                   nav_floor_by_arc=summ.get("nav_floor_by_arc"), tz_nav_effect=summ.get("tz_nav_effect"))
