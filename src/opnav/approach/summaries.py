"""Paper A's numbers from the simulation results: A-T1 in long form, the A-X1 bound table,
the roll-rate and stars studies, and A-summary.json.

Pure functions of the typed records of :mod:`opnav.approach.pipeline` and
:mod:`opnav.approach.alternatives`, returning typed records (A-summary.json is
:class:`ASummary`, written by the workflow's edge through :func:`opnav.core.tables.json_ready`);
editing this module reruns only the table rules, never the Monte Carlo. The words beside the
numbers (readings, notes, why, rule, reason) are :mod:`opnav.report.approach.text`'s, the
manuscript's sentences :mod:`opnav.report.approach_text`'s. Units: arcsec, km, samples.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from opnav.core.tables import JSON_SKIP, OMIT_NONE, json_key

from . import cases
from . import scenario as sc
from .labels import label_columns, row_label, variant_label
from .setup import Setup

if TYPE_CHECKING:  # the records only (alternatives imports CasADi)
    from .alternatives import StarsRow
    from .navfloor import NavFloor
    from .pipeline import RollRateBounds


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
            **dataclasses.asdict(label_columns(r, target)),
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


@dataclass(frozen=True)
class NeesRow:
    """Filter consistency of one headline row (T1-01, initial error drawn from the prior, whole arc;
    :func:`nees_summary`): the position NEES of the filter compensated with the estimate taken as
    exact (``nees_mean``) and of the Schmidt filter carrying its covariance (``consider_nees_mean``)
    beside the NEES of the filter given the true theta on the same runs (``reference_nees_mean``: the
    truth has no process noise while the filters' Q > 0, so that filter's NEES, not 3, is what a
    consistent compensation would show), the theta = 0 filter's, the paired differences to the
    reference (seed mean and standard error), the seeds and the row's scheme (None: not held)."""

    nees_mean: float | None
    reference_nees_mean: float
    consider_nees_mean: float | None
    before_nees_mean: float | None
    n_seeds: int | None
    after_minus_reference_mean: float | None
    after_minus_reference_se: float | None
    consider_minus_reference_mean: float | None
    consider_minus_reference_se: float | None
    scenario: str
    method: str
    mode: str


def nees_summary(t1: pd.DataFrame) -> dict[str, NeesRow]:
    """Issue 54, item 5: per headline row (its A-T1 ``variant``) with the true-theta filter's NEES,
    its :class:`NeesRow`."""
    out = {}
    for r in t1[t1.case_id == "T1-01"].itertuples():
        ref = _num(r, "nees_pos_true_theta_mean")
        if ref is None:
            continue
        out[r.variant] = NeesRow(
            nees_mean=_num(r, "nees_pos_after_mean"), reference_nees_mean=ref,
            consider_nees_mean=_num(r, "nees_pos_consider_mean"), before_nees_mean=_num(r, "nees_pos_before_mean"),
            n_seeds=int(r.nees_n_seeds) if _num(r, "nees_n_seeds") is not None else None,
            after_minus_reference_mean=_num(r, "nees_pos_after_minus_true_theta_mean"),
            after_minus_reference_se=_num(r, "nees_pos_after_minus_true_theta_se"),
            consider_minus_reference_mean=_num(r, "nees_pos_consider_minus_true_theta_mean"),
            consider_minus_reference_se=_num(r, "nees_pos_consider_minus_true_theta_se"),
            scenario=r.scenario, method=r.method, mode=r.mode)
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
    h = t1[(t1.scenario == variant) & (t1.case_id == "T1-01") & (t1["mode"] == "sliding")]  # (t1.mode: a method)
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


@dataclass(frozen=True)
class RollRateSummary:
    """The roll-rate study (:func:`opnav.approach.pipeline.roll_rate_study`) for the summary: per
    rate the worse of (tx, ty) bounds after the published data and after all the data (with Q and
    Q = 0), arcsec; the log-log slope; the rate reaching the target in that data (deg/s; None: none
    in the searched range); the target and the configured rate."""

    rates_deg_s: list
    samples: int
    total_samples: int
    bound_at_samples_arcsec: list
    bound_all_arcsec: list
    bound_all_q0_arcsec: list
    slope_all: float
    rate_to_target_deg_s: float | None
    target_arcsec: float
    config_rate_deg_s: float


