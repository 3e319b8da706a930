"""Vision-aided inertial error-state EKF (paper B eq. 4-18).

Description
-----------
State ``x = [r, v, q, p]`` (eq. 4, ``n_p = 1`` unknown landmark): position and
velocity in {L} (m, m/s), attitude ``R_LtoB`` (the paper's ``C(q)``), and the
unknown landmark's position ``p`` in {L} (m). Error state (eq. 5), dimension
12: ``[dr, dv, dtheta, dp]`` with the body-side attitude error of
``opnav.landing.measurement`` (``R_LtoB_true = Exp(-dtheta) R_LtoB_est``).

Propagation over one filter interval ``i -> j`` (``Delta t``) applies the IMU
pre-integration in closed form (``opnav.landing.imu``) and the transition
matrix of eq. 6-10::

    Phi_13 = [ (r_i - r_j + v_i Dt + g Dt^2 / 2) x ] C_i^T        (eq. 8)
    Phi_23 = [ (v_i - v_j + g Dt) x ] C_i^T                         (eq. 9)
    Phi_33 = C_j C_i^T                                              (eq. 10)

with ``g = [0, 0, -3.711]`` the gravity vector (``a = C^T f + g``). The paper
prints ``- g`` in eq. 8-9, which is the same matrix for a gravity vector of
the opposite sign; with our sign these are exactly the Jacobians of the
closed-form propagation (checked by finite differences in the tests).

Process noise (IMU white noise, per-sample 1-sigma ``sigma_a``, ``sigma_w`` at
step ``dt``, ``n`` samples per interval) is isotropic and therefore frame-free::

    Q_vv = n sigma_a^2 dt^2 I,  Q_rv = sigma_a^2 dt^3 sum_k (n - k - 1/2) I,
    Q_rr = sigma_a^2 dt^4 sum_k (n - k - 1/2)^2 I,  Q_thth = n sigma_w^2 dt^2 I

(the attitude-noise coupling into velocity is second order and omitted).

Update: the stacked unit bearings of the known landmark and the unknown one
(eq. 11-18), isotropic noise ``sigma_b`` rad per component, Joseph form.

Landmark initialisation (Fig. 3 strategy): from its first bearing ``b`` and a
depth guess ``d`` (the estimated line of sight cut with the ground plane),
``p = r + d R^T b``, with covariance from the state's through the Jacobian of
that ray-plane intersection (cross-covariance kept) plus a large independent depth variance ``(depth_sigma_frac d)^2`` along the
line of sight and the bearing noise across it; the old landmark's rows and
columns are overwritten (removed from the state).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.landing.measurement import bearing_jacobian, exp_so3, skew

__all__ = ["NavState", "transition_matrix", "process_noise", "propagate", "update",
           "init_landmark", "inject", "nullspace", "init_jacobian"]

N_X = 12


@dataclass
class NavState:
    r: np.ndarray          # (3,) m
    v: np.ndarray          # (3,) m/s
    R: np.ndarray          # (3, 3) R_LtoB
    p: np.ndarray          # (3,) m, unknown landmark
    P: np.ndarray          # (12, 12)

    def copy(self) -> "NavState":
        return NavState(self.r.copy(), self.v.copy(), self.R.copy(), self.p.copy(), self.P.copy())


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
