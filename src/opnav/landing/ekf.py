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

Compiled: each step is written once as plain loops over one run's 3-vectors
and 12 x 12 matrices (``opnav.core.compiled.kernel``: here ``_transition`` eq. 6-10,
``_oc``, ``_propagate``, ``_init``, ``_nullspace``; the update's ``_linearise``,
``_update`` eq. 11-18 and ``_inject`` in ``opnav.landing.ekf_update``), and a
``*_batch`` kernel loops over the runs; the Python functions below flatten the
leading dimensions and call them. The bearing and its Jacobian blocks are the
kernels of ``opnav.landing.measurement``, Exp is
``opnav.core.rotations.exp_so3_into``. The pre-kernel numpy EKF
(tests/descent_reference.py) is the reference the tests compare against.
Compiling per run and looping over the batch inside the kernel is what makes a
Monte-Carlo chunk cheap (measured: docs/performance.md).

Update (``opnav.landing.ekf_update``): the stacked unit bearings of the known
landmark and the unknown one (eq. 11-18: ``measurement.line_of_sight`` and
``measurement.blocks``, their one home), isotropic noise ``sigma_b`` rad per
component, gain by a Cholesky solve (``opnav.landing.linalg``), Joseph form.

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

from opnav.core.compiled import kernel, warms
from opnav.landing.ekf_update import N_X, _inject_batch, _linearise_batch, _update_batch
from opnav.landing.linalg import matmul, symmetrize

__all__ = ["NavState", "transition_matrix", "oc_transition", "process_noise", "propagate",
           "update", "linearise", "init_landmark", "inject", "nullspace", "init_jacobian", "Bearing"]


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


# ---------------------------------------------------------------- kernels: one run each
# (plain loops over 3-vectors and 12 x 12 matrices; the *_batch kernels loop over runs)

@kernel
def _skew_CT(a0, a1, a2, C, Phi, row) -> None:
    """``Phi[row:row+3, 6:9] = [a x] C^T`` (eq. 8-9)."""
    for j in range(3):
        Phi[row, 6 + j] = -a2 * C[j, 1] + a1 * C[j, 2]
        Phi[row + 1, 6 + j] = a2 * C[j, 0] - a0 * C[j, 2]
        Phi[row + 2, 6 + j] = -a1 * C[j, 0] + a0 * C[j, 1]


@kernel
def _transition(r_i, v_i, C_i, r_j, v_j, C_j, Dt, g, Phi) -> None:
    """Phi (12, 12) of eq. 6-10 (module docstring) into ``Phi``."""
    for a in range(N_X):
        for b in range(N_X):
            Phi[a, b] = 1.0 if a == b else 0.0
    for a in range(3):
        Phi[a, 3 + a] = Dt
    h = 0.5 * Dt * Dt
    _skew_CT(r_i[0] - r_j[0] + v_i[0] * Dt + g[0] * h, r_i[1] - r_j[1] + v_i[1] * Dt + g[1] * h,
             r_i[2] - r_j[2] + v_i[2] * Dt + g[2] * h, C_i, Phi, 0)                   # eq. 8
    _skew_CT(v_i[0] - v_j[0] + g[0] * Dt, v_i[1] - v_j[1] + g[1] * Dt,
             v_i[2] - v_j[2] + g[2] * Dt, C_i, Phi, 3)                                # eq. 9
    for a in range(3):                                                               # eq. 10
        for b in range(3):
            Phi[6 + a, 6 + b] = C_j[a, 0] * C_i[b, 0] + C_j[a, 1] * C_i[b, 1] + C_j[a, 2] * C_i[b, 2]


@kernel
def _nullspace(r, v, R, p, N) -> None:
    """``N`` (12,) <- ``[e_z x r, e_z x v, R e_z, e_z x p]`` (:func:`nullspace`)."""
    N[0], N[1], N[2] = -r[1], r[0], 0.0
    N[3], N[4], N[5] = -v[1], v[0], 0.0
    N[6], N[7], N[8] = R[0, 2], R[1, 2], R[2, 2]
    N[9], N[10], N[11] = -p[1], p[0], 0.0


