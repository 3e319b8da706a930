"""Table-1 cases and the segment-wise EM-EKF run of one case over many seeds (paper A sec. 2.3, 3).

Description
    :func:`table1_cases` lists the paper's 17 cases in its 5 groups (bias size,
    polarity, initial value, pixel accuracy, installation angle); every case
    not varied keeps the headline values of the config.

    :func:`run_case` runs one case for a batch of seeds (all seeds go through
    the filter together as stacked arrays):

    1. simulate the measurements of every seed (truth: exact misalignment);
    2. run the theta = 0 EKF over the whole arc from the prior (the paper's
       "already observed data", step 1 of sec. 2.3);
    3. for segment l = 0..L-1 take the window of N samples starting at
       ``N0 + l N`` (``sliding``, the paper's reading) or all samples from N0
       to ``N0 + (l+1) N`` (``growing``); start it from the variant's state
       (see :mod:`opnav.approach.scenario`) and run M EM iterations seeded
       with the previous segment's estimate;
    4. run the EKF over the whole arc again with the final estimate, and the Schmidt
       (consider) EKF that also carries the estimate's covariance (the squared bound of the
       data it used plus its squared distance to that data's ML estimate;
       :mod:`opnav.approach.consider`), whose position NEES is reported
       beside the compensated filter's and the true-theta filter's.

Written rules (Table 1 columns)
    *Data needed to converge* (samples): for each seed, the smallest amount
    of data ``(l+1) N`` such that after segment l and after every later
    segment both |tx - tx_final| and |ty - ty_final| are at most
    ``em.converge_tol_arcsec``; the table reports the median over seeds. Only a
    run labelled *converged* has one (:func:`opnav.approach.em.convergence_labels`:
    within ``em.converge_frac_of_bound`` times the 1-sigma bound of its last segment's
    data (tx and ty each, and tz where star images observe it: :func:`label_axes`,
    :func:`label_bounds`) of that data's ML estimate;
    *stalled* when not and its contraction per map toward it is ``em.stall_rate`` or
    more; else *not converged*). The label reads the data, not the start.
    *Navigation error before / after compensation* (km): for each seed, the
    RMS of the position-error norm |r_hat - r_true| of the full-arc EKF
    (step 2 with theta = 0, step 4 with the final estimate) over the last
    ``nav_error.last_fraction`` of the arc; the table reports the mean (and
    standard deviation) over seeds.
Units: arcsec and km in outputs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import scenario as sc
from .consider import run_consider
from .ekf import predict_only, run_filter
from .em import CONVERGED, STALLED, contraction_per_map, convergence_labels, em_window, maps_per_segment, ml_estimate
from .setup import Setup

GROUPS = ("size", "polarity", "initial", "pixel", "install")
GROUP_TITLES = {
    "size": "bias size", "polarity": "polarity", "initial": "initial value",
    "pixel": "pixel accuracy (3-sigma)", "install": "installation angle",
}


@dataclass(frozen=True)
class Case:
    case_index: int  # 1..17, also the Monte-Carlo stream index
    case_id: str
    group: str
    truth_arcsec: tuple
    init_arcsec: tuple
    sigma3_px: tuple
    install_deg: float
    init_mode: str | None = None  # initial-error mode of this run (None: the config's)


def table1_cases(setup: Setup) -> list[Case]:
    """The 17 cases of paper A Table 1 (ids T1-01..T1-17, paper row order)."""
    truth = setup.truth_bias_arcsec
    init = setup.theta_init_arcsec
    px = setup.camera.sigma3_px
    rows = []
    for b in ([10, 20, 10], [10, 10, 10], [10, 3, 10]):
        rows.append(("size", tuple(map(float, b)), init, px, 0.0))
    for b in ([10, 20, 10], [-10, 20, 10], [-10, -20, 10], [10, -20, 10]):
        rows.append(("polarity", tuple(map(float, b)), init, px, 0.0))
    for i in ([0, 0, 0], [-20, -20, -20]):
        rows.append(("initial", truth, tuple(map(float, i)), px, 0.0))
    for p in (0.1, 0.5, 1.0):
        rows.append(("pixel", truth, init, setup.camera.pixel_errors(p), 0.0))
    for a in (0.0, 45.0, 90.0, 135.0, 180.0):
        rows.append(("install", truth, init, px, a))
    return [Case(i + 1, f"T1-{i + 1:02d}", *r) for i, r in enumerate(rows)]


def headline_case(setup: Setup) -> Case:
    return table1_cases(setup)[0]


def rms_last(err_norm: np.ndarray, last_fraction: float) -> np.ndarray:
    """RMS over the last fraction of the samples (axis -1)."""
    n = err_norm.shape[-1]
    k0 = int(np.floor(n * (1.0 - last_fraction)))
    return np.sqrt(np.mean(err_norm[..., k0:] ** 2, axis=-1))


def data_to_converge(theta_seg_arcsec: np.ndarray, seg_data: np.ndarray, tol: float) -> np.ndarray:
    """Per seed, the data amount after which tx, ty stay within ``tol`` of their final value.

    theta_seg_arcsec (S, L, 3); seg_data (L,) samples used after each segment.
    """
    dev = np.abs(theta_seg_arcsec[:, :, :2] - theta_seg_arcsec[:, -1:, :2]).max(-1)  # (S,L)
    bad = dev > tol
    # last segment index that is still outside, +1 -> first index from which all stay inside
    L = bad.shape[1]
    last_bad = np.where(bad.any(1), L - 1 - np.argmax(bad[:, ::-1], axis=1), -1)
    return seg_data[last_bad + 1]


def lateral_range_errors(x: np.ndarray, P: np.ndarray, dx_true: np.ndarray, C: np.ndarray):
    """Position error split along the line of sight (camera z axis of ``C`` = A_c^i) and
    across it, with the filter's 3-sigma of each: (lateral, |range|, 3 sig lateral,
    3 sig range), km, each (S,). The lateral sigma is ``sqrt(P_xx + P_yy)`` of the
    position covariance rotated into the camera frame (2 dof), the range sigma ``sqrt(P_zz)``."""
    e = (x[:, :3] - dx_true[:3]) @ C.T
    Pc = np.einsum("ij,sjk,lk->sil", C, P[:, :3, :3], C)
    return (np.hypot(e[:, 0], e[:, 1]), np.abs(e[:, 2]),
            3.0 * np.sqrt(Pc[:, 0, 0] + Pc[:, 1, 1]), 3.0 * np.sqrt(Pc[:, 2, 2]))


def lateral_range_t(xf: np.ndarray, dx_true: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position error of a filter run over time split across the line of sight (lateral,
    the camera x-y plane of ``C`` = A_c^i) and along it (range, |camera z|), km, (S, n+1) each."""
    e = np.einsum("kij,skj->ski", C, xf[:, :, :3] - dx_true[None, :, :3])
    return np.hypot(e[..., 0], e[..., 1]), np.abs(e[..., 2])


