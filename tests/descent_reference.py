"""Frozen per-run reference of the paper-B descent (main at cfa4b0d, before the
batched descent): ``run_descent`` and the per-run EKF steps exactly as they were,
kept under tests/ only to check that the batched descent
(``opnav.landing.descent.run_descents``) gives the same numbers to round-off
(tests/test_landing_batch.py, benchmarks/bench_descent.py). Not part of the
package; do not edit except to follow renamed imports (and the vision cut-off margin of
issue 29, a change of specification)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from opnav.landing import imu
from opnav.landing.measurement import bearing_jacobian
from opnav.core.rotations import exp_so3, skew
from opnav.landing.metrics import H_METRICS
from opnav.landing.planner import PlanState, plan
from opnav.landing.trajectory import euler_rpy_deg

N_X = 12


@dataclass
class NavState:
    r: np.ndarray
    v: np.ndarray
    R: np.ndarray
    p: np.ndarray
    P: np.ndarray


def transition_matrix(r_i, v_i, C_i, r_j, v_j, C_j, Dt: float, g) -> np.ndarray:
    """Phi (12, 12) of eq. 6-10 from the nominal states at ``i`` and ``j``."""
    g = np.asarray(g, float)
    Phi = np.eye(N_X)
    Phi[0:3, 3:6] = Dt * np.eye(3)
    Phi[0:3, 6:9] = skew(r_i - r_j + v_i * Dt + 0.5 * g * Dt**2) @ C_i.T
    Phi[3:6, 6:9] = skew(v_i - v_j + g * Dt) @ C_i.T
    Phi[6:9, 6:9] = C_j @ C_i.T
    return Phi


def process_noise(sigma_a: float, sigma_w: float, dt: float, n_sub: int) -> np.ndarray:
    """Q (12, 12) of one filter interval of ``n_sub`` IMU samples of step ``dt``."""
    k = np.arange(n_sub)
    c = (n_sub - k - 0.5) * dt
    q = sigma_a**2 * dt**2
    Q = np.zeros((N_X, N_X))
    I3 = np.eye(3)
    Q[0:3, 0:3] = q * np.sum(c**2) * I3
    Q[0:3, 3:6] = Q[3:6, 0:3] = q * np.sum(c) * I3
    Q[3:6, 3:6] = q * n_sub * I3
    Q[6:9, 6:9] = n_sub * sigma_w**2 * dt**2 * I3
    return Q


def oc_transition(Phi: np.ndarray, N_i: np.ndarray, N_j: np.ndarray, C_i_prior: np.ndarray,
                  C_j: np.ndarray, Dt: float) -> np.ndarray:
    """Observability-constrained Phi (Hesch et al. 2013): the smallest change of
    the attitude columns with ``Phi N_i = N_j``, ``N`` from the *prior*
    (propagated) estimates at ``i`` and ``j``. Because the update moves the
    estimate between the two priors, the unconstrained Phi maps the direction
    at the *posterior* instead, and the filter gains spurious yaw information
    (paper B ref. [16]); the landmark rows get the rank-one term that carries
    its part of ``N`` from its prior to its posterior estimate."""
    Phi = Phi.copy()
    Phi[6:9, 6:9] = C_j @ C_i_prior.T
    u = N_i[6:9]
    uu = float(u @ u)
    w1 = N_j[0:3] - N_i[0:3] - Dt * N_i[3:6]
    w2 = N_j[3:6] - N_i[3:6]
    A = Phi[0:3, 6:9]
    Phi[0:3, 6:9] = A - np.outer(A @ u - w1, u) / uu
    B = Phi[3:6, 6:9]
    Phi[3:6, 6:9] = B - np.outer(B @ u - w2, u) / uu
    # the landmark's estimate moved in the update: carry its part of N too
    w3 = N_j[9:12] - N_i[9:12]
    Phi[9:12, 6:9] = np.outer(w3, u) / uu
    return Phi


def propagate(st: NavState, dR, dv, dp, Dt: float, g, Q: np.ndarray,
              oc: tuple | None = None) -> NavState:
    """Closed-form propagation of one interval (imu.apply_increment) and of P.

    ``oc = (N_i, C_i_prior)`` switches on the observability constraint: ``N_i``
    the unobservable direction at the prior estimate of step i (attitude
    ``C_i_prior``); ``Phi`` is then modified by :func:`oc_transition` to map it
    to ``N_j`` at the new prior. The update Jacobian, evaluated at that prior,
    annihilates ``N_j`` exactly, so the linearised system keeps yaw unobservable.
    """
    g = np.asarray(g, float)
    C_i = st.R
    R_BtoL = C_i.T
    r_j = st.r + st.v * Dt + R_BtoL @ dp + 0.5 * g * Dt**2
    v_j = st.v + R_BtoL @ dv + g * Dt
    C_j = (R_BtoL @ dR).T
    Phi = transition_matrix(st.r, st.v, C_i, r_j, v_j, C_j, Dt, g)
    if oc is not None:
        N_i, C_i_prior = oc
        Phi = oc_transition(Phi, N_i, nullspace(r_j, v_j, C_j, st.p), C_i_prior, C_j, Dt)
    P = Phi @ st.P @ Phi.T + Q
    return NavState(r_j, v_j, C_j, st.p.copy(), 0.5 * (P + P.T))


def inject(st: NavState, dx: np.ndarray) -> None:
    """Apply an error-state correction in place (attitude on the body side)."""
    st.r = st.r + dx[0:3]
    st.v = st.v + dx[3:6]
    st.R = exp_so3(-dx[6:9]) @ st.R
    st.p = st.p + dx[9:12]


def nullspace(r, v, R, p) -> np.ndarray:
    """Unobservable direction (12,) of the error state with one known landmark at
    the {L} origin: a rotation of everything about the vertical through the site
    (yaw): ``[e_z x r, e_z x v, R e_z, e_z x p]`` (our body-side dtheta)."""
    # e_z x a = [-a_y, a_x, 0]
    return np.array([-r[1], r[0], 0.0, -v[1], v[0], 0.0, R[0, 2], R[1, 2], R[2, 2],
                     -p[1], p[0], 0.0])


def _boxminus(a: NavState, b: NavState) -> np.ndarray:
    """Error-state difference ``a - b`` (12,) in our convention (R_a = Exp(-d) R_b)."""
    from scipy.spatial.transform import Rotation

    dth = -Rotation.from_matrix(a.R @ b.R.T).as_rotvec()
    return np.concatenate([a.r - b.r, a.v - b.v, dth, a.p - b.p])


def _linearise(st: NavState, meas, N):
    m = len(meas)
    H = np.zeros((3 * m, N_X))
    res = np.empty(3 * m)
    for i, (b, p_known) in enumerate(meas):
        p = st.p if p_known is None else p_known
        Hr, Ht, Hp = bearing_jacobian(st.r, st.R, p)
        rho = st.R @ (p - st.r)
        res[3 * i:3 * i + 3] = b - rho / np.linalg.norm(rho)
        H[3 * i:3 * i + 3, 0:3] = Hr
        H[3 * i:3 * i + 3, 6:9] = Ht
        if p_known is None:
            H[3 * i:3 * i + 3, 9:12] = Hp
    if N is not None:
        n = N / np.linalg.norm(N)
        H = H - np.outer(H @ n, n)
    return H, res


def update(st: NavState, meas: list[tuple[np.ndarray, np.ndarray | None]], sigma_b: float,
           N: np.ndarray | None = None, iterations: int = 1) -> tuple[NavState, float]:
    """Bearing update (eq. 11-18).

    ``meas``: list of ``(b_measured (3,), p_known_L or None)``; ``None`` means the
    unknown landmark of the state. Returns the updated state and the NIS (at
    the prior).

    ``iterations > 1`` relinearises the measurement at the updated estimate
    (iterated EKF, Gauss-Newton on the MAP cost): with initial errors of 1 km
    and 2 deg the second-order terms of a bearing exceed its 0.5-pixel noise,
    so a single linearisation is overconfident. ``N`` (12,), if given, is the
    unobservable direction; the Jacobian is then projected so that
    ``H N = 0`` (observability-constrained EKF, Hesch et al. 2013, paper B
    ref. [16]).
    """
    m = len(meas)
    if m == 0:
        return st, float("nan")
    Rn = sigma_b**2 * np.eye(3 * m)
    it = st
    delta = np.zeros(N_X)
    nis = float("nan")
    for k in range(max(1, int(iterations))):
        H, res = _linearise(it, meas, N)
        PHt = st.P @ H.T
        S = H @ PHt + Rn
        K = np.linalg.solve(S, PHt.T).T
        if k == 0:
            nis = float(res @ np.linalg.solve(S, res))
        delta_new = K @ (res + H @ delta)
        it = NavState(st.r, st.v, st.R, st.p, st.P)
        inject(it, delta_new)
        if np.max(np.abs(delta_new - delta)) < 1e-9:
            delta = delta_new
            break
        delta = delta_new
    A = np.eye(N_X) - K @ H
    P = A @ st.P @ A.T + K @ Rn @ K.T
    return NavState(it.r, it.v, it.R, it.p, 0.5 * (P + P.T)), nis


def init_jacobian(st: NavState, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(p, J, d)``: the new landmark ``p`` seen along ``b`` cut with the ground,
    the Jacobian ``J`` (3, 9) of ``p`` w.r.t. ``[dr, dv, dtheta]`` and the depth
    guess ``d`` (m). Raises ``ValueError`` if the ray misses the ground."""
    u = st.R.T @ b
    if u[2] >= 0 or st.r[2] <= 0:
        raise ValueError("landmark initialisation: line of sight does not meet the ground")
    d = -st.r[2] / u[2]
    proj = np.eye(3) - np.outer(u, np.array([0.0, 0.0, 1.0])) / u[2]
    J = np.zeros((3, 9))
    J[:, 0:3] = proj
    J[:, 6:9] = proj @ (-d * st.R.T @ skew(b))
    return st.r + d * u, J, d