@kernel
def _oc(Phi, N_i, N_j, C_i_prior, C_j, Dt) -> None:
    """:func:`oc_transition` in place on one ``Phi`` (12, 12)."""
    for a in range(3):
        for b in range(3):
            Phi[6 + a, 6 + b] = (C_j[a, 0] * C_i_prior[b, 0] + C_j[a, 1] * C_i_prior[b, 1]
                                 + C_j[a, 2] * C_i_prior[b, 2])
    uu = N_i[6] * N_i[6] + N_i[7] * N_i[7] + N_i[8] * N_i[8]
    for blk in range(2):                      # position rows (w1), velocity rows (w2)
        row = 3 * blk
        for a in range(3):
            Au = Phi[row + a, 6] * N_i[6] + Phi[row + a, 7] * N_i[7] + Phi[row + a, 8] * N_i[8]
            w = N_j[row + a] - N_i[row + a] - (Dt * N_i[3 + a] if blk == 0 else 0.0)
            f = (Au - w) / uu
            for b in range(3):
                Phi[row + a, 6 + b] -= f * N_i[6 + b]
    for a in range(3):                        # the landmark's part of N (w3)
        w3 = N_j[9 + a] - N_i[9 + a]
        for b in range(3):
            Phi[9 + a, 6 + b] = w3 * N_i[6 + b] / uu


@kernel
def _propagate(x, inc, model, ocp, out, work) -> None:
    """One run's :func:`propagate`: ``x = (r, v, C_i, p, P)`` the state at i, ``inc = (dR, dv,
    dp)`` the IMU increments (``imu.apply_increment``), ``model = (Dt, g, Q)`` (s, m/s^2, the
    interval's process noise), ``ocp = (oc, N_i, C_i_prior)`` the observability constraint
    (:func:`oc_transition`, if ``oc``), ``out = (r_j, v_j, C_j, P_j)``, ``work = (Phi, N_j,
    T)`` scratch (12, 12), (12,), (12, 12)."""
    r, v, C_i, p, P = x
    dR, dv, dp = inc
    Dt, g, Q = model
    oc, N_i, C_i_prior = ocp
    r_j, v_j, C_j, P_j = out
    Phi, N_j, T = work
    h = 0.5 * Dt * Dt
    for a in range(3):        # R_BtoL = C_i^T
        r_j[a] = (r[a] + v[a] * Dt + (C_i[0, a] * dp[0] + C_i[1, a] * dp[1] + C_i[2, a] * dp[2])
                  + g[a] * h)
        v_j[a] = v[a] + (C_i[0, a] * dv[0] + C_i[1, a] * dv[1] + C_i[2, a] * dv[2]) + g[a] * Dt
    for a in range(3):        # C_j = (C_i^T dR)^T = dR^T C_i
        for b in range(3):
            C_j[a, b] = dR[0, a] * C_i[0, b] + dR[1, a] * C_i[1, b] + dR[2, a] * C_i[2, b]
    _transition(r, v, C_i, r_j, v_j, C_j, Dt, g, Phi)
    if oc:
        _nullspace(r_j, v_j, C_j, p, N_j)
        _oc(Phi, N_i, N_j, C_i_prior, C_j, Dt)
    matmul(Phi, P, T)
    for a in range(N_X):      # P_j = T Phi^T + Q
        for b in range(N_X):
            s = 0.0
            for c in range(N_X):
                s += T[a, c] * Phi[b, c]
            P_j[a, b] = s + Q[a, b]
    symmetrize(P_j)


