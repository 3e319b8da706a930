"""Paper B's planning objectives as the papers define them, in numpy: the reference path.

The tests compare every compiled kernel of the package with these definitions, and the
planner's ``paper`` evaluation path (``PlannerConfig.eval_path``, timed beside the compiled
one) scores its candidates with them (:func:`paper_objective`) through the same search.

Depth error (eq. 19-26)
-----------------------
The lander at C observes landmark p twice, ``t_s`` apart; under assumption 2 (straight,
uniformly decelerated motion) the velocity line from C meets the ground at D. With ``beta``
the angle at C between the velocity and the line of sight C->p and ``alpha`` the interior
angle of the triangle C, D, p at D, the depth is ``d = |CD| sin(alpha) / sin(alpha + beta)``
(law of sines) and::

    |r^(k+s)| = sqrt(b^2 + d^2 - 2 b d cos(beta))          (eq. 25)
    sin(theta) = b sin(beta) / |r^(k+s)|                    (eq. 24)
    dr = 2 r_e / sin(theta)                                 (eq. 23)

with b (eq. 19) and r_e (eq. 21-22) from ``depth.baseline`` / ``depth.error_radius``.
In the plane holding the velocity beta is signed (``geometry``'s docstring). ``beta`` must lie
in ``(0, pi - alpha)``; outside it and at ``beta = 0`` (no parallax) the depth error is
``+inf`` by definition, never NaN. A non-positive ``|CD|`` or baseline raises
``layout.DegenerateGeometry``; a negative error radius, a non-finite beta or alpha outside
(0, pi) raise ``ValueError``.

The H baselines
---------------
H of eq. 14-18 from the CasADi derivation (``casadi_model.jacobian_casadi_batch``, which
stays with the other CasADi functions), then LAPACK: svd and cond from its four structural
singular values, gdop = 1 / trace[(H^T H)^+] with ``pinv(H, rcond=PINV_RCOND)``
(``opnav.landing.metrics`` says why four).

The information baselines (B-X1, beyond paper B)
------------------------------------------------
Every information baseline scores what the Fig. 3 strategy would actually do with
the candidate ``p_c`` (m, {L}) from the current estimate (r, v, R_LtoB, P), steps
1-3 below (:func:`planned_rows`), and differs only in what it reads of the planned
information (:func:`planned_metric`; step 4 is ``logdet_nav``'s).

1. **its own initialisation**: the prior covariance ``P0`` (12 x 12) is the
   filter's ``ekf.init_landmark`` for the candidate's (noise-free) bearing: the
   ground cut of the line of sight, its Jacobian cross-covariance with the
   navigation states, the depth guess ``(depth_sigma_frac d)^2`` along the line
   of sight and the bearing noise across it;
2. **the filter's noise model**: bearing noise ``sigma_f = meas_noise_scale *
   sigma_px / f`` rad per component (``Scenario.camera.sigma_b`` times the
   filter's scale), not the true one;
3. **the planned observations**: the landmark is seen ``n_obs`` times
   (``obs_per_landmark``), one image every ``dt`` s, from the poses the
   estimate predicts (``r + v t + a t^2 / 2``, attitude held); its first
   bearing initialises it (already in ``P0``), the other ``n_obs - 1`` are
   updates, and the site is seen at each of the ``n_obs`` images. Each update's
   tangent-plane whitened bearing rows ``G`` (``measurement.tangent_jacobian``,
   2 x 12 per bearing: a unit bearing has two degrees of freedom) are taken at
   its predicted pose and mapped to the planning instant by the filter's
   transition ``Phi`` (``ekf.transition_matrix``, eq. 6-10), projected on the
   complement of the unobservable yaw direction (``ekf.nullspace``) as the
   OC-EKF's update does, and the posterior covariance follows by Woodbury.
   Motion matters: seen again from the same point, a landmark initialised from
   its own bearing adds nothing to the navigation states (every candidate would
   score the same; tested), as with the paper's depth error, the information
   comes from the parallax of the predicted motion. Process noise over the
   ``(n_obs - 1) dt`` horizon is neglected;
4. **marginalised on the navigation states**: the score is
   ``-log det Sigma_post[:9, :9]`` (position m, velocity m/s, attitude rad;
   nats, larger is better): the landmark's own uncertainty does not count, only
   what it does for the lander.

Candidates behind the camera or whose line of sight
misses the ground score ``-inf``.

What the whitened baselines reward (B-X1)
-----------------------------------------
``svd_w``, ``gdop_w`` and ``cond_w`` are computed as defined (tested equal to the
compiled kernel, the kept count ``min(m, 11)`` is the rows' structural rank) and still
pick landmarks that are useless for navigation; this is what the metrics do, not a
bug. The rows ``A`` of a plan are the site's ``2 n_obs`` rows plus the candidate's
``2 (n_obs - 1)``. Deleting rows interlaces singular values (sigma_i(A P0^1/2) >=
sigma_i(A_site P0^1/2) >= sigma_(i+k)(A P0^1/2), k rows deleted), so the smallest kept
singular value is bounded by one of the site's own (:func:`whitened_site_bound`; at the
configured three observations, the site's smallest): the weakest direction of
re-observing the site over the short planning horizon, whose whitened gain depends on
the navigation prior only (the site's rows have no landmark columns; with OC the yaw
projection moves it by round-off).
``svd_w`` is therefore the candidate-independent ceiling minus however much the
candidate's rows pull that direction down; ``gdop_w`` (``1 / sum sigma_i^-2``) is
dominated by the same two smallest values. Neither can reward what a candidate adds:
its parallax on its own depth shows up in the *largest* singular value (the landmark's
depth prior ``(depth_sigma_frac d)^2`` dwarfs the rest, so its gain whitens large),
which ``svd_w`` and ``gdop_w`` ignore and ``cond_w`` (``sigma_min / sigma_max``)
divides by: cond_w prefers candidates that give the least depth parallax. Over the
plateau the best scores are set by candidates near the estimated velocity (the focus
of expansion, ``beta`` ~ 0, no parallax), so their picks cluster there, their depth is
not resolved, and the filter's position drifts. The descent records the optimum's
angle to the velocity (``plan_beta``); ``ranking.ranking_table`` reports its median
per method (``median_abs_beta_deg``), the number the manuscript quotes.
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np

from opnav.landing import ekf
from opnav.landing.measurement import tangent_jacobian
from opnav.landing.planning.depth import baseline, error_radius
from opnav.landing.planning.geometry import PlaneGeometry, ground_point, plane_geometry
from opnav.landing.planning.hmetrics import sv_metric
from opnav.landing.planning.layout import H_RANK, KINDS, OK, PLANNED_RANK, ZERO_BASELINE, DegenerateGeometry
from opnav.landing.planning.screens import valid_points

#: pseudo-inverse rank tolerance of the reference GDOP, relative to sigma_max
PINV_RCOND = 1e-10
#: the B-X1 information baselines scored from the planned observations (:func:`planned_metric`)
PLANNED_METRICS = ("logdet", "mineig", "svd_w", "gdop_w", "cond_w", "logdet_nav")
#: compiled kinds whose paper path is another method's definition (svd_lapack: a real SVD of
#: the 6 x 12 H, compiled; its definition is svd's, CasADi H and LAPACK)
PAPER_OF = {"svd_lapack": "svd"}


# ================================================================== depth error (eq. 19-26)

def _check_positive(name: str, x: float) -> float:
    x = float(x)
    if not np.isfinite(x) or x <= 0:
        raise DegenerateGeometry(f"depth error: {name} must be positive and finite, got {x}")
    return x


def depth(beta, alpha, cd: float) -> np.ndarray:
    """Range C->p (m) of the ground landmark seen at ``beta`` (rad), law of sines;
    ``+inf`` outside ``(0, pi - alpha)``."""
    cd = _check_positive("|CD|", cd)
    beta = np.asarray(beta, float)
    alpha = np.asarray(alpha, float)
    if np.any(~np.isfinite(beta)) or np.any((alpha <= 0) | (alpha >= np.pi)):
        raise ValueError("depth error: beta must be finite and alpha in (0, pi)")
    s = np.sin(alpha + beta)
    ok = (beta > 0) & (alpha + beta < np.pi) & (s > 0)
    return np.where(ok, cd * np.sin(alpha) / np.where(ok, s, 1.0), np.inf)


def depth_error(beta, alpha, cd: float, b: float, r_e: float) -> np.ndarray:
    """Depth estimation error ``dr`` (m), eq. 23-25 as the paper writes them,
    vectorised over ``beta`` (and ``alpha``, broadcast). ``+inf`` outside
    ``(0, pi - alpha)``."""
    b = _check_positive("baseline", b)
    r_e = float(r_e)
    if not np.isfinite(r_e) or r_e < 0:
        raise ValueError(f"depth error: error radius must be >= 0, got {r_e}")
    beta = np.asarray(beta, float)
    d = depth(beta, alpha, cd)
    fin = np.isfinite(d)
    dd = np.where(fin, d, 0.0)
    rks = np.sqrt(np.maximum(b * b + dd * dd - 2 * b * dd * np.cos(beta), 0.0))   # eq. 25
    sin_t = np.where(fin & (rks > 0), b * np.sin(beta) / np.where(rks > 0, rks, 1.0), 0.0)  # eq. 24
    with np.errstate(divide="ignore", over="ignore"):    # a vanishing sin(theta): +inf, as eq. 23 gives
        return np.where(fin & (sin_t > 0), 2.0 * r_e / np.where(sin_t > 0, sin_t, 1.0), np.inf)  # eq. 23


def signed_depth_error(beta_signed, geom: PlaneGeometry, b: float, r_e: float) -> np.ndarray:
    """Depth error (m) for signed beta (rad) in the velocity's vertical plane ``geom``
    (:func:`depth_error`; alpha = pi - gamma beyond D, beta > 0, else gamma)."""
    bs = np.asarray(beta_signed, float)
    return depth_error(np.abs(bs), np.where(bs > 0, np.pi - geom.gamma, geom.gamma), geom.cd, b, r_e)


def angles_to_landmarks(r_L, v_L, p_L: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(alpha, beta, |CD|)`` for arbitrary ground points ``p_L`` (n, 3): beta =
    angle(v, p - C), alpha = angle(v, D - p) (the triangle C, D, p is planar)."""
    geom = plane_geometry(r_L, v_L)
    D = geom.C + geom.cd * geom.v_hat
    p = np.asarray(p_L, float).reshape(-1, 3)
    lc, ld = p - geom.C, D - p
    with np.errstate(invalid="ignore", divide="ignore"):
        cb = (lc @ geom.v_hat) / np.linalg.norm(lc, axis=1)
        ca = (ld @ geom.v_hat) / np.linalg.norm(ld, axis=1)
    beta = np.arccos(np.clip(np.nan_to_num(cb, nan=1.0), -1, 1))
    alpha = np.arccos(np.clip(np.nan_to_num(ca, nan=1.0), -1, 1))
    return np.clip(alpha, 1e-12, np.pi - 1e-12), beta, geom.cd