@dataclass(frozen=True)
class Consistency:
    """One filter run's consistency over time, (S, n+1) each: the position NEES (3 dof) and the
    NIS (3 dof; None where the run's innovations are not kept)."""

    nees_pos: np.ndarray
    nis: np.ndarray | None = None


@dataclass(frozen=True)
class ConsistencySeries:
    """:class:`Consistency` of the full-arc filters of a run: theta = 0 (``before``), the final
    estimate as exact (``after``), the Schmidt filter carrying its covariance (``consider``, NEES
    only) and the filter given the true theta (``true_theta``, NEES only: a diagnostic)."""

    before: Consistency
    after: Consistency
    consider: Consistency
    true_theta: Consistency


class LateralRange(NamedTuple):
    """A position error split across the line of sight (``lateral``) and along it (``range``), km."""

    lateral: np.ndarray
    range: np.ndarray


@dataclass(frozen=True)
class SplitSeries:
    """:class:`LateralRange` over time, (S, n+1) each, of the theta = 0 filter (``before``), the
    compensated one (``after``) and the filter given the true theta (``true_theta``)."""

    before: LateralRange
    after: LateralRange
    true_theta: LateralRange


def consistency(f, dx_true: np.ndarray) -> Consistency:
    """Position NEES (3 dof) and NIS (3 dof) of a filter run over time, (S, n+1) each:
    ``e^T P_rr^-1 e`` with ``e`` the filtered position error, and ``nu^T S^-1 nu`` with the
    innovation ``nu`` and its covariance ``S`` (index 0, the prior, has no NIS: NaN)."""
    e = f.xf[:, :, :3] - dx_true[None, :, :3]
    nees = np.einsum("ski,ski->sk", e, np.linalg.solve(f.Pf[:, :, :3, :3], e[..., None])[..., 0])
    nis = np.einsum("ski,skij,skj->sk", f.nu, f.Sinv, f.nu)
    nis[:, 0] = np.nan
    return Consistency(nees, nis)


