"""The registry of paper A's misalignment estimators: a user's own (``approach.custom_estimators``)
run on the Table-1 cases beside the EM-EKF and scored against the truth and the bound of the data
it used (issue 58).

Description
-----------
``approach.custom_estimators`` maps an estimator name to its function::

    approach:
      custom_estimators:
        batch_ls:
          path: examples/batch_ls.py:estimate     # or an importable module: mypkg.est:estimate
          label: batch least squares              # legend and table name (default: the name)
          color: "#AA3377"                        # a matplotlib colour (default: from the name)

The function takes ONE argument, a :class:`Problem` (one Monte-Carlo seed's data window and the
filter's set-up), and returns the misalignment estimate theta = (tx, ty, tz) in rad, a (3,)
array, or a pair ``(theta, P_theta)`` with its 3 x 3 covariance (rad^2).

Runs (:func:`run_case`): for every Table-1 case (``cases.table1_cases``) of every variant of
``approach.table1_variants`` and every seed (the EM-EKF's measurement streams), the estimator is
called on the growing windows of data after ``N0`` ending at every segment end, ``(l + 1) N``
samples (l = 0 .. L-1; ``segments``), each started from the variant's state at ``N0`` (the
EM-EKF's first window's start: ``literal`` the theta = 0 filter's ``X_N0, P_N0``, ``prior`` and
``roll`` the prior propagated without data; ``cases.start_state``) with theta started at the
case's initial value. Each estimate is scored (:mod:`opnav.approach.estimator_summary`) against

* the truth (error, mean and sd over seeds, arcsec);
* the Cramér-Rao bound of the data it used (``bounds.bound_curve`` at the truth: the growing
  data after N0 from the variant's start; for ``literal``, whose start carries every sample from
  t0, the cumulative data from t0), and its returned sigma where it gives one;
* Table 1's written rules: data needed to converge (``cases.data_to_converge``) and the
  navigation error after compensation (the EKF over the whole arc with the final estimate,
  ``cases.rms_last``); run time per call (s, wall, this machine).

The ``stars`` variant is not run: a custom estimator receives no star images. Checked before any
work (:func:`problems`), one line naming the estimator: the path imports, the function takes one
argument, the name is no built-in estimator's, and a probe call on a small window of the headline
case returns a finite (3,) estimate (and a finite symmetric 3 x 3 covariance, if any). A failure
during a run stops the job naming the estimator, variant, case, seed and window.

Units: km, km/s, s, rad in a :class:`Problem` and the returned estimate; arcsec in results.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Mapping, NamedTuple

import numpy as np

from opnav.core import registry
from opnav.core.registry import CustomSpec, MethodError

__all__ = ["Problem", "Estimator", "BUILTIN", "specs", "load", "problems", "probe", "run_case", "EstimatorRun", "CaseRun",
           "run_variant", "call", "labels", "colors", "source_files"]

#: the built-in estimators' names (EM schemes, their growing-window forms, the A-X2 alternatives,
#: the peer): a custom estimator may not take one
BUILTIN = ("em", "em_plain", "em_squarem", "plain", "squarem", "em_growing_plain", "em_growing_squarem",
           "growing-plain", "growing-squarem", "augmented", "batch_ml", "basilisk", "crlb", "truth")


class Problem(NamedTuple):
    """What a misalignment estimator receives: one seed's window of data and the filter's set-up
    (paper A eq. 3-6). The measurement of sample k = 1..n is the spacecraft-to-Mars vector in the
    camera frame, ``z_k = A_m(theta) (u_ref_k - C_k dr_k) + v_k``, ``A_m(theta) = I - [theta x]``
    (eq. 5), ``v_k ~ N(0, diag(Rvar_k))``; the state is the deviation ``dX = [dr (km), dv (km/s)]``
    from the reference trajectory, ``dX_k = Phi_k dX_{k-1} + w_k``, ``w_k ~ N(0, Q)``. Sample 0
    is the window's start (no measurement). Read-only: do not modify the arrays."""

    z: np.ndarray            #: (n+1, 3) measurements, km (row 0 unused)
    t_s: np.ndarray          #: (n+1,) sample times, s
    Phi: np.ndarray          #: (n+1, 6, 6) one-step transitions, Phi[k] maps sample k-1 to k (Phi[0] unused)
    C: np.ndarray            #: (n+1, 3, 3) inertial -> nominal camera frame (A_c^i) at each sample
    u_ref: np.ndarray        #: (n+1, 3) C_k (X_Mars,k - r_ref,k): the measurement at the reference without misalignment, km
    Rvar: np.ndarray         #: (n+1, 3) measurement noise variances, km^2
    Q: np.ndarray            #: (6, 6) process noise per step, km^2 and (km/s)^2
    x0: np.ndarray           #: (6,) the start state's deviation from the reference (km, km/s)
    P0: np.ndarray           #: (6, 6) its covariance
    theta0: np.ndarray       #: (3,) the initial misalignment value (tx, ty, tz), rad
    theta_prior_sigma_rad: float  #: a diffuse prior sigma on each theta component (approach.crlb), rad


