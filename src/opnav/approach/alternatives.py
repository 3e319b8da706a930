"""A-X2: the EM-EKF against the alternatives a user would try, on the Table-1 cases (SPEC A.4).

Description
    For every Table-1 case (:func:`opnav.approach.cases.table1_cases`), scenario
    variant and Monte-Carlo seed of the EM-EKF runs (same measurement streams
    ``SeedSequence([base_seed, case_index, seed_index])``, same scenario
    geometry), :func:`run_case_alternatives` runs

    * the augmented EKF (:mod:`opnav.approach.augmented`), theta as constant
      states with the config prior;
    * batch maximum likelihood (:mod:`opnav.approach.batch_ml`), CasADi + IPOPT
      on the exact marginal likelihood.

    Both use the data of the EM's segments, samples ``N0+1 .. N0+L*N``, from
    the state the EM's first segment starts from in that variant (``literal``:
    the theta = 0 filter's ``X_N0, P_N0``; ``prior``/``roll``: the prior
    propagated to ``N0``; ``reference-start``: the true state with the filter's
    ``P_N0``, diagnostic), with theta started at the case's initial value.

Written rules (shared with the EM-EKF's Table 1, :mod:`opnav.approach.cases`)
    * *Bias error*: ``theta_hat - theta_true`` for tx and ty, arcsec; mean and
      sample standard deviation over seeds.
    * *Navigation error after compensation* (km): the EKF over the whole arc
      with the method's final estimate, RMS of ``|r_hat - r_true|`` over the
      last ``nav_error.last_fraction`` of the arc (:func:`cases.rms_last`).
    * *Data needed*: the EM's rule (:func:`cases.data_to_converge`) applied to
      the estimate after each ``N`` samples: for the augmented EKF its state at
      those samples (all seeds); for batch ML the IPOPT solutions on the
      growing windows ending every ``checkpoint_stride`` segments (and at
      ``L N``), warm-started, for the first ``alternatives.batch_ml.checkpoint_seeds``
      seeds (each checkpoint is a full batch solve), so its resolution is
      ``checkpoint_stride * N`` samples.
    * *Run time* (s per seed, wall clock, this machine): augmented EKF = the
      filter over all seeds / S; batch ML = build of the NLP (shared by the
      seeds of a case, includes the one-off JIT compilation) + preconditioner
      + IPOPT on the final window, / S;
      batch ML with checkpoints: per checkpoint seed.
The A-X2 tables (long form per case, the per-method table, the summary JSON) are
in :mod:`opnav.approach.alternatives_summary`.
Units: arcsec, km, samples, s.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from . import cases
from . import scenario as sc
from .augmented import run_augmented
from .dynamics import ARCSEC
from .ekf import run_filter
from .pipeline import cases_in
from .setup import Setup

def los_boresight(geo: sc.Geometry) -> np.ndarray:
    """``u`` along the camera boresight at the reference range (n+1, 3): the linearisation
    point of the batch-ML preconditioner (the camera tracks Mars, so the true ``u``
    has no lateral part)."""
    u = np.zeros_like(geo.u_ref)
    u[:, 2] = geo.rho_ref
    return u


def checkpoint_samples(seg_data: np.ndarray, stride: int) -> np.ndarray:
    """Every ``stride``-th segment end, always including the last one (samples after N0)."""
    idx = np.arange(len(seg_data))[::-1][::stride][::-1]
    return np.asarray(seg_data)[idx]


@dataclass(frozen=True)
class AugmentedResult:
    """The augmented EKF on one case (:func:`run_case_alternatives`), per seed: the final estimate
    and its own 1-sigma (arcsec, (S, 3)), the estimate after each segment's data (S, L, 3), the
    data to converge (EM's rule, samples), the navigation error after compensation (km) and the
    run time (s per seed)."""

    theta_final_arcsec: np.ndarray
    theta_seg_arcsec: np.ndarray
    sigma_final_arcsec: np.ndarray
    data_to_converge: np.ndarray
    nav_err_after_km: np.ndarray
    runtime_s_per_seed: float


@dataclass(frozen=True)
class BatchMLResult:
    """Batch ML (CasADi + IPOPT) on one case: the final window's estimate (arcsec, (S, 3)), IPOPT's
    gradient norm, iterations and success per seed, the navigation error after compensation (km),
    the run times (s per seed: build + solve, solve; the build's s); and, on growing checkpoint
    windows for the first ``checkpoint_seeds`` seeds, the estimates there (``theta_seg_arcsec``),
    their data (samples), the data to converge and the largest distance of the last checkpoint
    from the final estimate (None / NaN / 0 without checkpoints)."""

    theta_final_arcsec: np.ndarray
    grad_norm: np.ndarray
    ipopt_iterations: np.ndarray
    ipopt_success: np.ndarray
    nav_err_after_km: np.ndarray
    runtime_s_per_seed: float
    runtime_solve_s_per_seed: float
    runtime_build_s: float
    theta_seg_arcsec: np.ndarray | None = None
    checkpoint_data_used: np.ndarray | None = None
    data_to_converge: np.ndarray | None = None
    checkpoint_seeds: int = 0
    checkpoint_max_dev_from_final_arcsec: float = math.nan
    runtime_checkpoints_s_per_seed: float = math.nan


@dataclass(frozen=True)
class AltRun:
    """The alternatives on one Table-1 case and variant (:func:`run_case_alternatives`): the case,
    its seeds and truth (arcsec), the EM's segment data ends (samples after N0), and each
    method's result (``batch_ml`` None when not run)."""

    variant: str
    case: cases.Case
    seed_indices: np.ndarray
    truth_arcsec: np.ndarray
    seg_data_used: np.ndarray
    augmented: AugmentedResult
    batch_ml: BatchMLResult | None = field(default=None)

    @property
    def case_id(self) -> str:
        return self.case.case_id

    def methods(self) -> Iterator[tuple[str, AugmentedResult | BatchMLResult]]:
        """(method name, result) of each method run, in the order run."""
        yield "augmented", self.augmented
        if self.batch_ml is not None:
            yield "batch_ml", self.batch_ml


@dataclass(frozen=True)
class StarCounts:
    """Stars per image along the arc: the fewest, the median and the most."""

    min: int
    median: float
    max: int


@dataclass(frozen=True)
class StarsEstimate:
    """One estimator of a stars-study row, per seed: the final estimate (arcsec, (S, 3)) and the
    data to converge (samples); the EM's label and the ML estimate of its data, the augmented
    EKF's own 1-sigma (None where the estimator has none)."""

    theta_final_arcsec: np.ndarray
    data_to_converge: np.ndarray
    label: np.ndarray | None = None
    theta_ml_arcsec: np.ndarray | None = None
    sigma_final_arcsec: np.ndarray | None = None


@dataclass(frozen=True)
class StarsRow:
    """One swept value of the stars study (:func:`stars_study`): the sweep (``per_image`` or
    ``attitude_sigma_arcsec``) and its value, the stars' settings (stars per image, every K samples,
    attitude knowledge and drift, arcsec; magnitude limit; field and the camera's, deg, full width),
    the star images and the stars per image along the arc, the attitude floor
    ``hypot(sigma_a / sqrt(images), drift)``, the bound of the star images alone, the truth, the
    data after N0 and the bound after it (Q and Q = 0, (3,)) with its curve (samples, 3); per
    estimator its :class:`StarsEstimate`; the attitude knowledge at which the bound reaches the
    target (arcsec, the same for every row)."""

    sweep: str
    value: float
    per_image: int
    every_K: int
    attitude_sigma_arcsec: float
    mode_drift_arcsec: float
    mag_limit: float
    field_deg: float
    camera_field_deg: float
    images: int
    stars_per_image: StarCounts
    floor_arcsec: float
    crlb_stars_only_arcsec: np.ndarray
    truth_arcsec: np.ndarray
    total_samples: int
    crlb_all_arcsec: np.ndarray
    crlb_all_q0_arcsec: np.ndarray
    crlb_curve_arcsec: np.ndarray
    estimators: dict[str, StarsEstimate]
    attitude_threshold_arcsec: float = math.nan


class _BatchCache:
    """BatchML objects per checkpoint set: the NLP depends on the geometry only (the pixel
    noise enters as parameters); one cache per geometry (variant), shared by its cases."""

    def __init__(self):
        self.store = {}

    def get(self, key, make):
        if key not in self.store:
            t = time.perf_counter()
            self.store[key] = (make(), time.perf_counter() - t)
        return self.store[key]


def run_case_alternatives(setup: Setup, variant: str, case: cases.Case, seed_indices,
                          geo: sc.Geometry, cache: _BatchCache | None = None,
                          methods=("augmented", "batch_ml")) -> AltRun:
    """Augmented EKF and batch ML for one case and variant over the given seeds."""
    alt = setup.alternatives
    seg = setup.segments
    N0, N, L = seg.N0, seg.N, seg.L
    cache = cache or _BatchCache()
    seeds = list(seed_indices)
    Rvar, z, dx0 = cases.simulate_case(setup, geo, case, seeds, setup.initial_error.mode)
    win = geo.window(Rvar, geo.simulate_stars(sc.rad(case.truth_arcsec), setup.base_seed, case.case_index, seeds))
    S = z.shape[0]
    start = sc.START_OF[variant]
    f0 = None if start == "prior" else run_filter(z[:, :N0 + 1], np.zeros((S, 3)), dx0, geo.P0, win.slice(0, N0), predicted=False)
    x0, P0 = cases.start_state(start, N0, f0, geo.dx_true, dx0, geo.P0, win)
    P0 = np.broadcast_to(P0, (S, 6, 6))  # one per seed (the prior's is shared)
    wwin = win.slice(N0, N0 + L * N)
    zw = z[:, N0:N0 + L * N + 1]
    th0 = np.broadcast_to(sc.rad(case.init_arcsec), (S, 3)).copy()
    seg_data = np.array([(l + 1) * N for l in range(L)])
    tol = setup.em.converge_tol_arcsec
    frac = setup.nav_last_fraction

    def nav_after(theta_rad):
        f = run_filter(z, theta_rad, dx0, geo.P0, win, predicted=False)
        err = np.linalg.norm(f.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
        return cases.rms_last(err, frac)

    # (a) augmented EKF
    a = alt.augmented
    t = time.perf_counter()
    ra = run_augmented(zw, x0, P0, th0, sc.rad(a.theta_prior_sigma_arcsec), wwin,
                       q_theta=(a.theta_process_sigma_arcsec * ARCSEC) ** 2)
    t_aug = (time.perf_counter() - t) / S
    seg_th = sc.arcsec(ra.theta[:, seg_data])
    out = AltRun(variant=variant, case=case, seed_indices=np.asarray(seeds),
                 truth_arcsec=np.asarray(case.truth_arcsec, float), seg_data_used=seg_data,
                 augmented=AugmentedResult(
                     theta_final_arcsec=seg_th[:, -1],
                     theta_seg_arcsec=seg_th,
                     sigma_final_arcsec=sc.arcsec(np.sqrt(np.diagonal(ra.P_theta[:, -1], axis1=1, axis2=2))),
                     data_to_converge=cases.data_to_converge(seg_th, seg_data, tol),
                     nav_err_after_km=nav_after(ra.theta[:, -1]),
                     runtime_s_per_seed=t_aug))

    if "batch_ml" not in methods:
        return out
    # (b) batch ML: final window for every seed; growing checkpoints for the first few seeds
    from .batch_ml import BatchML  # CasADi: imported where used (the records above are read without it)

    b = alt.batch_ml
    sig = sc.rad(b.theta_prior_sigma_arcsec)
    key = "final"
    bm, t_build = cache.get(key, lambda: BatchML(wwin, [L * N], sig, jit=b.jit, tol=b.tol))
    t = time.perf_counter()
    rb = bm.solve(zw, x0, P0, th0, wwin.u_ref, rvar=wwin.Rvar)
    t_solve = time.perf_counter() - t
    ncp = min(b.checkpoint_seeds, S)
    res_b = BatchMLResult(
        theta_final_arcsec=sc.arcsec(rb.theta[:, -1]),
        grad_norm=rb.grad_norm[:, -1],
        ipopt_iterations=rb.iterations[:, -1],
        ipopt_success=rb.success[:, -1],
        nav_err_after_km=nav_after(rb.theta[:, -1]),
        runtime_s_per_seed=(t_build + t_solve) / S,
        runtime_solve_s_per_seed=t_solve / S,
        runtime_build_s=t_build)
    if ncp > 0:
        cp = checkpoint_samples(seg_data, b.checkpoint_stride)
        bmc, t_build_c = cache.get("checkpoints",
                                   lambda: BatchML(wwin, cp, sig, jit=b.jit, tol=b.tol))
        t = time.perf_counter()
        rc = bmc.solve(zw[:ncp], x0[:ncp], P0[:ncp], th0[:ncp], wwin.u_ref, rvar=wwin.Rvar)
        t_cp = time.perf_counter() - t
        cth = sc.arcsec(rc.theta)
        res_b = replace(
            res_b,
            theta_seg_arcsec=cth,
            checkpoint_data_used=cp,
            data_to_converge=cases.data_to_converge(cth, cp, tol),
            checkpoint_seeds=ncp,
            checkpoint_max_dev_from_final_arcsec=float(np.abs(cth[:, -1] - res_b.theta_final_arcsec[:ncp])[:, :2].max()),
            runtime_checkpoints_s_per_seed=t_cp / ncp + t_build_c / S)
    return replace(out, batch_ml=res_b)


def run_group_alternatives(setup: Setup, variant: str, group: str, log=None,
                           geo: sc.Geometry | None = None) -> list[AltRun]:
    """Alternatives for every case of a Table-1 ``group`` under ``variant`` (one Snakemake job)."""
    geo = geo or sc.build_geometry(setup, variant)
    cache = _BatchCache()
    seeds = range(setup.n_seeds)
    res = []
    for case in cases_in(setup, group):
        r = run_case_alternatives(setup, variant, case, seeds, geo, cache)
        res.append(r)
        if log:
            log.info("%s %s %s: aug %s ml %s", variant, group, case.case_id,
                     np.round(r.augmented.theta_final_arcsec.mean(0), 3),
                     np.round(r.batch_ml.theta_final_arcsec.mean(0), 3))
    return res


def time_em(setup: Setup, variant: str, case: cases.Case, seed_indices, geo: sc.Geometry) -> dict[str, float]:
    """Wall time per seed of the EM-EKF (:func:`cases.run_case`) for each configured EM scheme.

    ``run_case`` also runs the theta = 0 and the compensated full-arc filters
    (2 of its ``1 + M L + 1`` filter passes); the time includes them.
    """
    out = {}
    S = len(list(seed_indices))
    for m in setup.methods:
        t = time.perf_counter()
        cases.run_case(setup, variant, case, seed_indices, geo=geo, method=m)
        out[f"em_{m}"] = (time.perf_counter() - t) / S
    return out


def stars_study(setup: Setup, target_arcsec: float, log=None) -> list[StarsRow]:
    """The ``stars`` variant (beyond the paper), headline case, ``n_seeds`` seeds, one row per
    swept value (``sweep``):

    * ``per_image``: stars per image, each value of ``stars.study_count`` made real (issue 54,
      item 4): ``per_image`` = the count, with the magnitude limit and field at which every image
      holds that many stars (:func:`opnav.approach.stars.count_settings`: the camera's field and
      the brightest limit that gives every image the count; the catalogue's limit and a widened
      field where the camera's field holds too few). The bound of (tx, ty, tz) after all the data
      with Q and Q = 0 and its curve against the data, beside the EM-EKF with growing windows and
      SQUAREM, the paper's sliding plain EM and the augmented EKF;
    * ``attitude_sigma_arcsec``: the per-image attitude knowledge
      (``stars.study_attitude_sigma_arcsec``) at the configured stars (the bound and the
      growing-window SQUAREM EM-EKF).

    Every row also holds the stars-only bound (the star images' information alone), the stars
    per image along the arc, the magnitude limit and the field (deg, full width), and the attitude
    knowledge at which the bound reaches ``target_arcsec`` (:func:`attitude_threshold`; the claimed
    accuracy, the analysis plan's A-C1 target)."""
    from . import stars as stars_mod
    from .pipeline import bound_curves
    case = cases.headline_case(setup)
    seeds = range(setup.n_seeds)
    st0 = setup.stars
    geo0 = sc.build_geometry(setup, "stars")
    cam_half = sc.camera_half_fov_rad(setup)
    plan = []
    for m in st0.study_count:
        cs = stars_mod.count_settings(geo0.C, setup.segments.N0, st0.every_K, int(m), st0.mag_limit, st0.slew_deg,
                                      cam_half, stars_mod.catalogue())
        plan.append(("per_image", float(m), replace(st0, per_image=int(m), mag_limit=cs.mag_limit),
                     cs.half_fov_rad, True))
    plan += [("attitude_sigma_arcsec", float(a), replace(st0, attitude_sigma_arcsec=float(a)), cam_half, False)
             for a in st0.study_attitude_sigma_arcsec]
    out = []
    for sweep, value, st, half_fov, full in plan:
        s_m = setup.replace(stars=st)
        geo = sc.with_stars(geo0, s_m, half_fov)  # the same arc, these stars
        Rvar = geo.measurement_variance(case.sigma3_px)
        c, c0 = bound_curves(s_m, geo, [(Rvar, case.truth_arcsec, False), (Rvar, case.truth_arcsec, True)], "stars")
        d = min(s_m.segments.data_samples, len(c) - 1)
        n_img = int(np.sum(geo.stars.idx <= geo.t.size - 1))
        J = geo.stars.info_per_sample(geo.t.size - 1).sum(0)
        ns = geo.stars.n_stars
        estimators = {}
        ems = (("em_growing_squarem", s_m.scheme("growing"), "squarem"),) + ((("em_plain", s_m, "plain"),) if full else ())
        for name, sx, method in ems:
            r = cases.run_case(sx, "stars", case, seeds, geo=geo, method=method)
            estimators[name] = StarsEstimate(r.theta_final_arcsec, r.data_to_converge, label=r.label,
                                             theta_ml_arcsec=r.theta_ml_arcsec)
        if full:
            a = run_case_alternatives(s_m, "stars", case, seeds, geo, methods=("augmented",)).augmented
            estimators["augmented"] = StarsEstimate(a.theta_final_arcsec, a.data_to_converge,
                                                    sigma_final_arcsec=a.sigma_final_arcsec)
        row = StarsRow(
            sweep=sweep, value=value, per_image=int(st.per_image), every_K=st.every_K,
            attitude_sigma_arcsec=st.attitude_sigma_arcsec, mode_drift_arcsec=st.mode_drift_arcsec,
            mag_limit=st.mag_limit, field_deg=float(2.0 * np.degrees(half_fov)),
            camera_field_deg=float(2.0 * np.degrees(cam_half)), images=n_img,
            stars_per_image=StarCounts(int(ns.min()), float(np.median(ns)), int(ns.max())),
            floor_arcsec=float(np.hypot(st.attitude_sigma_arcsec / np.sqrt(n_img), st.mode_drift_arcsec)),
            crlb_stars_only_arcsec=sc.arcsec(np.sqrt(np.diag(np.linalg.pinv(J)))),
            truth_arcsec=np.asarray(case.truth_arcsec, float), total_samples=int(d),
            crlb_all_arcsec=c[d], crlb_all_q0_arcsec=c0[d], crlb_curve_arcsec=c, estimators=estimators)
        if log:
            log.info("stars %s = %g: %s stars per image, bound %s arcsec (stars only %s), EM growing %s", sweep, value,
                     row.stars_per_image, np.round(c[d], 3), np.round(row.crlb_stars_only_arcsec, 3),
                     np.round(estimators["em_growing_squarem"].theta_final_arcsec.mean(0), 3))
        out.append(row)
    thr = attitude_threshold(setup, target_arcsec)
    return [replace(row, attitude_threshold_arcsec=thr) for row in out]


def attitude_threshold(setup: Setup, target_arcsec: float, hi_arcsec: float = 3600.0,
                       iterations: int = 30) -> float:
    """The per-image attitude knowledge (1-sigma, arcsec) at which the bound of tx and ty after all
    the data of the ``stars`` variant (configured stars, drift and magnitude limit) reaches
    ``target_arcsec``: bisection (the bound grows with it); 0 if not even perfect knowledge reaches
    it, ``hi_arcsec`` if any knowledge up to it does."""
    from dataclasses import replace

    from .pipeline import bound_curves
    case = cases.headline_case(setup)
    geo0 = sc.build_geometry(setup, "stars")
    Rvar = geo0.measurement_variance(case.sigma3_px)

    def worst(a):
        s = setup.replace(stars=replace(setup.stars, attitude_sigma_arcsec=float(a)))
        g = sc.with_stars(geo0, s)
        c = bound_curves(s, g, [(Rvar, case.truth_arcsec, False)], "stars")[0]
        return float(c[min(s.segments.data_samples, len(c) - 1), :2].max())

    if worst(0.0) > target_arcsec:
        return 0.0
    if worst(hi_arcsec) <= target_arcsec:
        return hi_arcsec
    lo, hi = 0.0, hi_arcsec
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if worst(mid) <= target_arcsec else (lo, mid)
    return lo