@kernel
def _init(r, R, P, b, depth_sigma_frac, sigma_b, p_o, P_o, J, JP) -> bool:
    """One run's :func:`init_landmark` into ``p_o`` (3,), ``P_o`` (12, 12) (left
    as they are when the ray misses the ground); ``J`` (3, 9) the Jacobian of
    :func:`init_jacobian`, ``JP`` (3, 9) scratch. Returns ``ok``."""
    u0 = R[0, 0] * b[0] + R[1, 0] * b[1] + R[2, 0] * b[2]       # u = R^T b
    u1 = R[0, 1] * b[0] + R[1, 1] * b[1] + R[2, 1] * b[2]
    u2 = R[0, 2] * b[0] + R[1, 2] * b[1] + R[2, 2] * b[2]
    if not (u2 < 0.0 and r[2] > 0.0):
        return False
    d = -r[2] / u2
    u = (u0, u1, u2)
    for a in range(3):                        # proj = I - u e_z^T / u_z
        for c in range(3):
            J[a, c] = (1.0 if a == c else 0.0) - (u[a] / u2 if c == 2 else 0.0)
            J[a, 3 + c] = 0.0
    # attitude block: proj (-d R^T [b x]); R^T [b x] column c = R^T (b x e_c)
    for c in range(3):
        e0 = (0.0, -b[2], b[1])[c]            # b x e_c = column c of [b x]
        e1 = (b[2], 0.0, -b[0])[c]
        e2 = (-b[1], b[0], 0.0)[c]
        w0 = -d * (R[0, 0] * e0 + R[1, 0] * e1 + R[2, 0] * e2)
        w1 = -d * (R[0, 1] * e0 + R[1, 1] * e1 + R[2, 1] * e2)
        w2 = -d * (R[0, 2] * e0 + R[1, 2] * e1 + R[2, 2] * e2)
        for a in range(3):
            J[a, 6 + c] = J[a, 0] * w0 + J[a, 1] * w1 + J[a, 2] * w2
    for a in range(3):
        p_o[a] = r[a] + d * u[a]
    for a in range(3):                        # JP = J P_xx
        for c in range(9):
            s = 0.0
            for k in range(9):
                s += J[a, k] * P[k, c]
            JP[a, c] = s
    for a in range(N_X):
        for c in range(N_X):
            P_o[a, c] = P[a, c]
    fd2 = (depth_sigma_frac * d) ** 2
    bd2 = (d * sigma_b) ** 2
    for a in range(3):
        for c in range(9):
            P_o[9 + a, c] = JP[a, c]
            P_o[c, 9 + a] = JP[a, c]
        for c in range(3):
            s = 0.0
            for k in range(9):
                s += JP[a, k] * J[c, k]
            uu = u[a] * u[c]
            P_o[9 + a, 9 + c] = s + fd2 * uu + bd2 * ((1.0 if a == c else 0.0) - uu)
    symmetrize(P_o)
    return True


# ---------------------------------------------------------------- kernels: batches of runs

@kernel
def _transition_batch(r_i, v_i, C_i, r_j, v_j, C_j, Dt, g, Phi) -> None:
    for k in range(r_i.shape[0]):
        _transition(r_i[k], v_i[k], C_i[k], r_j[k], v_j[k], C_j[k], Dt[k], g, Phi[k])


@kernel
def _oc_batch(Phi, N_i, N_j, C_i_prior, C_j, Dt) -> None:
    for k in range(Phi.shape[0]):
        _oc(Phi[k], N_i[k], N_j[k], C_i_prior[k], C_j[k], Dt)


@kernel
def _nullspace_batch(r, v, R, p, N) -> None:
    for k in range(r.shape[0]):
        _nullspace(r[k], v[k], R[k], p[k], N[k])


@kernel
def _propagate_batch(x, inc, model, ocp, out) -> None:
    """:func:`_propagate` of every run (the tuples' arrays with a leading run axis; ``model``
    and the flag ``oc`` shared)."""
    r, v, R, p, P = x
    dR, dv, dp = inc
    oc, N_i, C_i_prior = ocp
    r_j, v_j, R_j, P_j = out
    work = (np.empty((N_X, N_X)), np.empty(N_X), np.empty((N_X, N_X)))
    for k in range(r.shape[0]):
        _propagate((r[k], v[k], R[k], p[k], P[k]), (dR[k], dv[k], dp[k]), model, (oc, N_i[k], C_i_prior[k]),
                   (r_j[k], v_j[k], R_j[k], P_j[k]), work)


@kernel
def _init_batch(r, R, P, b, depth_sigma_frac, sigma_b, p_o, P_o, J, ok) -> None:
    JP = np.empty((3, 9))
    for k in range(r.shape[0]):
        ok[k] = _init(r[k], R[k], P[k], b[k], depth_sigma_frac, sigma_b, p_o[k], P_o[k], J[k], JP)