def simulate_case(setup: Setup, geo: sc.Geometry, case: Case, seed_indices, init_mode: str | None = None,
                  truth_arcsec=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Measurement variances (n+1, 3) the estimators use (pixel noise and the Mars images'
    attitude knowledge), measurements z (S, n+1, 3) and the prior mean
    deviations dx0 (S, 6) of ``case`` for the given seeds (streams
    ``SeedSequence([base_seed, case_index, seed_index])``; ``truth_arcsec`` overrides the
    case's truth, ``init_mode`` the initial-error mode of the case and the setup)."""
    Rvar = geo.measurement_variance(case.sigma3_px)
    rngs = sc.seed_streams(setup.base_seed, case.case_index, seed_indices)
    truth = case.truth_arcsec if truth_arcsec is None else truth_arcsec
    z, e0 = sc.simulate(geo, geo.pixel_variance(case.sigma3_px), sc.rad(truth), rngs)
    return Rvar, z, sc.prior_mean_deviation(geo, e0, init_mode or case.init_mode or setup.initial_error.mode)


def start_state(start: str, a: int, f0, dx_true: np.ndarray, dx0: np.ndarray, P_X0: np.ndarray,
                win) -> tuple[np.ndarray, np.ndarray]:
    """State (S,6) and covariance at window start ``a`` for a variant's start rule.

    ``filter``: the theta = 0 EKF's own ``X_a, P_a`` (``literal``); ``prior``: the
    prior propagated to ``a`` without data; ``truth``: the true state with the
    filter's ``P_a`` (``reference-start`` diagnostic).
    """
    return start_states(start, [a], f0, dx_true, dx0, P_X0, win)[0]


def start_states(start: str, starts, f0, dx_true: np.ndarray, dx0: np.ndarray, P_X0: np.ndarray,
                 win) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`start_state` at every window start of ``starts`` (increasing); the prior is
    propagated once through them all."""
    S = dx0.shape[0]
    if start == "filter":
        return [(f0.xf[:, a], f0.Pf[:, a]) for a in starts]
    if start == "truth":
        return [(np.broadcast_to(dx_true[a], (S, 6)).copy(), f0.Pf[:, a]) for a in starts]
    if start == "prior":
        return list(zip(*predict_only(dx0, P_X0, win, at=starts)))
    raise ValueError(f"unknown start rule {start!r}")


@dataclass(frozen=True)
class CaseBounds:
    """The 1-sigma Cramer-Rao bounds of one case (arcsec, (3,) each; per segment (L, 3)): of the
    data its estimate used (``crlb_arcsec``: the last window when sliding, the cumulative data
    when growing; per segment ``crlb_seg_arcsec``), of all the segments' data
    (``crlb_total_arcsec``), and each with Q = 0 (``*_q0_*``: the truth has no process noise).
    Computed by :func:`opnav.approach.pipeline.case_bounds`."""

    crlb_seg_arcsec: np.ndarray
    crlb_seg_q0_arcsec: np.ndarray
    crlb_arcsec: np.ndarray
    crlb_q0_arcsec: np.ndarray
    crlb_total_arcsec: np.ndarray
    crlb_total_q0_arcsec: np.ndarray


@dataclass(frozen=True)
class SampledRun:
    """The headline case rerun with the initial error drawn from the prior (the only spread that
    may be set beside a Bayesian bound): the :class:`CaseRun` fields the tables read."""

    theta_final_arcsec: np.ndarray
    label: np.ndarray
    stalled: np.ndarray
    dist_to_ml_arcsec: np.ndarray
    consistency_t: ConsistencySeries
    nav_err_after_km: np.ndarray
    nav_err_before_km: np.ndarray
    nav_err_true_theta_km: np.ndarray

    @classmethod
    def of(cls, run: "CaseRun") -> "SampledRun":
        return cls(**{f: getattr(run, f) for f in cls.__dataclass_fields__})


#: the time series of a run (figures): kept for the headline case only (:meth:`CaseRun.without_series`)
SERIES_FIELDS = ("err_before_t_km", "err_after_t_km", "err_split_t_km", "consistency_t")


@dataclass(frozen=True)
class CaseRun:
    """The EM-EKF on one Table-1 case, variant and EM scheme over a batch of seeds
    (:func:`run_cases`; module docstring for the rules). Per-seed arrays have the seeds first
    (S, ...); arcsec, km, samples, s.

    Estimates: ``theta_final_arcsec`` (S, 3); after each segment ``theta_seg_arcsec`` (S, L, 3);
    every EM iterate ``theta_iter_arcsec`` (S, maps, 3) with its log-likelihood ``loglik_iter``
    and the data it used ``iter_data_used``; ``seg_data_used`` (L,) samples after each segment;
    ``maps_per_segment``. Position error at each segment's end (the filter inside the EM):
    ``seg_pos_err_km`` and its lateral / range parts with the filter's 3-sigma. The convergence
    label (SPEC A.3c): ``label``, ``stalled``, ``converged``, ``moved_arcsec`` (from the start),
    ``contraction_per_map``, the ML estimate of the last segment's data ``theta_ml_arcsec`` (and
    ``ml_converged``), the distance to it ``dist_to_ml_arcsec`` and in bounds of that data
    ``dist_to_ml_over_bound`` (``label_bound_arcsec`` (3,)); ``data_to_converge`` (NaN unless
    converged); ``tz_unobservable``. Navigation errors (RMS over the last
    ``nav_error.last_fraction``, km): theta = 0 (``before``), compensated (``after``), split
    across (``lat``) and along (``rng``) the line of sight, with the true theta and by the
    Schmidt filter (``consider``). Time series (headline case only, else None): the error norms
    ``err_before_t_km`` / ``err_after_t_km``, their split ``err_split_t_km`` and the filters'
    consistency ``consistency_t``; ``t_s`` the sample times. Added by
    :func:`opnav.approach.pipeline.run_group`: the job's case ``group``, the case's ``bounds``
    and, for the headline case, the ``sampled`` rerun.
    """

    variant: str
    mode: str
    method: str
    case: Case
    seed_indices: np.ndarray
    truth_arcsec: np.ndarray
    theta_final_arcsec: np.ndarray
    theta_seg_arcsec: np.ndarray
    theta_iter_arcsec: np.ndarray
    loglik_iter: np.ndarray
    iter_data_used: np.ndarray
    seg_data_used: np.ndarray
    maps_per_segment: int
    seg_pos_err_km: np.ndarray
    seg_lat_err_km: np.ndarray
    seg_rng_err_km: np.ndarray
    seg_lat_3sig_km: np.ndarray
    seg_rng_3sig_km: np.ndarray
    tz_unobservable: bool
    data_to_converge: np.ndarray
    label: np.ndarray
    stalled: np.ndarray
    converged: np.ndarray
    moved_arcsec: np.ndarray
    contraction_per_map: np.ndarray
    theta_ml_arcsec: np.ndarray
    ml_converged: np.ndarray
    dist_to_ml_arcsec: np.ndarray
    dist_to_ml_over_bound: np.ndarray
    label_bound_arcsec: np.ndarray
    nav_err_before_km: np.ndarray
    nav_err_after_km: np.ndarray
    nav_err_before_lat_km: np.ndarray
    nav_err_before_rng_km: np.ndarray
    nav_err_after_lat_km: np.ndarray
    nav_err_after_rng_km: np.ndarray
    nav_err_true_theta_lat_km: np.ndarray
    nav_err_true_theta_rng_km: np.ndarray
    nav_err_true_theta_km: np.ndarray
    nav_err_consider_km: np.ndarray
    t_s: np.ndarray
    err_before_t_km: np.ndarray | None = None
    err_after_t_km: np.ndarray | None = None
    err_split_t_km: SplitSeries | None = None
    consistency_t: ConsistencySeries | None = None
    group: str = ""
    bounds: CaseBounds | None = None
    sampled: SampledRun | None = field(default=None, repr=False)

    @property
    def case_id(self) -> str:
        return self.case.case_id

    def without_series(self) -> "CaseRun":
        """The run without its time series (:data:`SERIES_FIELDS`)."""
        return dataclasses.replace(self, **{f: None for f in SERIES_FIELDS})


def run_case(setup: Setup, variant: str, case: Case, seed_indices, geo: sc.Geometry | None = None,
             method: str | None = None, init_mode: str | None = None) -> CaseRun:
    """EM-EKF for one case and variant over the given seeds; arrays in arcsec / km."""
    return run_cases(setup, variant, [case], seed_indices, geo, method, init_mode)[0]


@dataclass
class CaseData:
    """What every EM scheme of :func:`run_cases` shares for one variant, case list and seed
    set: the stacked measurements ``z (S, n+1, 3)``, prior mean deviations ``dx0 (S, 6)``,
    variances ``Rvar`` ((n+1, 3), or (n+1, S, 3) when the cases' pixel noise differs),
    initial theta (S, 3) rad, the window of the whole arc, the theta = 0 filter over it
    (``f0``) with its position errors and consistency, and the start states of the
    windows, per start list (filled by :func:`run_cases`), and the filter run with the *true*
    theta (``f_true``, a diagnostic: the navigation-error floor that compensation could reach).
    Built by :func:`prepare_cases`."""

    geo: sc.Geometry
    z: np.ndarray
    dx0: np.ndarray
    Rvar: np.ndarray
    theta0: np.ndarray
    win: object
    f0: object
    err_before: np.ndarray
    cons_before: Consistency
    starts: dict
    f_true: object = None


def prepare_cases(setup: Setup, variant: str, case_list: list[Case], seed_indices,
                  geo: sc.Geometry | None = None, init_mode: str | None = None) -> CaseData:
    """Simulate every (case, seed) run of ``case_list`` (one row each of the stacked filter
    arrays; each keeps its own stream) and run the theta = 0 filter over the whole arc."""
    geo = geo or sc.build_geometry(setup, variant)
    init_mode = init_mode or setup.initial_error.mode
    seed_indices = list(seed_indices)
    ns = len(seed_indices)
    zs, dx0s, Rvs, inits, ys = [], [], [], [], []
    for case in case_list:
        Rvar, z, dx0 = simulate_case(setup, geo, case, seed_indices, case.init_mode or init_mode)
        ys.append(geo.simulate_stars(sc.rad(case.truth_arcsec), setup.base_seed, case.case_index, seed_indices))
        zs.append(z)
        dx0s.append(dx0)
        Rvs.append(np.broadcast_to(Rvar[:, None, :], (Rvar.shape[0], ns, 3)))
        inits.append(np.broadcast_to(sc.rad(case.init_arcsec), (ns, 3)))
    z = np.concatenate(zs)
    dx0 = np.concatenate(dx0s)
    Rvar = np.concatenate(Rvs, axis=1)
    if all(np.array_equal(c.sigma3_px, case_list[0].sigma3_px) for c in case_list):
        Rvar = Rvar[:, 0]  # shared by every run: the cheaper broadcast form
    theta = np.concatenate(inits).copy()
    win = geo.window(Rvar, None if geo.stars is None else np.concatenate(ys))
    S = z.shape[0]
    f0 = run_filter(z, np.zeros((S, 3)), dx0, geo.P0, win, predicted=False)
    err_before = np.linalg.norm(f0.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
    # diagnostic floor: the same filter with the true misalignment (truth used on purpose; no
    # estimate reads it)
    truth = np.concatenate([np.broadcast_to(sc.rad(c.truth_arcsec), (ns, 3)) for c in case_list])
    f_true = run_filter(z, truth, dx0, geo.P0, win, predicted=False)
    return CaseData(geo, z, dx0, Rvar, theta, win, f0, err_before, consistency(f0, geo.dx_true), {}, f_true)


def run_cases(setup: Setup, variant: str, case_list: list[Case], seed_indices,
              geo: sc.Geometry | None = None, method: str | None = None, init_mode: str | None = None,
              data: CaseData | None = None, seg_bounds: list | None = None) -> list[CaseRun]:
    """EM-EKF for several cases of one variant at once: every (case, seed) run is one row
    of the stacked filter arrays (runs are independent; each keeps its own stream).
    ``data``: the :func:`prepare_cases` of these arguments, shared by several EM schemes
    (``method``, ``setup.segments``). ``seg_bounds``: per case, the 1-sigma bound (arcsec) of
    the data the last segment's estimate used (3,), for the convergence label; computed
    (:func:`label_bounds`) when not given."""
    em_set = setup.em
    method = method or em_set.method
    seed_indices = list(seed_indices)
    ns = len(seed_indices)
    if data is None:
        data = prepare_cases(setup, variant, case_list, seed_indices, geo, init_mode)
    geo, z, dx0, theta, win, f0 = data.geo, data.z, data.dx0, data.theta0.copy(), data.win, data.f0
    err_before = data.err_before
    dx_true = geo.dx_true
    tz_tol = em_set.tz_tol

    windows = setup.segments.windows()
    M = setup.segments.M
    theta_init = theta.copy()
    seg_theta, it_theta, it_ll, it_data = [], [], [], []
    seg_lat, seg_rng, seg_lat3, seg_rng3 = [], [], [], []
    unobs = None
    for a, b, x0, P0, theta_seg_start, tr in em_segments(setup, variant, data, method, theta):
        theta = tr.theta[-1]
        unobs = tr.unobservable
        used = b - windows[0][0]
        seg_theta.append(theta)
        it_theta.extend(tr.theta)
        it_ll.extend(tr.loglik)
        it_data.extend([used] * len(tr.theta))
        x_end, P_end = tr.last_state
        lat, rng, lat3, rng3 = lateral_range_errors(x_end, P_end, dx_true[b], geo.C[b])
        seg_lat.append(lat)
        seg_rng.append(rng)
        seg_lat3.append(lat3)
        seg_rng3.append(rng3)

    # the convergence label (SPEC A.3c) from the last segment's data (one window when sliding,
    # the cumulative data when growing): its ML estimate, reached from the final estimate by
    # SQUAREM, the distance to it and the measured contraction factor per map toward it, over
    # the axes the data observe (tx, ty; tz too with star images, issue 54)
    nax = label_axes(geo)
    theta_ml, ml_done, _ = ml_estimate(z[:, a:b + 1], theta, x0, P0, win.slice(a, b), tz_tol,
                                       em_set.ml_max_maps, axes=nax)
    rate = contraction_per_map(theta_seg_start, theta, theta_ml, maps_per_segment(method, M), axes=nax)
    dist_ml = np.abs(sc.arcsec(theta - theta_ml))[:, :nax].max(1)
    moved = np.abs(sc.arcsec(theta - theta_init))[:, :nax].max(1)
    if seg_bounds is None:
        seg_bounds = label_bounds(setup, geo, case_list, variant)
    bnd = np.repeat(np.stack([np.asarray(b, float)[:nax] for b in seg_bounds]), ns, axis=0)  # (S, nax)
    dist_rel = (np.abs(sc.arcsec(theta - theta_ml))[:, :nax] / bnd).max(1)  # in bounds of the data used
    label = convergence_labels(dist_rel, rate, em_set.converge_frac_of_bound, em_set.stall_rate)

    f1 = run_filter(z, theta, dx0, geo.P0, win, predicted=False)
    # compensation that carries the estimate's uncertainty (issue 44): the Schmidt EKF with
    # P_theta = the squared bound of the data the estimate used plus the squared distance to that
    # data's ML estimate (an iterate that stopped short carries its own known error; no truth;
    # dx_true only for the NEES)
    P_th = np.zeros((theta.shape[0], 3, 3))
    P_th[:, [0, 1, 2], [0, 1, 2]] = (sc.rad(np.repeat(np.stack([np.asarray(b, float) for b in seg_bounds]), ns,
                                                      axis=0)) ** 2 + (theta - theta_ml) ** 2)
    fc = run_consider(z, theta, P_th, dx0, geo.P0, win, dx_true=dx_true, keep_cov=False)
    err_after = np.linalg.norm(f1.xf[:, :, :3] - dx_true[None, :, :3], axis=-1)
    err_consider = np.linalg.norm(fc.xf[:, :, :3] - dx_true[None, :, :3], axis=-1)
    frac = setup.nav_last_fraction
    seg_theta_as = sc.arcsec(np.stack(seg_theta, 1))
    seg_data = np.array([b - windows[0][0] for (_, b) in windows])
    conv = data_to_converge(seg_theta_as, seg_data, em_set.converge_tol_arcsec).astype(float)
    conv[label != CONVERGED] = np.nan  # not at the ML estimate of its data: no 'data to converge'
    theta_iter = sc.arcsec(np.stack(it_theta, 1))
    ll_iter = np.stack(it_ll, 1)
    seg_lat, seg_rng = np.stack(seg_lat, 1), np.stack(seg_rng, 1)
    seg_lat3, seg_rng3 = np.stack(seg_lat3, 1), np.stack(seg_rng3, 1)
    nb, na = rms_last(err_before, frac), rms_last(err_after, frac)
    # the same errors split across / along the line of sight, and the floor with the true theta
    split_t = SplitSeries(before=LateralRange(*lateral_range_t(f0.xf, dx_true, geo.C)),
                          after=LateralRange(*lateral_range_t(f1.xf, dx_true, geo.C)),
                          true_theta=LateralRange(*lateral_range_t(data.f_true.xf, dx_true, geo.C)))
    err_true = np.linalg.norm(data.f_true.xf[:, :, :3] - dx_true[None, :, :3], axis=-1)
    nav_true = rms_last(err_true, frac)
    nav_consider = rms_last(err_consider, frac)
    rms_b, rms_a, rms_t = (LateralRange(rms_last(v.lateral, frac), rms_last(v.range, frac))
                           for v in (split_t.before, split_t.after, split_t.true_theta))
    cons = ConsistencySeries(before=data.cons_before, after=consistency(f1, dx_true), consider=Consistency(fc.nees_pos),
                             true_theta=Consistency(consistency(data.f_true, dx_true).nees_pos))

    out = []
    for i, case in enumerate(case_list):
        sl = slice(i * ns, (i + 1) * ns)
        out.append(CaseRun(
            variant=variant,
            mode=setup.segments.mode,
            method=method,
            case=case,
            seed_indices=np.asarray(seed_indices),
            truth_arcsec=np.asarray(case.truth_arcsec, float),
            theta_final_arcsec=sc.arcsec(theta[sl]),
            theta_seg_arcsec=seg_theta_as[sl],
            theta_iter_arcsec=theta_iter[sl],
            loglik_iter=ll_iter[sl],
            iter_data_used=np.asarray(it_data),
            seg_data_used=seg_data,
            maps_per_segment=maps_per_segment(method, M),
            seg_pos_err_km=np.hypot(seg_lat[sl], seg_rng[sl]),
            seg_lat_err_km=seg_lat[sl], seg_rng_err_km=seg_rng[sl],
            seg_lat_3sig_km=seg_lat3[sl], seg_rng_3sig_km=seg_rng3[sl],
            tz_unobservable=bool(np.all(unobs[sl, 0])) if unobs is not None else False,
            data_to_converge=conv[sl],
            label=label[sl],
            stalled=label[sl] == STALLED,
            converged=label[sl] == CONVERGED,
            moved_arcsec=moved[sl],
            contraction_per_map=rate[sl],
            theta_ml_arcsec=sc.arcsec(theta_ml[sl]),
            ml_converged=ml_done[sl],
            dist_to_ml_arcsec=dist_ml[sl],
            dist_to_ml_over_bound=dist_rel[sl],
            label_bound_arcsec=np.asarray(seg_bounds[i], float),
            nav_err_before_km=nb[sl],
            nav_err_after_km=na[sl],
            nav_err_before_lat_km=rms_b.lateral[sl], nav_err_before_rng_km=rms_b.range[sl],
            nav_err_after_lat_km=rms_a.lateral[sl], nav_err_after_rng_km=rms_a.range[sl],
            nav_err_true_theta_lat_km=rms_t.lateral[sl], nav_err_true_theta_rng_km=rms_t.range[sl],
            nav_err_true_theta_km=nav_true[sl], nav_err_consider_km=nav_consider[sl],
            t_s=geo.t,
            err_before_t_km=err_before[sl],
            err_after_t_km=err_after[sl],
            err_split_t_km=SplitSeries(*(_rows_lr(v, sl) for v in (split_t.before, split_t.after, split_t.true_theta))),
            consistency_t=ConsistencySeries(*(_rows_cons(c, sl) for c in (cons.before, cons.after, cons.consider,
                                                                          cons.true_theta))),
        ))
    return out


def _rows_lr(v: LateralRange, sl: slice) -> LateralRange:
    return LateralRange(v.lateral[sl], v.range[sl])


def _rows_cons(c: Consistency, sl: slice) -> Consistency:
    return Consistency(c.nees_pos[sl], None if c.nis is None else c.nis[sl])


def em_segments(setup: Setup, variant: str, data: CaseData, method: str, theta: np.ndarray, windows=None):
    """The segment-wise EM-EKF (paper A sec. 2.3) over ``data``: for each window (a, b) of
    ``setup.segments`` (sliding or growing; or of ``windows`` when given), M maps of ``method``
    from the variant's start state at a, seeded with the previous window's estimate (``theta``
    (S, 3) rad for the first). Yields ``(a, b, x0, P0, theta_start, trace)`` per window
    (:func:`opnav.approach.em.em_window`'s trace; its last iterate seeds the next window). The
    variant's start states are computed once per window list and kept in ``data.starts``."""
    windows = setup.segments.windows() if windows is None else list(windows)
    key = (sc.START_OF[variant], tuple(a for (a, _) in windows))
    if key not in data.starts:
        data.starts[key] = start_states(key[0], list(key[1]), data.f0, data.geo.dx_true, data.dx0, data.geo.P0,
                                        data.win)
    for (a, b), (x0, P0) in zip(windows, data.starts[key]):
        tr = em_window(data.z[:, a:b + 1], theta, x0, P0, data.win.slice(a, b), setup.segments.M, method,
                       setup.em.tz_tol)
        yield a, b, x0, P0, theta, tr
        theta = tr.theta[-1]


def label_axes(geo: sc.Geometry) -> int:
    """The components of theta a run's convergence label reads: tx and ty (2), and tz as well (3)
    where the data observe it (star images, which see the roll about the boresight)."""
    return 3 if geo.stars is not None else 2


def label_bounds(setup: Setup, geo: sc.Geometry, case_list: list[Case], variant: str) -> list[np.ndarray]:
    """Per case, the 1-sigma bound (3,), arcsec, of the data its last segment's estimate used
    (:func:`opnav.approach.pipeline.segment_bounds`), evaluated at what the estimator knows: the
    case's configured start theta and the reference trajectory (``Geometry.along_reference``),
    not the truth: the convergence label's scale and the consider filter's covariance (the bound
    changes with theta and the trajectory by a relative O(theta) and O(|dr| / rho), about 1e-4
    here)."""
    from .bounds import segment_bounds_many

    items = [(geo.measurement_variance(c.sigma3_px), c.init_arcsec, False) for c in case_list]
    return [b[-1] for b in segment_bounds_many(setup, geo.along_reference(), items, variant)]


@dataclass(frozen=True)
class MapsToML:
    """One EM scheme of :func:`convergence_study`, per seed: the maps (filter + smoother + M-step)
    to reach the ML estimate (``maps_to_converge``; ``max_maps + 1`` when it does not within
    ``max_maps``), the same extrapolated at the measured rate for a run that stalled
    (``maps_extrapolated``), the distance to the ML estimate after each map ``dist_arcsec``
    (S, maps), the iterates ``theta_hist_arcsec`` (S, maps, 3), their ``loglik`` and the
    contraction ``rate_per_map`` over the last iterations."""

    maps_to_converge: np.ndarray
    maps_extrapolated: np.ndarray
    dist_arcsec: np.ndarray
    theta_hist_arcsec: np.ndarray
    loglik: np.ndarray
    rate_per_map: np.ndarray


@dataclass(frozen=True)
class ConvergenceStudy:
    """Plain EM and SQUAREM to the ML estimate of one window (:func:`convergence_study`): the
    reference ``theta_star_arcsec`` (S, 3), the case's truth, the window's samples and the map
    budget, and each scheme's :class:`MapsToML`."""

    variant: str
    theta_star_arcsec: np.ndarray
    truth_arcsec: np.ndarray
    data_samples: int
    max_maps: int
    plain: MapsToML
    squarem: MapsToML


def convergence_study(setup: Setup, variant: str, case: Case, seed_indices, data_samples: int,
                      max_maps: int, tol_arcsec: float, geo: sc.Geometry | None = None,
                      init_mode: str | None = None) -> ConvergenceStudy:
    """Iterations of plain EM and SQUAREM to reach the maximum-likelihood estimate.

    One window of ``data_samples`` samples from ``N0`` (start rule of the
    variant). The reference ``theta*`` is SQUAREM run until its step is below
    1e-4 arcsec (or ``max_maps`` maps). "Maps to converge" counts filter +
    smoother + M-step evaluations until |theta - theta*| <= ``tol_arcsec`` in
    both tx and ty and stays there; a run that does not get there within
    ``max_maps`` is reported as ``max_maps + 1`` (stalled) together with the
    contraction rate per map measured over its last iterations.
    """
    N0 = setup.segments.N0
    geo = geo or sc.build_geometry(setup, variant, n=N0 + data_samples)
    init_mode = init_mode or setup.initial_error.mode
    Rvar, z, dx0 = simulate_case(setup, geo, case, seed_indices, init_mode)
    win = geo.window(Rvar, geo.simulate_stars(sc.rad(case.truth_arcsec), setup.base_seed, case.case_index,
                                              seed_indices))
    S = z.shape[0]
    f0 = run_filter(z[:, :N0 + 1], np.zeros((S, 3)), dx0, geo.P0, win.slice(0, N0), predicted=False)
    x0, P0 = start_state(sc.START_OF[variant], N0, f0, geo.dx_true, dx0, geo.P0, win)
    a, b = N0, N0 + data_samples
    wz, ww = z[:, a:b + 1], win.slice(a, b)
    tz_tol = setup.em.tz_tol
    theta0 = np.broadcast_to(sc.rad(case.init_arcsec), (S, 3)).copy()

    # SQUAREM cycles from theta0 until the step is below 1e-4 arcsec: its end point is the
    # reference theta* (the ML estimate), its history the SQUAREM convergence record
    th, _, sq = ml_estimate(wz, theta0, x0, P0, ww, tz_tol, max(max_maps, 30), per_seed=False)
    sq_theta, sq_ll = sq.theta, sq.loglik
    ref_as = sc.arcsec(th)
    tr = em_window(wz, theta0, x0, P0, ww, max_maps, "plain", tz_tol)
    return ConvergenceStudy(variant=variant, theta_star_arcsec=ref_as, truth_arcsec=np.asarray(case.truth_arcsec),
                            data_samples=data_samples, max_maps=max_maps,
                            plain=_maps_to_ml(tr.theta, tr.loglik, ref_as, tol_arcsec, max_maps),
                            squarem=_maps_to_ml(sq_theta, sq_ll, ref_as, tol_arcsec, max_maps))


def _maps_to_ml(th_list, ll_list, ref_as: np.ndarray, tol_arcsec: float, max_maps: int) -> MapsToML:
    """:class:`MapsToML` of one scheme's iterates (rad) against the reference ``ref_as`` (arcsec)."""
    hist = sc.arcsec(np.stack(th_list, 1))  # (S, maps, 3)
    S = hist.shape[0]
    dist = np.abs(hist[:, :, :2] - ref_as[:, None, :2]).max(-1)
    ok = dist <= tol_arcsec
    maps_needed = np.full(S, max(max_maps, hist.shape[1]) + 1)
    for i in range(S):
        bad = np.where(~ok[i])[0]
        last_bad = bad[-1] if bad.size else -1
        if last_bad + 1 < ok.shape[1]:
            maps_needed[i] = last_bad + 2  # maps are 1-based
    d = np.maximum(dist[:, -11:], 1e-300)
    rate = np.exp(np.mean(np.diff(np.log(d), axis=1), axis=1))
    # stalled runs: maps still needed at the measured linear rate (extrapolation, labelled so)
    with np.errstate(divide="ignore", invalid="ignore"):
        extra = np.where(rate < 1.0, np.log(tol_arcsec / d[:, -1]) / np.log(rate), np.inf)
    extrap = np.where(maps_needed > hist.shape[1], dist.shape[1] + np.maximum(extra, 0.0),
                      maps_needed.astype(float))
    return MapsToML(maps_to_converge=maps_needed, maps_extrapolated=extrap, dist_arcsec=dist,
                    theta_hist_arcsec=hist, loglik=np.stack(ll_list, 1), rate_per_map=rate)