def init_landmark(st: NavState, b: np.ndarray, depth_sigma_frac: float, sigma_b: float) -> NavState:
    """Replace the unknown landmark by a new one seen along the bearing ``b`` (body).

    Raises ``ValueError`` if the estimated line of sight does not meet the ground
    or the estimated lander is not above it.
    """
    p, J, d = init_jacobian(st, b)
    u = st.R.T @ b
    Pxx = st.P[:9, :9]
    Ppx = J @ Pxx
    uu = np.outer(u, u)
    # ... plus a large independent depth variance (the depth guess) and the
    # bearing noise across the line of sight
    Ppp = J @ Pxx @ J.T + (depth_sigma_frac * d) ** 2 * uu + (d * sigma_b) ** 2 * (np.eye(3) - uu)
    P = st.P.copy()
    P[9:12, :9] = Ppx
    P[:9, 9:12] = Ppx.T
    P[9:12, 9:12] = Ppp
    return NavState(st.r.copy(), st.v.copy(), st.R.copy(), p, 0.5 * (P + P.T))


# ---- descent (per run)

def initial_error(rng: np.random.Generator, bounds: tuple) -> np.ndarray:
    """Error state (truth - estimate) [dr, dv, dtheta] (9,), uniform per axis."""
    br, bv, bt = bounds
    return np.concatenate([rng.uniform(-br, br, 3), rng.uniform(-bv, bv, 3),
                           rng.uniform(-bt, bt, 3)])