@warms
def _warm() -> None:
    st = NavState(np.array([[10.0, 20.0, 3000.0]]), np.ones((1, 3)), np.eye(3)[None].copy(),
                  np.array([[50.0, 0.0, 0.0]]), np.eye(N_X)[None].copy())
    g = np.array([0.0, 0.0, -3.711])
    N = nullspace(st.r, st.v, st.R, st.p)
    st2 = propagate(st, np.eye(3)[None], np.zeros((1, 3)), np.zeros((1, 3)), 1.0, g,
                    np.eye(N_X), (N, st.R))
    oc_transition(transition_matrix(st.r, st.v, st.R, st2.r, st2.v, st2.R, 1.0, g), N, N, st.R,
                  st2.R, 1.0)
    init_landmark(st2, np.array([[0.0, 0.0, -1.0]]), 0.1, 1e-3)


# ---------------------------------------------------------------- the Python API (batches)

def _rows(a, tail: tuple, lead: tuple) -> np.ndarray:
    """``a`` broadcast to ``lead + tail`` as contiguous float rows (n, *tail) (no
    copy when it already is)."""
    a = np.asarray(a, float)
    if a.shape != lead + tail or not (a.flags.c_contiguous and a.flags.writeable):
        a = np.array(np.broadcast_to(a, lead + tail), order="C")   # writable: one kernel signature
    return a.reshape((-1,) + tail)


def _flat(st: NavState) -> tuple:
    lead = st.r.shape[:-1]
    return lead, (_rows(st.r, (3,), lead), _rows(st.v, (3,), lead), _rows(st.R, (3, 3), lead),
                  _rows(st.p, (3,), lead), _rows(st.P, (N_X, N_X), lead))


def _state(lead: tuple, r, v, R, p, P) -> NavState:
    return NavState(r.reshape(lead + (3,)), v.reshape(lead + (3,)), R.reshape(lead + (3, 3)),
                    p.reshape(lead + (3,)), P.reshape(lead + (N_X, N_X)))


def transition_matrix(r_i, v_i, C_i, r_j, v_j, C_j, Dt, g) -> np.ndarray:
    """Phi (..., 12, 12) of eq. 6-10 from the nominal states at ``i`` and ``j``
    (``Dt`` s, a scalar or one per run; all broadcast over leading dimensions)."""
    lead = np.broadcast_shapes(*(np.shape(x)[:-1] for x in (r_i, v_i, r_j, v_j)),
                               *(np.shape(x)[:-2] for x in (C_i, C_j)), np.shape(Dt))
    Phi = np.empty((int(np.prod(lead)), N_X, N_X))
    _transition_batch(_rows(r_i, (3,), lead), _rows(v_i, (3,), lead), _rows(C_i, (3, 3), lead),
                      _rows(r_j, (3,), lead), _rows(v_j, (3,), lead), _rows(C_j, (3, 3), lead),
                      _rows(Dt, (), lead), _rows(g, (3,), ())[0], Phi)
    return Phi.reshape(lead + (N_X, N_X))


def process_noise(sigma_a: float, sigma_w: float, dt: float, n_sub: int) -> np.ndarray:
    """Q (12, 12) of one filter interval of ``n_sub`` IMU samples of step ``dt``
    (computed once per scenario: numpy; the propagation kernel adds it)."""
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
    Phi = np.asarray(Phi, float)
    lead = Phi.shape[:-2]
    out = _rows(Phi, (N_X, N_X), lead).copy()
    _oc_batch(out, _rows(N_i, (N_X,), lead), _rows(N_j, (N_X,), lead),
              _rows(C_i_prior, (3, 3), lead), _rows(C_j, (3, 3), lead), float(Dt))
    return out.reshape(Phi.shape)


