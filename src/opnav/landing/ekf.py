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

Batches: every function takes arrays with any leading (batch) dimensions,
``r`` (..., 3), ``R`` (..., 3, 3), ``P`` (..., 12, 12), so the Monte Carlo
flies the runs of a chunk as one batch (``opnav.landing.descent``); a single
run is the batch of shape ().

Update: the stacked unit bearings of the known landmark and the unknown one
(eq. 11-18: ``measurement.bearing`` and ``measurement.bearing_jacobian``, their
one home), isotropic noise ``sigma_b`` rad per component, Joseph form. The
cross-product matrices and the attitude correction ``Exp`` are
``opnav.rotations.skew`` / ``exp_so3``.

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

from opnav.landing.measurement import bearing, bearing_jacobian
from opnav.rotations import exp_so3, skew

__all__ = ["NavState", "transition_matrix", "oc_transition", "process_noise", "propagate",
           "update", "init_landmark", "inject", "nullspace", "init_jacobian", "Bearing"]

N_X = 12


def _T(A: np.ndarray) -> np.ndarray:
    return np.swapaxes(A, -1, -2)


def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Matrix (..., n, m) times vector (..., m)."""
    return (A @ x[..., None])[..., 0]


@dataclass
class NavState:
    """Estimates of a batch of runs (leading dimensions ``...``, () for one run)."""

    r: np.ndarray          # (..., 3) m
    v: np.ndarray          # (..., 3) m/s
    R: np.ndarray          # (..., 3, 3) R_LtoB
    p: np.ndarray          # (..., 3) m, unknown landmark
    P: np.ndarray          # (..., 12, 12)

    def copy(self) -> "NavState":
        return NavState(self.r.copy(), self.v.copy(), self.R.copy(), self.p.copy(), self.P.copy())

    def take(self, idx) -> "NavState":
        """The runs ``idx`` (index array into the first batch dimension), copied."""
        return NavState(self.r[idx], self.v[idx], self.R[idx], self.p[idx], self.P[idx])

    def put(self, idx, other: "NavState") -> None:
        """Overwrite the runs ``idx`` with ``other`` (in place)."""
        self.r[idx], self.v[idx], self.R[idx], self.p[idx], self.P[idx] = (
            other.r, other.v, other.R, other.p, other.P)


def transition_matrix(r_i, v_i, C_i, r_j, v_j, C_j, Dt: float, g) -> np.ndarray:
    """Phi (..., 12, 12) of eq. 6-10 from the nominal states at ``i`` and ``j``."""
    g = np.asarray(g, float)
    r_i = np.asarray(r_i, float)
    Phi = np.broadcast_to(np.eye(N_X), r_i.shape[:-1] + (N_X, N_X)).copy()
    Phi[..., 0:3, 3:6] = Dt * np.eye(3)
    Phi[..., 0:3, 6:9] = skew(r_i - r_j + v_i * Dt + 0.5 * g * Dt**2) @ _T(C_i)
    Phi[..., 3:6, 6:9] = skew(v_i - v_j + g * Dt) @ _T(C_i)
    Phi[..., 6:9, 6:9] = C_j @ _T(C_i)
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


def _outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., :, None] * b[..., None, :]


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
    Phi[..., 6:9, 6:9] = C_j @ _T(C_i_prior)
    u = N_i[..., 6:9]
    uu = np.einsum("...i,...i->...", u, u)[..., None, None]
    w1 = N_j[..., 0:3] - N_i[..., 0:3] - Dt * N_i[..., 3:6]
    w2 = N_j[..., 3:6] - N_i[..., 3:6]
    A = Phi[..., 0:3, 6:9]
    Phi[..., 0:3, 6:9] = A - _outer(_mv(A, u) - w1, u) / uu
    B = Phi[..., 3:6, 6:9]
    Phi[..., 3:6, 6:9] = B - _outer(_mv(B, u) - w2, u) / uu
    # the landmark's estimate moved in the update: carry its part of N too
    w3 = N_j[..., 9:12] - N_i[..., 9:12]
    Phi[..., 9:12, 6:9] = _outer(w3, u) / uu
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
    R_BtoL = _T(C_i)
    r_j = st.r + st.v * Dt + _mv(R_BtoL, dp) + 0.5 * g * Dt**2
    v_j = st.v + _mv(R_BtoL, dv) + g * Dt
    C_j = _T(R_BtoL @ dR)
    Phi = transition_matrix(st.r, st.v, C_i, r_j, v_j, C_j, Dt, g)
    if oc is not None:
        N_i, C_i_prior = oc
        Phi = oc_transition(Phi, N_i, nullspace(r_j, v_j, C_j, st.p), C_i_prior, C_j, Dt)
    P = Phi @ st.P @ _T(Phi) + Q
    return NavState(r_j, v_j, C_j, st.p.copy(), 0.5 * (P + _T(P)))


def inject(st: NavState, dx: np.ndarray) -> None:
    """Apply an error-state correction (..., 12) in place (attitude on the body side)."""
    st.r = st.r + dx[..., 0:3]
    st.v = st.v + dx[..., 3:6]
    st.R = exp_so3(-dx[..., 6:9]) @ st.R
    st.p = st.p + dx[..., 9:12]


def nullspace(r, v, R, p) -> np.ndarray:
    """Unobservable direction (..., 12) of the error state with one known landmark at
    the {L} origin: a rotation of everything about the vertical through the site
    (yaw): ``[e_z x r, e_z x v, R e_z, e_z x p]`` (our body-side dtheta)."""
    # e_z x a = [-a_y, a_x, 0]
    r, v, R, p = (np.asarray(x, float) for x in (r, v, R, p))
    z = np.zeros(r.shape[:-1])
    return np.stack([-r[..., 1], r[..., 0], z, -v[..., 1], v[..., 0], z, R[..., 0, 2], R[..., 1, 2],
                     R[..., 2, 2], -p[..., 1], p[..., 0], z], axis=-1)


@dataclass(frozen=True)
class Bearing:
    """One measured unit bearing per run: ``b`` (..., 3) in {B}, of the known
    landmark ``p_known`` (3,) m, or of the state's unknown landmark (None)."""

    b: np.ndarray
    p_known: np.ndarray | None = None