def depth_error_at_landmarks(r_L, v_L, a_L, p_L, t_s: float, r_e: float) -> np.ndarray:
    """Depth error (m) of each ground landmark ``p_L`` (n, 3), eq. 23-25 (B-F5), the
    baseline of eq. 19 from v_L (m/s), a_L (m/s^2) over t_s (s)."""
    alpha, beta, cd = angles_to_landmarks(r_L, v_L, p_L)
    b = baseline(np.asarray(v_L, float), np.asarray(a_L, float), float(t_s))
    return depth_error(beta, alpha, cd, b, r_e)


# ================================================================== the H baselines

def chol_logdet(A: np.ndarray, jitter: float | None = None) -> np.ndarray:
    """log det of a stack of SPD matrices (..., k, k) as 2 sum(log(diag(L))) of
    the Jacobi-equilibrated matrix D^-1/2 A D^-1/2 + jitter I, plus sum(log D): the
    project's one log-det rule (``linalg.logdet_spd`` compiles it). ``jitter`` defaults to
    k * machine epsilon; a matrix whose Cholesky still fails is retried with the jitter
    multiplied by 1e3 up to 1e-8, then scored -inf. The equilibration keeps the jitter
    relative to each variance, whose units differ."""
    A = np.asarray(A, dtype=float)
    k = A.shape[-1]
    jitter = k * np.finfo(float).eps if jitter is None else jitter
    dg = np.diagonal(A, axis1=-2, axis2=-1)
    out = np.full(A.shape[:-2], -np.inf)
    ok = np.all(dg > 0, axis=-1) & np.all(np.isfinite(A), axis=(-2, -1))
    if not np.any(ok):
        return out
    s = 1.0 / np.sqrt(dg[ok])
    As = A[ok] * s[..., :, None] * s[..., None, :]
    try:
        vals = 2.0 * np.sum(np.log(np.diagonal(np.linalg.cholesky(As + jitter * np.eye(k)),
                                               axis1=-2, axis2=-1)), axis=-1)
    except np.linalg.LinAlgError:          # one by one, the jitter escalated where needed
        vals = np.full(As.shape[0], -np.inf)
        for i, Ai in enumerate(As):
            j = jitter
            while j <= 1e-8:
                try:
                    vals[i] = 2.0 * np.sum(np.log(np.diag(np.linalg.cholesky(Ai + j * np.eye(k)))))
                    break
                except np.linalg.LinAlgError:
                    j *= 1e3
    out[ok] = vals - 2.0 * np.sum(np.log(s), axis=-1)
    return out