def propagate(st: NavState, dR, dv, dp, Dt: float, g, Q: np.ndarray,
              oc: tuple | None = None) -> NavState:
    """Closed-form propagation of one interval (imu.apply_increment) and of P
    (``P_j = Phi P Phi^T + Q``, eq. 6-10), one kernel call for the batch.

    ``oc = (N_i, C_i_prior)`` switches on the observability constraint: ``N_i``
    the unobservable direction at the prior estimate of step i (attitude
    ``C_i_prior``); ``Phi`` is then modified by :func:`oc_transition` to map it
    to ``N_j`` at the new prior. The update Jacobian, evaluated at that prior,
    annihilates ``N_j`` exactly, so the linearised system keeps yaw unobservable.
    """
    lead, (r, v, R, p, P) = _flat(st)
    n = r.shape[0]
    N_i, C_p = (np.zeros((n, N_X)), R) if oc is None else (_rows(oc[0], (N_X,), lead),
                                                           _rows(oc[1], (3, 3), lead))
    r_j, v_j, R_j, P_j = np.empty_like(r), np.empty_like(v), np.empty_like(R), np.empty_like(P)
    _propagate_batch((r, v, R, p, P), (_rows(dR, (3, 3), lead), _rows(dv, (3,), lead), _rows(dp, (3,), lead)),
                     (float(Dt), _rows(g, (3,), ())[0], _rows(Q, (N_X, N_X), ())[0]),
                     (oc is not None, N_i, C_p), (r_j, v_j, R_j, P_j))
    return _state(lead, r_j, v_j, R_j, p.copy(), P_j)


def inject(st: NavState, dx: np.ndarray) -> None:
    """Apply an error-state correction (..., 12) in place (attitude on the body
    side: ``R <- Exp(-dtheta) R``)."""
    lead, (r, v, R, p, _) = _flat(st)
    out = [np.empty_like(a) for a in (r, v, R, p)]
    _inject_batch(r, v, R, p, _rows(dx, (N_X,), lead), *out)
    st.r, st.v, st.R, st.p = (a.reshape(lead + a.shape[1:]) for a in out)


def nullspace(r, v, R, p) -> np.ndarray:
    """Unobservable direction (..., 12) of the error state with one known landmark at
    the {L} origin: a rotation of everything about the vertical through the site
    (yaw): ``[e_z x r, e_z x v, R e_z, e_z x p]`` (our body-side dtheta)."""
    r = np.asarray(r, float)
    lead = r.shape[:-1]
    if not (np.shape(v)[:-1] == np.shape(R)[:-2] == np.shape(p)[:-1] == lead):
        lead = np.broadcast_shapes(lead, np.shape(v)[:-1], np.shape(R)[:-2], np.shape(p)[:-1])
    N = np.empty((int(np.prod(lead)), N_X))
    _nullspace_batch(_rows(r, (3,), lead), _rows(v, (3,), lead), _rows(R, (3, 3), lead),
                     _rows(p, (3,), lead), N)
    return N.reshape(lead + (N_X,))


@dataclass(frozen=True)
class Bearing:
    """One measured unit bearing per run: ``b`` (..., 3) in {B}, of the known
    landmark ``p_known`` (3,) m, or of the state's unknown landmark (None)."""

    b: np.ndarray
    p_known: np.ndarray | None = None


def _measurements(lead: tuple, meas: list[Bearing]):
    """``(bs (n, m, 3), pk (n, m, 3), known (m,))`` of the bearings ``meas``."""
    m = len(meas)
    n = int(np.prod(lead))
    bs = np.empty((n, m, 3))
    pk = np.zeros((n, m, 3))
    known = np.zeros(m, np.bool_)
    for i, ms in enumerate(meas):
        bs[:, i] = _rows(ms.b, (3,), lead)
        if ms.p_known is not None:
            pk[:, i] = _rows(ms.p_known, (3,), lead)
            known[i] = True
    return bs, pk, known


def _direction(N, lead: tuple) -> tuple[np.ndarray, bool]:
    if N is None:
        return np.zeros((int(np.prod(lead)), N_X)), False
    return _rows(N, (N_X,), lead), True


def linearise(st: NavState, meas: list[Bearing], N=None) -> tuple[np.ndarray, np.ndarray]:
    """Stacked Jacobian H (..., 3m, 12) and residual (..., 3m) of the bearings
    ``meas`` at ``st`` (eq. 12, 15-18); H projected on the complement of ``N``
    (..., 12) if given (the kernel :func:`update` iterates with)."""
    lead, (r, v, R, p, P) = _flat(st)
    bs, pk, known = _measurements(lead, meas)
    Nf, use = _direction(N, lead)
    H = np.empty((r.shape[0], 3 * len(meas), N_X))
    res = np.empty((r.shape[0], 3 * len(meas)))
    if not _linearise_batch(r, R, p, (bs, pk, known), (Nf, use), H, res):
        raise ValueError("bearing undefined: a landmark at the lander or a non-finite state")
    return H.reshape(lead + H.shape[1:]), res.reshape(lead + res.shape[1:])