def _linearise(st: NavState, meas: list[Bearing], N):
    """Stacked Jacobian H (..., 3m, 12) and residual (..., 3m) of the bearings
    at ``st``; H projected on the complement of ``N`` (..., 12) if given."""
    lead = st.r.shape[:-1]
    m = len(meas)
    H = np.zeros(lead + (3 * m, N_X))
    res = np.empty(lead + (3 * m,))
    for i, ms in enumerate(meas):
        p = st.p if ms.p_known is None else np.broadcast_to(ms.p_known, st.r.shape)
        Hr, Ht, Hp = bearing_jacobian(st.r, st.R, p)                 # eq. 15-18
        res[..., 3 * i:3 * i + 3] = ms.b - bearing(st.r, st.R, p)      # eq. 12
        H[..., 3 * i:3 * i + 3, 0:3] = Hr
        H[..., 3 * i:3 * i + 3, 6:9] = Ht
        if ms.p_known is None:
            H[..., 3 * i:3 * i + 3, 9:12] = Hp
    if N is not None:
        n = N / np.linalg.norm(N, axis=-1, keepdims=True)
        H = H - _outer(_mv(H, n), n)
    return H, res


def update(st: NavState, meas: list[Bearing], sigma_b: float,
           N: np.ndarray | None = None, iterations: int = 1) -> tuple[NavState, np.ndarray]:
    """Bearing update (eq. 11-18) of every run of the batch with the same kinds
    of bearings ``meas`` (each :class:`Bearing` holds one per run).

    Returns the updated state and the NIS (at the prior, per run).

    ``iterations > 1`` relinearises the measurement at the updated estimate
    (iterated EKF, Gauss-Newton on the MAP cost): with initial errors of 1 km
    and 2 deg the second-order terms of a bearing exceed its 0.5-pixel noise,
    so a single linearisation is overconfident. A run stops iterating once its
    correction changes by less than 1e-9 (the others go on: masks). ``N``
    (..., 12), if given, is the unobservable direction; the Jacobian is then
    projected so that ``H N = 0`` (observability-constrained EKF, Hesch et al.
    2013, paper B ref. [16]).
    """
    m = len(meas)
    lead = st.r.shape[:-1]
    if m == 0:
        return st, np.full(lead, np.nan)
    Rn = sigma_b**2 * np.eye(3 * m)
    it = st
    delta = np.zeros(lead + (N_X,))
    K = H = nis = None
    going = np.ones(lead, bool)
    for k in range(max(1, int(iterations))):
        H_k, res = _linearise(it, meas, N)
        PHt = st.P @ _T(H_k)
        S = H_k @ PHt + Rn
        if k == 0:         # one solve for the gain and the NIS
            X = np.linalg.solve(S, np.concatenate([_T(PHt), res[..., None]], axis=-1))
            K_k = _T(X[..., :N_X])
            nis = np.einsum("...i,...i->...", res, X[..., N_X])
            K, H = K_k, H_k
        else:
            K_k = _T(np.linalg.solve(S, _T(PHt)))
        delta_new = _mv(K_k, res + _mv(H_k, delta))
        g = going[..., None]
        K = np.where(g[..., None], K_k, K)
        H = np.where(g[..., None], H_k, H)
        nxt = NavState(st.r, st.v, st.R, st.p, st.P)
        inject(nxt, delta_new)
        it = NavState(*(np.where(going.reshape(lead + (1,) * (a.ndim - len(lead))), a, b)
                        for a, b in ((nxt.r, it.r), (nxt.v, it.v), (nxt.R, it.R), (nxt.p, it.p))),
                      st.P)
        conv = np.max(np.abs(delta_new - delta), axis=-1) < 1e-9
        delta = np.where(g, delta_new, delta)
        going = going & ~conv
        if not going.any():
            break
    A = np.eye(N_X) - K @ H
    P = A @ st.P @ _T(A) + K @ Rn @ _T(K)
    return NavState(it.r, it.v, it.R, it.p, 0.5 * (P + _T(P))), nis