def roll_rate_summary(study: RollRateBounds) -> RollRateSummary:
    """:class:`RollRateSummary` of a roll-rate study."""
    def worst(b):
        return [float(v) for v in np.asarray(b)[:, :2].max(1)]

    rate = study.rate_to_target_deg_s
    return RollRateSummary(rates_deg_s=[float(r) for r in study.rates_deg_s], samples=int(study.samples),
                           total_samples=int(study.total_samples),
                           bound_at_samples_arcsec=worst(study.bound_at_samples_arcsec),
                           bound_all_arcsec=worst(study.bound_all_arcsec),
                           bound_all_q0_arcsec=worst(study.bound_all_q0_arcsec),
                           slope_all=float(study.slope_all),
                           rate_to_target_deg_s=None if not math.isfinite(rate) else float(rate),
                           target_arcsec=float(study.target_arcsec), config_rate_deg_s=float(study.config_rate_deg_s))


@dataclass(frozen=True)
class MarsAttitude:
    """The Mars images' attitude knowledge (issue 54, item 3) for the summary
    (:func:`mars_attitude_summary`): the configured value (``default_arcsec``) and the study's
    values, and per variant the worse of (tx, ty) of the bound of all the data with it
    (``default``) and at each study value (keyed ``f"{value:g}"``), arcsec; ``why``: the words
    (the report's)."""

    default_arcsec: float
    values_arcsec: list
    bound_all_arcsec: dict[str, dict[str, float]]
    why: str = ""


def mars_attitude_summary(setup: Setup, bounds: Mapping[str, Mapping[float, Any]] | None,
                          curves: Mapping[str, np.ndarray]) -> MarsAttitude:
    """:class:`MarsAttitude` from the bounds of :func:`opnav.approach.pipeline.mars_attitude_bounds`
    per variant and the variants' bound curves."""
    d = setup.segments.data_samples
    out = {}
    for v, c in curves.items():
        row = {"default": float(np.asarray(c)[min(d, len(c) - 1), :2].max())}
        for a, b in (bounds or {}).get(v, {}).items():
            row[f"{float(a):g}"] = float(np.asarray(b)[:2].max())
        out[v] = row
    return MarsAttitude(default_arcsec=float(setup.camera.attitude_sigma_arcsec),
                        values_arcsec=[float(a) for a in setup.camera.attitude_study_arcsec], bound_all_arcsec=out)


@dataclass(frozen=True)
class RollRateBound:
    """The roll variant's bound against the roll rate for the claims scorer (issue 54,
    :func:`roll_rate_bound_summary`): on the log grid of the roll-rate study, the worse of the
    (tx, ty) 1-sigma bounds after the published data (``samples`` after N0), arcsec; the scorer
    reads the rate at which it reaches the plan's target; ``rule``: the words (the report's)."""

    rate_deg_s: list
    bound_arcsec: list
    samples: int
    rule: str = ""


def roll_rate_bound_summary(study: RollRateBounds) -> RollRateBound:
    return RollRateBound(rate_deg_s=[float(r) for r in study.grid_rates_deg_s],
                         bound_arcsec=[float(b) for b in np.asarray(study.bound_grid_arcsec)[:, :2].max(1)],
                         samples=int(study.samples))


@dataclass(frozen=True)
class NavFloorSummary:
    """:func:`opnav.approach.navfloor.nav_floor_by_arc` for the summary: the rows (field order: the
    claims engineer's contract first, issue 54), without the per-seed arrays; ``rule``: the words
    (the report's)."""

    variant: str
    scenario: str
    scheme: str
    rows: tuple
    n_seeds: int = field(default=0, metadata=JSON_SKIP)
    last_fraction: float = field(default=math.nan, metadata=JSON_SKIP)
    rule: str = ""


def nav_floor_summary(nf: NavFloor) -> NavFloorSummary:
    return NavFloorSummary(variant=nf.variant, scenario=nf.scenario, scheme=nf.scheme, rows=nf.rows,
                           n_seeds=nf.n_seeds, last_fraction=nf.last_fraction)


def nav_floor_frame(nf: NavFloor) -> pd.DataFrame:
    """A-X7: one row per arc length (:class:`opnav.approach.navfloor.NavFloorRow`'s fields)."""
    return pd.DataFrame([dataclasses.asdict(r) for r in nf.rows])


@dataclass(frozen=True)
class FigureRows:
    """One of paper A's figures read against ours (:func:`figures_5_6`): the claims that judge its
    numbers, its rows (dicts: the figure's quantities per A-T1 row) and ``reason``: the words (the
    report's)."""

    claims: list
    rows: list
    reason: str = ""