@dataclass(frozen=True)
class Estimator:
    name: str
    label: str
    color: str
    path: str
    fn: object


#: the config key of the registry
SECTION = "approach.custom_estimators"


def specs(custom: Mapping | None) -> dict[str, CustomSpec]:
    """``approach.custom_estimators`` as entries (name -> ``{path, label, color}`` or name -> path)."""
    return registry.specs(custom, SECTION)


def _key(name: str) -> str:
    return f"{SECTION}.{name}"


def load(spec: CustomSpec) -> Estimator:
    """Import and check one entry (:class:`MethodError`, one line naming the estimator)."""
    fn = registry.load_function(spec, BUILTIN, "opnav.approach.estimators.Problem", "estimator")
    return Estimator(spec.name, spec.label or spec.name, spec.color, spec.path, fn)


def call(est: Estimator, prob: Problem, where: str = "") -> tuple[np.ndarray, np.ndarray | None]:
    """The estimator on one problem: ``(theta (3,) rad, P_theta (3, 3) or None)``; a
    :class:`MethodError` naming it (and ``where``) for an exception or a malformed / non-finite
    result."""
    key = _key(est.name)
    at = f" {where}" if where else ""
    try:
        out = est.fn(prob)
    except Exception as exc:
        raise MethodError(f"{key}: {est.path} raised {registry.what(exc)}{at}") from exc
    P = None
    if isinstance(out, tuple):
        if len(out) != 2:
            raise MethodError(f"{key}: {est.path} returned a tuple of {len(out)}, expected theta or (theta, P_theta){at}")
        out, P = out
    try:
        th = np.asarray(out, float)
    except (TypeError, ValueError):
        th = np.zeros(0)
    if th.shape != (3,):
        raise MethodError(f"{key}: {est.path} returned {type(out).__name__} of shape {np.shape(out)}, "
                          f"expected theta (tx, ty, tz) in rad, shape (3,){at}")
    if not np.isfinite(th).all():
        raise MethodError(f"{key}: {est.path} returned a non-finite estimate {th.tolist()}{at}")
    if P is not None:
        try:
            P = np.asarray(P, float)
        except (TypeError, ValueError):
            P = np.zeros(0)
        ok = P.shape == (3, 3) and np.isfinite(P).all() and np.all(np.diag(P) >= 0)
        # symmetric to round-off on the scale of each entry (sqrt(P_ii P_jj)), not of the entry itself
        if not ok or np.any(np.abs(P - P.T) > 1e-8 * np.sqrt(np.outer(np.diag(P), np.diag(P))) + 1e-300):
            raise MethodError(f"{key}: {est.path} returned a covariance that is not a finite symmetric 3 x 3 "
                              f"matrix with a non-negative diagonal{at}")
    return th, P


# ---------------------------------------------------------------- problems and runs

def _prepare(setup, variant: str, case, seeds, geo):
    """The case's data for ``seeds`` and the variant's start at N0: (Rvar, z, dx0, x0, P0)."""
    from . import cases
    from . import scenario as sc
    from .ekf import run_filter

    N0 = setup.segments.N0
    Rvar, z, dx0 = cases.simulate_case(setup, geo, case, seeds, setup.initial_error.mode)
    win = geo.window(Rvar)
    S = z.shape[0]
    start = sc.START_OF[variant]
    f0 = None if start == "prior" else run_filter(z[:, :N0 + 1], np.zeros((S, 3)), dx0, geo.P0, win.slice(0, N0),
                                                  predicted=False)
    x0, P0 = cases.start_state(start, N0, f0, geo.dx_true, dx0, geo.P0, win)
    return Rvar, z, dx0, np.asarray(x0, float), np.broadcast_to(P0, (S, 6, 6)), win