def _att_error(R_true: np.ndarray, R_est: np.ndarray) -> np.ndarray:
    """dtheta (rad) with R_true = Exp(-dtheta) R_est (log map; angles < pi/2)."""
    D = R_true @ R_est.T
    w = 0.5 * np.array([D[2, 1] - D[1, 2], D[0, 2] - D[2, 0], D[1, 0] - D[0, 1]])
    s = float(np.linalg.norm(w))
    c = 0.5 * (D[0, 0] + D[1, 1] + D[2, 2] - 1.0)
    if s < 1e-12:
        return -w
    return -w * (math.atan2(s, c) / s)


def _wrap_deg(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def run_descent(scn: Scenario, method: str, run_index: int, *, base_seed: int | None = None,
                imu_noise: bool = True, init_error: bool = True) -> dict:
    """Fly one descent; see the module docstring for the returned arrays."""
    seed = scn.base_seed if base_seed is None else int(base_seed)
    ss = np.random.SeedSequence([seed, int(run_index)])
    rng_init, rng_imu, rng_px, rng_pick = (np.random.default_rng(s) for s in ss.spawn(4))
    e0 = initial_error(rng_init, scn.bounds)
    if not init_error:
        e0[:] = 0.0
    if imu_noise:
        f, w = imu.add_noise(scn.f, scn.w, scn.sigma_a, scn.sigma_w, rng_imu)
    else:
        f, w = scn.f, scn.w
    noise_px = rng_px.standard_normal((scn.n_steps + 1, 2, 2))
    pre = imu.preintegrate(f, w, scn.dt_imu, scn.n_sub)

    tr = scn.truth
    cam = scn.camera
    sb = cam.sigma_b * scn.noise_scale      # the filter's bearing-noise model
    p_site = np.zeros(3)
    P0 = np.zeros((12, 12))
    br, bv, bt = scn.bounds
    P0[:9, :9] = np.diag(np.repeat([br**2 / 3, bv**2 / 3, bt**2 / 3], 3))
    P0[9:, 9:] = np.eye(3) * 1e8      # dormant until the first landmark is initialised
    st = NavState(r=tr.r[0] - e0[0:3], v=tr.v[0] - e0[3:6],
                      R=exp_so3(e0[6:9]) @ tr.R_LtoB[0], p=np.zeros(3), P=P0)
    n = scn.n_steps
    err_r = np.empty((n + 1, 3))
    err_v = np.empty((n + 1, 3))
    err_th = np.empty((n + 1, 3))
    sig = np.empty((n + 1, 9))
    sig_yaw = np.empty(n + 1)
    nees_r = np.empty(n + 1)
    nees_v = np.empty(n + 1)
    updated = np.zeros(n + 1, bool)
    plan_ns, plan_cpu, plan_evals, plan_t, plan_beta, plan_idx = [], [], [], [], [], []
    plan_edge, plan_ratio, plan_ns_alt, plan_cpu_alt = [], [], [], []
    cur, n_obs, n_used = -1, 0, 0
    a_est = tr.a[0]

    def record(k):
        er = tr.r[k] - st.r
        ev = tr.v[k] - st.v
        err_r[k], err_v[k] = er, ev
        err_th[k] = _att_error(tr.R_LtoB[k], st.R)
        sig[k] = np.sqrt(np.clip(np.diag(st.P)[:9], 0, None))
        sig_yaw[k] = yaw_sigma_rad(st.R, st.P)
        nees_r[k] = er @ np.linalg.solve(st.P[0:3, 0:3], er)
        nees_v[k] = ev @ np.linalg.solve(st.P[3:6, 3:6], ev)

    record(0)
    # the planner's metric contexts skip validation (timed path): validate the
    # descent's inputs once, here, with the same kinds of values
    from opnav.landing.metrics import MetricContext

    MetricContext(r_L=st.r, v_L=st.v, R_LtoB=st.R, p_known_L=np.asarray(scn.planner.p_known, float),
                  P=st.P, R_meas=scn.camera.sigma_b**2 * np.eye(6), boresight_B=cam.boresight_B)
    # observability constraint (OC-EKF): unobservable direction at the prior
    N = nullspace(st.r, st.v, st.R, st.p)
    C_prior = st.R
    for j in range(n):
        v_prev = st.v
        oc = (N, C_prior) if scn.oc else None
        st = propagate(st, pre.dR[j], pre.dv[j], pre.dp[j], scn.Dt, scn.g, scn.Q, oc)
        N = nullspace(st.r, st.v, st.R, st.p)
        C_prior = st.R
        a_est = (st.v - v_prev) / scn.Dt
        k = j + 1
        # issue 29: the cut-off has a margin on the estimated altitude (spec change)
        if k < n and st.r[2] - scn.update_margin_m > scn.min_update_alt:
            r_t, R_t = tr.r[k], tr.R_LtoB[k]

            def visible(pts, margin=scn.planner.margin_px, r_t=r_t, R_t=R_t):
                # pose bound now (not late-bound), so a stored closure stays this image's
                return cam.in_view((np.asarray(pts) - r_t) @ R_t.T, margin)

            meas = []
            d_site = R_t @ (p_site - r_t)
            if cam.in_view(d_site[None])[0]:
                meas.append((cam.measure(d_site, noise_px[k, 0]), p_site))
            still = cur >= 0 and visible(scn.field.xyz[cur][None], 0.0)[0]
            need_new = cur < 0 or n_obs >= scn.obs_per_landmark or not still
            det = visible(scn.field.xyz) if need_new else None   # the image's feature list
            if need_new and not _detects_other(det, cur):
                # the image holds no other landmark (e.g. low altitude): nothing to
                # choose, so no planning call; keep the current one while it is seen
                need_new = False
                if not still:
                    cur, n_obs = -1, 0
            if need_new:
                res = plan(method, PlanState(st.r, st.v, a_est, st.R, st.P), cam, scn.field,
                           visible, scn.planner, exclude={cur} if cur >= 0 else set(),
                           rng=rng_pick, detected=np.flatnonzero(det))
                plan_ns.append(res.time_ns)
                plan_cpu.append(res.cpu_ns)
                if method in H_METRICS:
                    # the paper's baselines on the alternative evaluation path too
                    # (closed-form singular values vs H + LAPACK): timing only, same pick
                    alt = plan(method, PlanState(st.r, st.v, a_est, st.R, st.P), cam, scn.field,
                               visible, scn.planner_alt, exclude={cur} if cur >= 0 else set(),
                               rng=None, detected=np.flatnonzero(det), diagnose=False)
                    plan_ns_alt.append(alt.time_ns)
                    plan_cpu_alt.append(alt.cpu_ns)
                else:
                    plan_ns_alt.append(res.time_ns)
                    plan_cpu_alt.append(res.cpu_ns)
                plan_evals.append(res.n_evals)
                plan_t.append(k * scn.Dt)
                plan_beta.append(res.beta)
                plan_idx.append(res.index)
                plan_edge.append(res.edge)
                plan_ratio.append(res.pick_ratio)
                cur, n_obs = res.index, 0
                if cur >= 0:
                    b = cam.measure(R_t @ (scn.field.xyz[cur] - r_t), noise_px[k, 1])
                    try:
                        st = init_landmark(st, b, scn.depth_sigma_frac, sb)
                        N = nullspace(st.r, st.v, st.R, st.p)
                        n_obs, n_used = 1, n_used + 1
                    except ValueError:
                        cur = -1
            elif cur >= 0:
                b = cam.measure(R_t @ (scn.field.xyz[cur] - r_t), noise_px[k, 1])
                meas.append((b, None))
                n_obs += 1
            if meas:
                # OC-EKF: the Jacobian at the prior annihilates N exactly; an iterated
                # update relinearises away from the prior, so it must project H on N's
                # complement (update), or yaw becomes spuriously observable
                st, _ = update(st, meas, sb, N if scn.oc else None, scn.iterations)
                updated[k] = True
        record(k)

    rpy_t = euler_rpy_deg(tr.R_LtoB)
    return {
        "t": tr.t.copy(),
        "err_r": err_r, "err_v": err_v, "err_th_deg": np.degrees(err_th),
        "err_rpy_deg": _wrap_deg(rpy_t - _est_rpy(tr.R_LtoB, err_th)),
        "sig_r": sig[:, 0:3], "sig_v": sig[:, 3:6], "sig_th_deg": np.degrees(sig[:, 6:9]),
        "sig_yaw_deg": np.degrees(sig_yaw),
        "nees_r": nees_r, "nees_v": nees_v, "updated": updated,
        "plan_ns": np.asarray(plan_ns, np.int64), "plan_cpu_ns": np.asarray(plan_cpu, np.int64),
        "plan_evals": np.asarray(plan_evals, np.int64),
        "plan_t": np.asarray(plan_t, float), "plan_beta": np.asarray(plan_beta, float),
        "plan_index": np.asarray(plan_idx, np.int64), "n_landmarks": n_used,
        "plan_edge": np.asarray(plan_edge, bool), "plan_ratio": np.asarray(plan_ratio, float),
        "plan_ns_alt": np.asarray(plan_ns_alt, np.int64),
        "plan_cpu_ns_alt": np.asarray(plan_cpu_alt, np.int64),
        "init_error": e0,
    }


def yaw_sigma_rad(R_LtoB: np.ndarray, P: np.ndarray) -> float:
    """1-sigma (rad) of the filter's heading error: the attitude error about the
    {L} vertical, i.e. along ``R_LtoB e_z`` in our body-side ``dtheta`` (the
    attitude part of the unobservable direction, :func:`nullspace`)."""
    u = R_LtoB[:, 2]
    return float(math.sqrt(max(float(u @ P[6:9, 6:9] @ u), 0.0)))


def last_update_index(updated: np.ndarray) -> int:
    """Index of the last filter time with a vision update (0 if none): after it
    the filter coasts on the IMU to touchdown."""
    idx = np.flatnonzero(np.asarray(updated, bool))
    return int(idx[-1]) if idx.size else 0


def _detects_other(detected: np.ndarray, cur: int) -> bool:
    """True if the camera detects a landmark other than ``cur`` (the image's
    feature list, from the truth pose: the same for every planning method)."""
    return bool(detected.sum() - (detected[cur] if cur >= 0 else 0) > 0)


def _est_rpy(R_true: np.ndarray, dth: np.ndarray) -> np.ndarray:
    """Estimated roll/pitch/yaw (deg) from the truth and dtheta (R_est = Exp(dtheta) R_true)."""
    R_est = exp_so3(dth) @ R_true
    return euler_rpy_deg(R_est)