@dataclass(frozen=True)
class Figures56:
    """Paper A's Figs. 5 and 6 (issue 54, item 7), keyed ``A-F5`` and ``A-F6`` in JSON."""

    f5: FigureRows = field(metadata=json_key("A-F5"))
    f6: FigureRows = field(metadata=json_key("A-F6"))


def figures_5_6(results: list[cases.CaseRun]) -> Figures56:
    """Paper A's Figs. 5 and 6 (issue 54, item 7): the numbers of ours that answer each, from the
    headline (T1-01) runs of every variant and scheme. Fig. 5 (navigation accuracy during the
    estimation) states no number: its rows are the position error at the end of the first and the
    last segment (the filter inside the EM, mean over seeds). Fig. 6 (navigation before and after
    compensation) carries Table 1's numbers (A-C6, A-C7, by the table's rule); its rows add the
    errors at the arc's last sample."""
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
    return Figures56(f5=FigureRows(claims=[], rows=f5), f6=FigureRows(claims=["A-C6", "A-C7"], rows=f6))


def _stars_key(row: StarsRow) -> str:
    """Summary key of a stars-study row: ``m<k>`` (k stars in every image) or ``att<v>``
    (attitude knowledge, arcsec); '.' written 'p', '-' written 'n'."""
    if row.sweep == "per_image":
        return f"m{row.per_image}"
    tag = {"attitude_sigma_arcsec": "att"}[row.sweep]
    return tag + f"{row.value:g}".replace(".", "p").replace("-", "n")


@dataclass(frozen=True)
class StarsEstimatorSummary:
    """One estimator of a stars-study row in the summary: seed mean and sd of (tx, ty, tz), RMS error
    in (tx, ty), arcsec; the EM's label and the RMS error of the ML estimate of its data (None: the
    estimator has none)."""

    mean_arcsec: list
    sd_arcsec: list
    rmse_xy_arcsec: float
    label: str | None = field(default=None, metadata=OMIT_NONE)
    ml_rmse_xy_arcsec: float | None = field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class StarsRowSummary:
    """One stars-study row in the summary (:func:`stars_summary`): its settings, stars per image along
    the arc, the bound of tx, ty, tz after all the data (Q and Q = 0) and of the star images alone,
    the attitude floor, samples after N0 until the bound of tx and ty is at most the target (None:
    never), and per estimator its :class:`StarsEstimatorSummary`."""

    sweep: str
    per_image: int
    every_K: int
    images: int
    total_samples: int
    attitude_sigma_arcsec: float
    mode_drift_arcsec: float
    mag_limit: float
    field_deg: float
    camera_field_deg: float
    stars_per_image: Any
    floor_arcsec: float
    crlb_arcsec: list
    crlb_q0_arcsec: list
    crlb_stars_only_arcsec: list
    samples_to_target: float | None
    estimators: dict[str, StarsEstimatorSummary]


@dataclass(frozen=True)
class StarsObjection:
    """The attitude knowledge at which the stars bound reaches the target (arcsec), and the target."""

    attitude_threshold_arcsec: float
    target_arcsec: float


@dataclass(frozen=True)
class StarsSummary:
    """The stars study for the summary: each row by its key (:func:`_stars_key`, written at the top
    level of the JSON object) and ``objection``."""

    rows: dict[str, StarsRowSummary] = field(metadata={"json_flatten": True})
    objection: StarsObjection | None = field(default=None, metadata=OMIT_NONE)


