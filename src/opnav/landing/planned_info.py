"""The information a candidate landmark would give the filter, specified as the
filter would get it: B-X1's information baselines (``logdet``, ``mineig``,
``svd_w``, ``gdop_w``, ``cond_w``, ``logdet_nav``; beyond paper B).

Description
-----------
Every information baseline scores what the Fig. 3 strategy would actually do with
the candidate ``p_c`` (m, {L}) from the current estimate (r, v, R_LtoB, P), steps
1-3 below (:func:`planned_rows`), and differs only in what it reads of the planned
information (:func:`planned_metric`; step 4 is ``logdet_nav``'s). An earlier form
scored one two-bearing observation with the true pixel noise and the current
landmark's covariance (issue 43: that mis-specification, not the metrics, made them
lose to depth); it is gone, no study needs it.

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

What the whitened baselines reward (issue 43 follow-up; B-X1)
-------------------------------------------------------------
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

Two implementations of the one specification above: the Monte Carlo's planner runs
the compiled one (``kernels.planned_rows`` and ``kernels.planned``, per candidate:
``ekf._init``, ``measurement.tangent_rows``, ``ekf._nullspace``, the Woodbury
posterior by a Cholesky factor; the transitions Phi_k and the site's rows once per
call, ``kernels.nav_constants``); this module is the reference in numpy, batched over
candidates, in the information form (the tests compare the two, and the planner's
``paper`` path and the timing replay's other path run it). Costs: docs/performance.md.
"""

from __future__ import annotations

import numpy as np

from opnav.landing import ekf
from opnav.landing.measurement import tangent_jacobian
from opnav.landing.metrics import chol_logdet

__all__ = ["planned_nav_logdet", "planned_posterior", "planned_rows", "planned_metric", "whitened_site_bound",
           "PLANNED_METRICS"]

#: the B-X1 information baselines scored from the planned observations (:func:`planned_metric`)
PLANNED_METRICS = ("logdet", "mineig", "svd_w", "gdop_w", "cond_w", "logdet_nav")
#: structural rank of the whitened planned rows A P0^1/2 (yaw unobservable; kernels.PLANNED_RANK)
PLANNED_RANK = 11


def _states(r, v, R_LtoB, P, n: int) -> ekf.NavState:
    """One filter state per candidate: (3,)/(3, 3)/(12, 12) inputs repeated, or
    (n, ...) inputs (one planning state per candidate) taken as they are."""
    return ekf.NavState(r=np.broadcast_to(np.asarray(r, float), (n, 3)).copy(),
                        v=np.broadcast_to(np.asarray(v, float), (n, 3)).copy(),
                        R=np.broadcast_to(np.asarray(R_LtoB, float), (n, 3, 3)).copy(),
                        p=np.zeros((n, 3)),
                        P=np.broadcast_to(np.asarray(P, float), (n, 12, 12)).copy())