def problem(setup, geo, win, z_s, x0_s, P0_s, theta0_rad, n_data: int) -> Problem:
    """The :class:`Problem` of one seed: the window of ``n_data`` samples after N0."""
    N0 = setup.segments.N0
    w = win.slice(N0, N0 + n_data)
    c = lambda a: np.ascontiguousarray(a, float)   # noqa: E731
    return Problem(c(z_s[N0:N0 + n_data + 1]), c(geo.t[N0:N0 + n_data + 1]), c(w.Phi), c(w.C), c(w.u_ref),
                   c(w.Rvar if w.Rvar.ndim == 2 else w.Rvar[:, 0]), c(w.Q), c(x0_s), c(P0_s), c(theta0_rad),
                   float(setup.crlb_prior_sigma_rad))


@dataclass(frozen=True, eq=False)
class EstimatorRun:
    """One estimator on one case (:func:`run_case`): its label and path, the estimates after each
    growing window (seeds x L x 3, arcsec) and the final one, its sigmas where it returns a
    covariance (NaN where not), the data to converge per seed (samples), the navigation error after
    compensation (km, per seed) and the run time per call (s)."""

    label: str
    path: str
    theta_seg_arcsec: np.ndarray
    theta_final_arcsec: np.ndarray
    sigma_seg_arcsec: np.ndarray
    sigma_final_arcsec: np.ndarray
    data_to_converge: np.ndarray
    nav_err_after_km: np.ndarray
    runtime_s_per_call: float


@dataclass(frozen=True, eq=False)
class CaseRun:
    """Every estimator on one Table-1 case and variant (:func:`run_case`): the case, its seeds, the
    truth and start (arcsec), the data each window used (samples after N0) and its bound (L x 3,
    arcsec), the navigation error before compensation (km, per seed) and per estimator its
    :class:`EstimatorRun`."""

    variant: str
    case: object
    case_id: str
    seed_indices: np.ndarray
    truth_arcsec: np.ndarray
    init_arcsec: np.ndarray
    seg_data_used: np.ndarray
    bound_seg_arcsec: np.ndarray
    nav_err_before_km: np.ndarray
    estimators: dict[str, EstimatorRun]