def stars_summary(study: list[StarsRow], target_arcsec: float) -> StarsSummary:
    """The stars study (:func:`opnav.approach.alternatives.stars_study`) for the summary, per row
    (:func:`_stars_key`; :class:`StarsRowSummary`), with the attitude knowledge at which the bound
    reaches ``target_arcsec`` (``objection``)."""
    out = {}
    for row in study:
        curve = np.asarray(row.crlb_curve_arcsec)
        need = _first_below(curve[:, :2].max(1), target_arcsec)
        truth = np.asarray(row.truth_arcsec, float)
        est = {}
        for name, e in row.estimators.items():
            th = np.asarray(e.theta_final_arcsec, float)
            ml = None if e.theta_ml_arcsec is None else np.asarray(e.theta_ml_arcsec, float)
            est[name] = StarsEstimatorSummary(
                mean_arcsec=[float(x) for x in th.mean(0)],
                sd_arcsec=[float(x) for x in (th.std(0, ddof=1) if th.shape[0] > 1 else np.full(3, np.nan))],
                rmse_xy_arcsec=float(np.sqrt(np.mean((th[:, :2] - truth[:2]) ** 2))),
                label=None if e.label is None else row_label(e.label)[0],
                ml_rmse_xy_arcsec=None if ml is None else float(np.sqrt(np.mean((ml[:, :2] - truth[:2]) ** 2))))
        out[_stars_key(row)] = StarsRowSummary(
            sweep=row.sweep, per_image=row.per_image, every_K=row.every_K, images=row.images,
            total_samples=row.total_samples, attitude_sigma_arcsec=row.attitude_sigma_arcsec,
            mode_drift_arcsec=row.mode_drift_arcsec, mag_limit=row.mag_limit, field_deg=row.field_deg,
            camera_field_deg=row.camera_field_deg, stars_per_image=row.stars_per_image,
            floor_arcsec=row.floor_arcsec, crlb_arcsec=[float(x) for x in row.crlb_all_arcsec],
            crlb_q0_arcsec=[float(x) for x in row.crlb_all_q0_arcsec],
            crlb_stars_only_arcsec=[float(x) for x in row.crlb_stars_only_arcsec],
            samples_to_target=None if math.isnan(need) else need, estimators=est)
    objection = (StarsObjection(float(study[0].attitude_threshold_arcsec), float(target_arcsec)) if study else None)
    return StarsSummary(rows=out, objection=objection)


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


@dataclass(frozen=True)
class VariantHeadline:
    """One headline (T1-01) row of A-summary.json ``variants`` (:func:`summary`): its scheme, the
    estimate's seed mean and sd and the sampled rerun's spread and RMS error, the bounds (of the
    data used, Q = 0, all the data), the convergence label and its counts, the filters'
    consistency, the distance to the ML estimate, the data to converge, the navigation errors and
    their split, the convergence study's EM maps and the variant's bound against the target (A-X1).
    A value the tables do not hold is None. ``reading`` and ``nav_note``: the row's words (the
    report's, :mod:`opnav.report.approach.text`)."""

    scenario: str
    method: str
    mode: str
    est_x_mean: float
    est_x_std: float
    est_y_mean: float
    est_y_std: float
    est_x_std_sampled: float | None
    rmse_x_sampled: float | None
    crlb_x_arcsec: float
    crlb_y_arcsec: float
    crlb_q0_x_arcsec: float | None
    crlb_all_x_arcsec: float | None
    crlb_all_y_arcsec: float | None
    label: str
    converged_seeds: int
    stalled: bool
    stalled_seeds: int
    n_seeds: int
    identifiable: bool
    nees_pos_before_mean: float | None
    nees_pos_after_mean: float | None
    nis_before_mean: float | None
    nis_after_mean: float | None
    nees_pos_consider_mean: float | None
    nees_pos_true_theta_mean: float | None
    contraction_per_map: float | None
    dist_to_ml_arcsec: float | None
    dist_to_ml_over_bound: float | None
    data_to_converge_samples: float | None
    nav_err_before_km: float
    nav_err_after_km: float
    nav_err_true_theta_km: float | None
    nav_err_consider_km: float | None
    nav_err_before_lat_km: float | None
    nav_err_before_rng_km: float | None
    nav_err_after_lat_km: float | None
    nav_err_after_rng_km: float | None
    nav_err_true_theta_lat_km: float | None
    nav_err_true_theta_rng_km: float | None
    iterations_plain_median: float | None
    iterations_plain_extrapolated_median: float | None
    iterations_squarem_median: float | None
    mle_rmse_x_arcsec: float | None
    bound_reaches_target: bool | None
    reading: str = ""
    nav_note: str = ""