def planned_rows(r, v, a, R_LtoB, P, p_known, cand, sigma_f: float, depth_sigma_frac: float,
                 n_obs: int, dt: float, g, oc: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A (n, m, 12), P0 (n, 12, 12), ok (n,))``, m = 4 n_obs - 2: each candidate's
    prior ``P0`` (its own initialisation) and the whitened tangent-plane rows ``A``
    of its planned observations (module docstring, steps 1-3), mapped to the
    planning instant and, if ``oc``, projected off the unit yaw direction; the
    planned information is ``P0^-1 + A^T A``. ``ok`` False where the candidate
    cannot be initialised (its line of sight misses the ground)."""
    cand = np.asarray(cand, float).reshape(-1, 3)
    n = len(cand)
    st = _states(r, v, R_LtoB, P, n)
    acc = np.broadcast_to(np.asarray(a, float), (n, 3))
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


def planned_posterior(r, v, a, R_LtoB, P, p_known, cand, sigma_f: float, depth_sigma_frac: float,
                      n_obs: int, dt: float, g, oc: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """``(Sigma_post (n, 12, 12), ok (n,))``: the planned posterior covariance of
    ``[dr, dv, dtheta, dp]`` at the planning instant after observing each
    candidate of ``cand`` (n, 3) ``n_obs`` times, one image every ``dt`` s
    (module docstring), from one planning state (r (3,), ...: position m,
    velocity m/s, acceleration m/s^2 with gravity ``g``, R_LtoB, P) or one per
    candidate (r (n, 3), ...): :func:`planned_rows`, then Woodbury; ``ok`` False
    where the candidate cannot be initialised (its line of sight misses the ground)."""
    A, P0, ok = planned_rows(r, v, a, R_LtoB, P, p_known, cand, sigma_f, depth_sigma_frac, n_obs, dt, g, oc)
    AP = A @ P0
    S = np.eye(A.shape[1]) + AP @ np.swapaxes(A, 1, 2)
    Sig = P0 - np.swapaxes(AP, 1, 2) @ np.linalg.solve(S, AP)
    return 0.5 * (Sig + np.swapaxes(Sig, 1, 2)), ok


def planned_nav_logdet(r, v, a, R_LtoB, P, p_known, cand, sigma_f: float, depth_sigma_frac: float,
                       n_obs: int, dt: float, g, oc: bool = True, boresight_B=None) -> np.ndarray:
    """``-log det`` (nats) of the navigation block (9 x 9) of
    :func:`planned_posterior`, per candidate (n,); larger is better; ``-inf``
    for candidates that cannot be initialised or lie behind the camera
    (``boresight_B``: the camera axis in {B}, None = no check). The
    transition to the last image has unit determinant on the navigation block,
    so the score is the same at the planning instant and at the last image."""
    cand = np.asarray(cand, float).reshape(-1, 3)
    Sig, ok = planned_posterior(r, v, a, R_LtoB, P, p_known, cand, sigma_f, depth_sigma_frac, n_obs,
                                dt, g, oc)
    out = -chol_logdet(Sig[:, :9, :9])
    if boresight_B is not None:
        st = _states(r, v, R_LtoB, np.eye(12), len(cand))
        ok = ok & (np.einsum("nij,nj->ni", st.R, cand - st.r) @ boresight_B > 0)
    return np.where(ok, out, -np.inf)


def planned_metric(name: str, r, v, a, R_LtoB, P, p_known, cand, sigma_f: float, depth_sigma_frac: float,
                   n_obs: int, dt: float, g, oc: bool = True, boresight_B=None) -> np.ndarray:
    """The B-X1 information baseline ``name`` (:data:`PLANNED_METRICS`, larger is better) of each
    candidate (n,) as its definition says, from the candidate's planned observations
    (:func:`planned_rows`: its own initialisation P0, the filter's noise ``sigma_f``, ``n_obs``
    observations on the predicted poses) and the information Lambda = P0^-1 + A^T A:

    * ``logdet`` (D-optimal): log det Lambda (:func:`metrics.chol_logdet`, nats);
    * ``mineig`` (E-optimal): lambda_min(Lambda), as 1 / lambda_max of its inverse taken through
      the Jacobi-equilibrated Lambda (Lambda's entries span ~1e14: eigvalsh of it directly loses
      the smallest eigenvalue);
    * ``svd_w``, ``gdop_w``, ``cond_w``: sigma_min, 1 / sum sigma_i^-2, sigma_min / sigma_max of
      the ``min(m, PLANNED_RANK)`` structural singular values of the whitened H, A P0^1/2 (LAPACK
      SVD; A is already whitened by 1/sigma_f);
    * ``logdet_nav``: :func:`planned_nav_logdet`.

    ``-inf`` for candidates that cannot be initialised or lie behind the camera. The numpy
    definition: ``kernels.planned`` is tested equal to it."""
    if name == "logdet_nav":
        return planned_nav_logdet(r, v, a, R_LtoB, P, p_known, cand, sigma_f, depth_sigma_frac, n_obs, dt,
                                  g, oc, boresight_B)
    if name not in PLANNED_METRICS:
        raise ValueError(f"unknown planned metric {name!r}; expected one of {PLANNED_METRICS}")
    cand = np.asarray(cand, float).reshape(-1, 3)
    A, P0, ok = planned_rows(r, v, a, R_LtoB, P, p_known, cand, sigma_f, depth_sigma_frac, n_obs, dt, g, oc)
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
        R = np.asarray(R_LtoB, float)
        ok = ok & ((cand - np.asarray(r, float)) @ R.T @ np.asarray(boresight_B, float) > 0)
    return np.where(ok, out, -np.inf)


def whitened_site_bound(r, v, a, R_LtoB, P, p_known, cand, sigma_f: float, depth_sigma_frac: float,
                        n_obs: int, dt: float, g, oc: bool = True) -> np.ndarray:
    """The ceiling of ``svd_w`` per candidate (n,): the ``j``-th largest singular value of the
    site's whitened rows alone, ``A_site P0^1/2`` (the ``2 n_obs`` rows of :func:`planned_rows`
    with zero landmark columns; module docstring), ``j = min(m, PLANNED_RANK) - 2 (n_obs - 1)``
    (the kept count less the candidate's rows; at ``n_obs <= 3``, the site's smallest).
    Deleting the candidate's ``2 (n_obs - 1)`` rows interlaces the singular values
    (sigma_(j + k)(A P0^1/2) <= sigma_j(A_site P0^1/2), k rows deleted), so ``svd_w <=`` this
    bound and ``gdop_w <=`` its square. The site's rows see the navigation prior only, so the
    bound does not depend on the candidate (without OC exactly; with OC to round-off). NaN
    where the candidate cannot be initialised."""
    A, P0, ok = planned_rows(r, v, a, R_LtoB, P, p_known, cand, sigma_f, depth_sigma_frac, n_obs, dt, g, oc)
    site = [4 * k + i - (2 if k else 0) for k in range(int(n_obs)) for i in range(2)]
    j = min(A.shape[1], PLANNED_RANK) - 2 * (int(n_obs) - 1)
    sv = np.linalg.svd(A[:, site] @ np.linalg.cholesky(P0), compute_uv=False)[:, j - 1]
    return np.where(ok, sv, np.nan)