def init_jacobian(st: NavState, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(p, J, d, ok)``: the new landmark ``p`` (..., 3) seen along ``b`` cut with
    the ground, the Jacobian ``J`` (..., 3, 9) of ``p`` w.r.t. ``[dr, dv,
    dtheta]``, the depth guess ``d`` (..., m) and ``ok`` (...,): False where the
    ray misses the ground or the lander is not above it (p, J, d meaningless there)."""
    u = _mv(_T(st.R), b)
    ok = (u[..., 2] < 0) & (st.r[..., 2] > 0)
    uz = np.where(ok, u[..., 2], -1.0)
    d = -st.r[..., 2] / uz
    proj = np.eye(3) - _outer(u, np.array([0.0, 0.0, 1.0])) / uz[..., None, None]
    J = np.zeros(b.shape[:-1] + (3, 9))
    J[..., 0:3] = proj
    J[..., 6:9] = proj @ (-d[..., None, None] * _T(st.R) @ skew(b))
    return st.r + d[..., None] * u, J, d, ok


def init_landmark(st: NavState, b: np.ndarray, depth_sigma_frac: float, sigma_b: float
                  ) -> tuple[NavState, np.ndarray]:
    """Replace the unknown landmark by a new one seen along the bearing ``b`` (body).

    Returns the new state and ``ok`` (...,): where the estimated line of sight
    does not meet the ground or the estimated lander is not above it, the
    run's state is returned unchanged and ``ok`` is False.
    """
    p, J, d, ok = init_jacobian(st, b)
    u = _mv(_T(st.R), b)
    Pxx = st.P[..., :9, :9]
    Ppx = J @ Pxx
    uu = _outer(u, u)
    # ... plus a large independent depth variance (the depth guess) and the
    # bearing noise across the line of sight
    dd = d[..., None, None]
    Ppp = J @ Pxx @ _T(J) + (depth_sigma_frac * dd) ** 2 * uu + (dd * sigma_b) ** 2 * (np.eye(3) - uu)
    P = st.P.copy()
    P[..., 9:12, :9] = Ppx
    P[..., :9, 9:12] = _T(Ppx)
    P[..., 9:12, 9:12] = Ppp
    P = 0.5 * (P + _T(P))
    okv = ok[..., None]
    return NavState(st.r.copy(), st.v.copy(), st.R.copy(), np.where(okv, p, st.p),
                    np.where(okv[..., None], P, st.P)), ok