def h_scores_from_H(name: str, H: np.ndarray) -> np.ndarray:
    """The H baseline ``name`` (svd, gdop, cond; larger is better) of explicit H (n, 6, 12):
    LAPACK SVD, or the pseudo-inverse for gdop (``(H^T H)^+ = H^+ H^+T``)."""
    if name == "gdop":
        Hp = np.linalg.pinv(H, rcond=PINV_RCOND)
        return 1.0 / np.einsum("nij,nij->n", Hp, Hp)
    s = np.linalg.svd(H, compute_uv=False)
    return np.array([sv_metric(KINDS[name], *(x * x for x in row[:H_RANK])) for row in s])


def h_metric_reference(name: str, ctx, cand: np.ndarray) -> np.ndarray:
    """The H baseline ``name`` of each candidate ``cand`` (n, 3; m, finite) as the paper defines
    it: H of every valid candidate from the CasADi derivation (``Function.map``), then
    :func:`h_scores_from_H`; ``-inf`` where the validity rule (``screens.candidate_ok``) fails.
    ``ctx``: a ``metrics.MetricContext`` (r_L, v_L, p_known_L, R_LtoB and its ``q()``)."""
    from opnav.landing import casadi_model as cm  # CasADi (~15-20 ms import) only here

    ok = valid_points(ctx.q(), np.ascontiguousarray(cand))
    out = np.full(cand.shape[0], -np.inf)
    if ok.any():
        H = cm.jacobian_casadi_batch(ctx.r_L, ctx.v_L, ctx.p_known_L, cand[ok], ctx.R_LtoB)
        out[ok] = h_scores_from_H(name, H)
    return out