def update(st: NavState, meas: list[Bearing], sigma_b: float,
           N: np.ndarray | None = None, iterations: int = 1) -> tuple[NavState, np.ndarray]:
    """Bearing update (eq. 11-18) of every run of the batch with the same kinds
    of bearings ``meas`` (each :class:`Bearing` holds one per run), one kernel
    call: gain from a Cholesky solve of ``S = H P H^T + sigma_b^2 I``, Joseph form.

    Returns the updated state and the NIS (at the prior, per run).

    ``iterations > 1`` relinearises the measurement at the updated estimate
    (iterated EKF, Gauss-Newton on the MAP cost): with initial errors of 1 km
    and 2 deg the second-order terms of a bearing exceed its 0.5-pixel noise,
    so a single linearisation is overconfident. A run stops iterating once its
    correction changes by less than 1e-9 (per run, in the kernel). ``N``
    (..., 12), if given, is the unobservable direction; the Jacobian is then
    projected so that ``H N = 0`` (observability-constrained EKF, Hesch et al.
    2013, paper B ref. [16]).
    """
    lead = st.r.shape[:-1]
    if len(meas) == 0:
        return st, np.full(lead, np.nan)
    lead, (r, v, R, p, P) = _flat(st)
    bs, pk, known = _measurements(lead, meas)
    Nf, use = _direction(N, lead)
    out = [np.empty_like(a) for a in (r, v, R, p, P)]
    nis = np.empty(r.shape[0])
    _update_batch((r, v, R, p, P), (bs, pk, known), (Nf, use), (float(sigma_b), int(iterations)),
                  tuple(out), nis)
    if np.isnan(nis).any():
        raise ValueError("bearing undefined: a landmark at the lander or a non-finite state")
    return _state(lead, *out), nis.reshape(lead)


def init_jacobian(st: NavState, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(p, J, d, ok)``: the new landmark ``p`` (..., 3) seen along ``b`` cut with
    the ground, the Jacobian ``J`` (..., 3, 9) of ``p`` w.r.t. ``[dr, dv,
    dtheta]``, the depth guess ``d`` (...) and ``ok`` (...,): False where the
    ray misses the ground or the lander is not above it (p, J, d meaningless there)."""
    new, ok, J = _init_landmark(st, b, 0.0, 0.0)
    u_z = np.einsum("...j,...j->...", np.asarray(st.R, float)[..., :, 2], b)     # (R^T b)_z
    d = -st.r[..., 2] / np.where(ok, u_z, -1.0)
    return new.p, J, d, ok


def _init_landmark(st: NavState, b, depth_sigma_frac: float, sigma_b: float):
    lead, (r, v, R, p, P) = _flat(st)
    p_o, P_o = p.copy(), P.copy()
    J = np.zeros((r.shape[0], 3, 9))
    ok = np.empty(r.shape[0], np.bool_)
    _init_batch(r, R, P, _rows(b, (3,), lead), float(depth_sigma_frac), float(sigma_b), p_o, P_o, J, ok)
    return (_state(lead, r.copy(), v.copy(), R.copy(), p_o, P_o), ok.reshape(lead),
            J.reshape(lead + (3, 9)))


def init_landmark(st: NavState, b: np.ndarray, depth_sigma_frac: float, sigma_b: float
                  ) -> tuple[NavState, np.ndarray]:
    """Replace the unknown landmark by a new one seen along the bearing ``b`` (body).

    Returns the new state and ``ok`` (...,): where the estimated line of sight
    does not meet the ground or the estimated lander is not above it, the
    run's state is returned unchanged and ``ok`` is False.
    """
    new, ok, _ = _init_landmark(st, b, depth_sigma_frac, sigma_b)
    return new, ok