@dataclass(frozen=True)
class ASummary:
    """A-summary.json (:func:`summary`; written by the workflow's approach_tables rule): the
    profile's segments, the claimed accuracy (the analysis plan's A-C1 target), what the prior
    alone bounds theta to, the convergence study's map budget, the headline rows by their A-T1
    ``variant`` (:class:`VariantHeadline`) and the studies' parts (None: not computed, left out of
    the JSON): roll rate, stars, consistency, the Mars images' attitude, the roll-rate bound, the
    navigation floor against arc length and tz, Figs. 5-6, the installation rows and the sample
    time; the build's profile and the manuscript's finding sentences (``text``, the report's)."""

    profile_segments: Any
    accuracy_target_arcsec: float
    prior_bound_arcsec: float
    convergence_max_maps: int
    variants: dict[str, VariantHeadline]
    roll_rate: RollRateSummary | None = field(default=None, metadata=OMIT_NONE)
    stars: StarsSummary | None = field(default=None, metadata=OMIT_NONE)
    nees: dict[str, NeesRow] | None = field(default=None, metadata=OMIT_NONE)
    mars_attitude: MarsAttitude | None = field(default=None, metadata=OMIT_NONE)
    roll_rate_bound: RollRateBound | None = field(default=None, metadata=OMIT_NONE)
    nav_floor_by_arc: NavFloorSummary | None = field(default=None, metadata=OMIT_NONE)
    tz_nav_effect: Any = field(default=None, metadata=OMIT_NONE)
    figures_5_6: Figures56 | None = field(default=None, metadata=OMIT_NONE)
    installation: Any = field(default=None, metadata=OMIT_NONE)
    sample_time: Any = field(default=None, metadata=OMIT_NONE)
    profile: str | None = field(default=None, metadata=OMIT_NONE)
    text: dict[str, str] | None = field(default=None, metadata=OMIT_NONE)

    def replace(self, **changes) -> ASummary:
        return dataclasses.replace(self, **changes)


def summary(setup: Setup, t1: pd.DataFrame, x1: pd.DataFrame, target_arcsec: float,
            roll_rate: RollRateBounds | None = None) -> ASummary:
    """Headline numbers per variant and EM scheme for the manuscript macros; ``target_arcsec``: the
    claimed accuracy (the analysis plan's A-C1 target); ``roll_rate``: the roll-rate study
    (:func:`opnav.approach.pipeline.roll_rate_study`), if run. The studies' parts are added with
    :meth:`ASummary.replace`."""
    variants = {}
    for r in t1[t1.case_id == "T1-01"].itertuples():
        xs = x1[x1.variant == r.scenario]
        x = next(xs.itertuples()) if len(xs) else None
        variants[r.variant] = VariantHeadline(
            scenario=r.scenario, method=r.method, mode=r.mode,
            est_x_mean=r.est_x_mean, est_x_std=r.est_x_std, est_y_mean=r.est_y_mean, est_y_std=r.est_y_std,
            est_x_std_sampled=_num(r, "est_x_std_sampled"), rmse_x_sampled=_num(r, "rmse_x_sampled"),
            crlb_x_arcsec=r.crlb_x_arcsec, crlb_y_arcsec=r.crlb_y_arcsec,
            crlb_q0_x_arcsec=_num(r, "crlb_q0_x_arcsec"),
            crlb_all_x_arcsec=_num(r, "crlb_all_x_arcsec"), crlb_all_y_arcsec=_num(r, "crlb_all_y_arcsec"),
            label=r.label, converged_seeds=int(r.converged_seeds), stalled=bool(r.stalled),
            stalled_seeds=int(r.stalled_seeds), n_seeds=int(r.n_seeds), identifiable=bool(r.identifiable),
            **{f: _num(r, f) for f in ("nees_pos_before_mean", "nees_pos_after_mean", "nis_before_mean",
                                       "nis_after_mean", "nees_pos_consider_mean", "nees_pos_true_theta_mean",
                                       "contraction_per_map", "dist_to_ml_arcsec", "dist_to_ml_over_bound",
                                       "data_to_converge_samples") + NAV_SPLIT_KEYS},
            nav_err_before_km=r.nav_err_before_km, nav_err_after_km=r.nav_err_after_km,
            iterations_plain_median=_num(x, "maps_plain_median"),
            iterations_plain_extrapolated_median=_num(x, "maps_plain_extrapolated_median"),
            iterations_squarem_median=_num(x, "maps_squarem_median"),
            mle_rmse_x_arcsec=_num(x, "mle_rmse_x_arcsec"),
            bound_reaches_target=bool(x.bound_reaches_target) if x is not None else None)
    return ASummary(profile_segments=setup.segments, accuracy_target_arcsec=float(target_arcsec),
                    prior_bound_arcsec=prior_bound_arcsec(setup),
                    convergence_max_maps=setup.convergence_study.max_maps, variants=variants,
                    roll_rate=roll_rate_summary(roll_rate) if roll_rate is not None else None)


def _num(row, key: str) -> float | None:
    """A row's (``itertuples``) value of column ``key`` as a float, None when absent, not a number,
    NaN or infinite."""
    try:
        v = float(getattr(row, key))
    except (AttributeError, TypeError, ValueError):
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