# ================================================================== the information baselines

class FilterModel(NamedTuple):
    """The filter's model a planned observation follows: bearing noise sigma_f (rad per
    component, the filter's: noise scale x sigma_b), a new landmark's depth 1-sigma / depth,
    the observations of a landmark n_obs, one image every dt (s), gravity g (3, m/s^2, the
    transition's), and whether the updates are observability-constrained (oc)."""

    sigma_f: float
    depth_sigma_frac: float
    n_obs: int
    dt: float
    g: object
    oc: bool = True


def _states(est, n: int) -> ekf.NavState:
    """One filter state per candidate from the estimate ``est`` (attributes r, v, R_LtoB, P:
    a ``layout.Estimate``, a ``planner.PlanState``): (3,)/(3, 3)/(12, 12) fields repeated, or
    (n, ...) fields (one planning state per candidate) taken as they are."""
    return ekf.NavState(r=np.broadcast_to(np.asarray(est.r, float), (n, 3)).copy(),
                        v=np.broadcast_to(np.asarray(est.v, float), (n, 3)).copy(),
                        R=np.broadcast_to(np.asarray(est.R_LtoB, float), (n, 3, 3)).copy(),
                        p=np.zeros((n, 3)),
                        P=np.broadcast_to(np.asarray(est.P, float), (n, 12, 12)).copy())