def run_case(setup, variant: str, case, seeds, geo, estimators) -> CaseRun:
    """Every estimator of ``estimators`` on one case and variant (module docstring): per
    estimator the estimates after each growing window (arcsec), their sigmas where returned,
    the data to converge, the navigation error after compensation and the run time per call;
    the bound of each window's data (arcsec) and the truth."""
    from . import bounds, cases
    from . import scenario as sc
    from .ekf import run_filter

    seeds = list(seeds)
    seg = setup.segments
    N0, N, L = seg.N0, seg.N, seg.L
    seg_data = np.array([(l + 1) * N for l in range(L)])
    Rvar, z, dx0, x0, P0, win = _prepare(setup, variant, case, seeds, geo)
    th0 = sc.rad(case.init_arcsec)
    bound = bounds.bound_curve(setup, geo, Rvar, case.truth_arcsec, variant)[seg_data]     # (L, 3) arcsec
    runs = {}
    frac, tol = setup.nav_last_fraction, setup.em.converge_tol_arcsec
    f_before = run_filter(z, np.zeros((len(seeds), 3)), dx0, geo.P0, win, predicted=False)
    err_b = np.linalg.norm(f_before.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
    nav_before = cases.rms_last(err_b, frac)
    for est in estimators:
        th = np.empty((len(seeds), L, 3))
        sig = np.full((len(seeds), L, 3), np.nan)
        t = time.perf_counter()
        for i, s in enumerate(seeds):
            for l, d in enumerate(seg_data):
                prob = problem(setup, geo, win, z[i], x0[i], P0[i], th0, int(d))
                where = (f"on variant {variant}, case {case.case_id}, seed {s}, window of {int(d)} samples "
                         f"after N0 = {N0}")
                th[i, l], P = call(est, prob, where)
                if P is not None:
                    sig[i, l] = np.sqrt(np.diag(P))
        runtime = (time.perf_counter() - t) / (len(seeds) * L)
        f = run_filter(z, th[:, -1], dx0, geo.P0, win, predicted=False)
        err = np.linalg.norm(f.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
        th_as = sc.arcsec(th)
        runs[est.name] = EstimatorRun(
            label=est.label, path=est.path, theta_seg_arcsec=th_as, theta_final_arcsec=th_as[:, -1],
            sigma_seg_arcsec=sc.arcsec(sig), sigma_final_arcsec=sc.arcsec(sig[:, -1]),
            data_to_converge=cases.data_to_converge(th_as, seg_data, tol),
            nav_err_after_km=cases.rms_last(err, frac), runtime_s_per_call=runtime)
    return CaseRun(variant=variant, case=case, case_id=case.case_id, seed_indices=np.asarray(seeds),
                   truth_arcsec=np.asarray(case.truth_arcsec, float), init_arcsec=np.asarray(case.init_arcsec, float),
                   seg_data_used=seg_data, bound_seg_arcsec=bound, nav_err_before_km=nav_before, estimators=runs)


def run_variant(approach_cfg: Mapping, variant: str, log=None) -> list[CaseRun]:
    """Every registered estimator on every Table-1 case of ``variant`` (one job)."""
    from . import cases
    from . import scenario as sc
    from .setup import Setup

    setup = Setup.from_config(approach_cfg)
    ests = [load(s) for s in specs(approach_cfg.get("custom_estimators")).values()]
    geo = sc.build_geometry(setup, variant)
    seeds = range(setup.n_seeds)
    res = []
    for case in cases.table1_cases(setup):
        r = run_case(setup, variant, case, seeds, geo, ests)
        res.append(r)
        if log:
            log.info("%s %s: %s", variant, case.case_id,
                     {n: np.round(e.theta_final_arcsec.mean(0), 3).tolist() for n, e in r.estimators.items()})
    return res


# ---------------------------------------------------------------- preflight

def probe_problem(approach_cfg: Mapping, n_data: int | None = None) -> Problem:
    """A small problem of the headline case (first seed, ``prior`` start, the first segment's
    data) for the probe call."""
    from . import cases
    from . import scenario as sc
    from .setup import Setup

    setup = Setup.from_config(approach_cfg)
    seg = setup.segments
    n_data = int(n_data or seg.N)
    n = seg.N0 + n_data
    geo = sc.build_geometry(setup, "prior", n=n)
    case = cases.headline_case(setup)
    Rvar, z, dx0, x0, P0, win = _prepare(setup, "prior", case, [0], geo)
    return problem(setup, geo, win, z[0], x0[0], P0[0], sc.rad(case.init_arcsec), n_data)


def probe(est: Estimator, approach_cfg: Mapping, prob: Problem | None = None) -> None:
    call(est, prob if prob is not None else probe_problem(approach_cfg), "on the probe call (headline case, "
         "seed 0, the first segment's data)")


def problems(approach_cfg: Mapping) -> list[str]:
    """One line per registered estimator that cannot be used; [] if none is registered."""
    out, prob = [], None
    for spec in specs(approach_cfg.get("custom_estimators")).values():
        key = _key(spec.name)
        try:
            est = load(spec)
            if prob is None:
                prob = probe_problem(approach_cfg)
            probe(est, approach_cfg, prob)
        except MethodError as exc:
            out.append(f"invalid config key '{key}': {registry.strip_key(str(exc), key)}")
    return out


def labels(custom: Mapping | None) -> dict[str, str]:
    return {n: s.label or n for n, s in specs(custom).items()}


def colors(custom: Mapping | None) -> dict[str, str]:
    return {n: s.color for n, s in specs(custom).items() if s.color}


def source_files(custom: Mapping | None) -> list[str]:
    """The files the registered estimators live in (``core.registry.source_files``)."""
    return registry.source_files(specs(custom))