def planned_rows(est, p_known, cand, model: FilterModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A (n, m, 12), P0 (n, 12, 12), ok (n,))``, m = 4 n_obs - 2: each candidate's
    prior ``P0`` (its own initialisation) and the whitened tangent-plane rows ``A``
    of its planned observations (module docstring, steps 1-3), mapped to the
    planning instant and, if ``model.oc``, projected off the unit yaw direction; the
    planned information is ``P0^-1 + A^T A``. ``est``: the planning state (r m, v m/s,
    a m/s^2, R_LtoB, P; :func:`_states`), ``p_known`` the site (m), ``cand`` (n, 3) m.
    ``ok`` False where the candidate cannot be initialised (its line of sight misses the
    ground)."""
    sigma_f, depth_sigma_frac, n_obs, dt, g, oc = model
    cand = np.asarray(cand, float).reshape(-1, 3)
    n = len(cand)
    st = _states(est, n)
    acc = np.broadcast_to(np.asarray(est.a, float), (n, 3))
    d = np.einsum("nij,nj->ni", st.R, cand - st.r)
    b = d / np.linalg.norm(d, axis=1, keepdims=True)
    new, ok = ekf.init_landmark(st, b, depth_sigma_frac, sigma_f)     # its own initialisation
    p_known = np.asarray(p_known, float)
    rows = []
    for k in range(int(n_obs)):
        t = k * float(dt)
        r_k = st.r + st.v * t + 0.5 * acc * t * t
        Gs = tangent_jacobian(r_k, st.R, p_known, 1.0 / sigma_f)
        Gs[..., 9:12] = 0.0                                             # the site is known
        G = Gs if k == 0 else np.concatenate([Gs, tangent_jacobian(r_k, st.R, new.p, 1.0 / sigma_f)],
                                             axis=1)
        if k:
            G = G @ ekf.transition_matrix(st.r, st.v, st.R, r_k, st.v + acc * t, st.R, t, g)
        rows.append(G)
    A = np.concatenate(rows, axis=1)                                    # (n, 2 + 4 (n_obs - 1), 12)
    if oc:
        N = ekf.nullspace(new.r, new.v, new.R, new.p)
        N = N / np.linalg.norm(N, axis=-1, keepdims=True)
        A = A - np.einsum("nij,nj,nk->nik", A, N, N)
    return A, new.P, ok


def planned_posterior(est, p_known, cand, model: FilterModel) -> tuple[np.ndarray, np.ndarray]:
    """``(Sigma_post (n, 12, 12), ok (n,))``: the planned posterior covariance of
    ``[dr, dv, dtheta, dp]`` at the planning instant after observing each candidate of
    ``cand`` (n, 3) ``model.n_obs`` times (module docstring), from one planning state
    ``est`` or one per candidate: :func:`planned_rows`, then Woodbury; ``ok`` False where
    the candidate cannot be initialised (its line of sight misses the ground)."""
    A, P0, ok = planned_rows(est, p_known, cand, model)
    AP = A @ P0
    S = np.eye(A.shape[1]) + AP @ np.swapaxes(A, 1, 2)
    Sig = P0 - np.swapaxes(AP, 1, 2) @ np.linalg.solve(S, AP)
    return 0.5 * (Sig + np.swapaxes(Sig, 1, 2)), ok


def planned_nav_logdet(est, p_known, cand, model: FilterModel, boresight_B=None) -> np.ndarray:
    """``-log det`` (nats) of the navigation block (9 x 9) of :func:`planned_posterior`, per
    candidate (n,); larger is better; ``-inf`` for candidates that cannot be initialised or lie
    behind the camera (``boresight_B``: the camera axis in {B}, None = no check). The
    transition to the last image has unit determinant on the navigation block, so the score is
    the same at the planning instant and at the last image."""
    cand = np.asarray(cand, float).reshape(-1, 3)
    Sig, ok = planned_posterior(est, p_known, cand, model)
    out = -chol_logdet(Sig[:, :9, :9])
    if boresight_B is not None:
        st = _states(est, len(cand))
        ok = ok & (np.einsum("nij,nj->ni", st.R, cand - st.r) @ boresight_B > 0)
    return np.where(ok, out, -np.inf)


def planned_metric(name: str, est, p_known, cand, model: FilterModel, boresight_B=None) -> np.ndarray:
    """The B-X1 information baseline ``name`` (:data:`PLANNED_METRICS`, larger is better) of each
    candidate (n,) as its definition says, from the candidate's planned observations
    (:func:`planned_rows`: its own initialisation P0, the filter's noise, ``n_obs`` observations
    on the predicted poses) and the information Lambda = P0^-1 + A^T A:

    * ``logdet`` (D-optimal): log det Lambda (:func:`chol_logdet`, nats);
    * ``mineig`` (E-optimal): lambda_min(Lambda), as 1 / lambda_max of its inverse taken through
      the Jacobi-equilibrated Lambda (Lambda's entries span ~1e14: eigvalsh of it directly loses
      the smallest eigenvalue);
    * ``svd_w``, ``gdop_w``, ``cond_w``: sigma_min, 1 / sum sigma_i^-2, sigma_min / sigma_max of
      the ``min(m, PLANNED_RANK)`` structural singular values of the whitened H, A P0^1/2 (LAPACK
      SVD; A is already whitened by 1/sigma_f);
    * ``logdet_nav``: :func:`planned_nav_logdet`.

    ``-inf`` for candidates that cannot be initialised or lie behind the camera."""
    if name == "logdet_nav":
        return planned_nav_logdet(est, p_known, cand, model, boresight_B)
    if name not in PLANNED_METRICS:
        raise ValueError(f"unknown planned metric {name!r}; expected one of {PLANNED_METRICS}")
    cand = np.asarray(cand, float).reshape(-1, 3)
    A, P0, ok = planned_rows(est, p_known, cand, model)
    Lam = np.linalg.inv(P0) + np.swapaxes(A, 1, 2) @ A
    Lam = 0.5 * (Lam + np.swapaxes(Lam, 1, 2))
    if name == "logdet":
        out = chol_logdet(Lam)
    elif name == "mineig":
        s = 1.0 / np.sqrt(np.diagonal(Lam, axis1=1, axis2=2))
        Sig = np.linalg.inv(Lam * s[:, :, None] * s[:, None, :]) * s[:, :, None] * s[:, None, :]
        out = 1.0 / np.linalg.eigvalsh(0.5 * (Sig + np.swapaxes(Sig, 1, 2)))[:, -1]
    else:
        k = min(A.shape[1], PLANNED_RANK)
        sv = np.linalg.svd(A @ np.linalg.cholesky(P0), compute_uv=False)[:, :k]
        out = {"svd_w": sv[:, -1], "cond_w": sv[:, -1] / sv[:, 0],
               "gdop_w": 1.0 / np.sum(sv ** -2.0, axis=1)}[name]
    if boresight_B is not None:
        R = np.asarray(est.R_LtoB, float)
        ok = ok & ((cand - np.asarray(est.r, float)) @ R.T @ np.asarray(boresight_B, float) > 0)
    return np.where(ok, out, -np.inf)


def whitened_site_bound(est, p_known, cand, model: FilterModel) -> np.ndarray:
    """The ceiling of ``svd_w`` per candidate (n,): the ``j``-th largest singular value of the
    site's whitened rows alone, ``A_site P0^1/2`` (the ``2 n_obs`` rows of :func:`planned_rows`
    with zero landmark columns; module docstring), ``j = min(m, PLANNED_RANK) - 2 (n_obs - 1)``
    (the kept count less the candidate's rows; at ``n_obs <= 3``, the site's smallest).
    Deleting the candidate's ``2 (n_obs - 1)`` rows interlaces the singular values
    (sigma_(j + k)(A P0^1/2) <= sigma_j(A_site P0^1/2), k rows deleted), so ``svd_w <=`` this
    bound and ``gdop_w <=`` its square. The site's rows see the navigation prior only, so the
    bound does not depend on the candidate (without OC exactly; with OC to round-off). NaN
    where the candidate cannot be initialised."""
    A, P0, ok = planned_rows(est, p_known, cand, model)
    n_obs = int(model.n_obs)
    site = [4 * k + i - (2 if k else 0) for k in range(n_obs) for i in range(2)]
    j = min(A.shape[1], PLANNED_RANK) - 2 * (n_obs - 1)
    sv = np.linalg.svd(A[:, site] @ np.linalg.cholesky(P0), compute_uv=False)[:, j - 1]
    return np.where(ok, sv, np.nan)


# ================================================================== the paper path's objective

def paper_objective(method: str, state, cfg, camera, q: np.ndarray, metric_context: Callable):
    """``(f(beta, q), scores(q, xyz, cand), status)`` of ``method`` as the papers define it, for
    the planner's ``paper`` path (the search's source run by the interpreter): the law-of-sines
    depth error (eq. 19-25), the H baselines from CasADi and LAPACK (:func:`h_metric_reference`
    of ``metric_context()``, the state's ``metrics.MetricContext``), the information baselines
    (:func:`planned_metric`); minimised, ``+inf`` where the line of sight misses the ground.
    ``state`` a ``planner.PlanState``, ``cfg`` its ``PlannerConfig``, ``camera`` a ``Camera``,
    ``q`` the call's constants with the plane filled."""
    if method == "depth":
        b = baseline(np.asarray(state.v, float), np.asarray(state.a, float), float(cfg.t_s))
        if not b > 0:
            return None, None, ZERO_BASELINE
        r_e = error_radius(np.asarray(state.P[3:6, 3:6], float), float(cfg.t_s), float(cfg.n_sigma_v))
        geom = PlaneGeometry.of(q)
        f = lambda beta, q: float(signed_depth_error(beta, geom, b, r_e))
        scores = lambda q, xyz, cand: depth_error_at_landmarks(state.r, state.v, state.a, xyz[cand],
                                                               cfg.t_s, r_e)
        return f, scores, OK
    if method in PLANNED_METRICS:
        model = FilterModel(camera.sigma_b * cfg.noise_scale, cfg.depth_sigma_frac, cfg.obs_per_landmark,
                            cfg.t_s, cfg.g, cfg.oc)
        p_known = np.asarray(cfg.p_known, float)
        score = lambda pts: -planned_metric(method, state, p_known, pts, model, camera.boresight_B)
    else:
        ctx = metric_context()
        name = PAPER_OF.get(method, method)
        score = lambda pts: -h_metric_reference(name, ctx, np.asarray(pts, float))

    def f(beta, q):
        hit, x, y, z = ground_point(beta, q)
        return float(score(np.array([[x, y, z]]))[0]) if hit else math.inf

    return f, lambda q, xyz, cand: score(xyz[cand]), OK
