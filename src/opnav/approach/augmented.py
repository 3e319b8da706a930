"""Misalignment by state augmentation: the EKF carries theta as constant states (A-X2 (a); SPEC A.4).

Description
    The alternative a navigation engineer tries first: append the camera
    misalignment ``theta = (tx, ty, tz)`` to the filter state,
    ``Y = [dX; theta]`` (9 states), and run one EKF over the data.

    Time update (theta constant, optional random-walk noise ``q_theta``)::

        dX_k = Phi_{k,k-1} dX_{k-1} + W_{k-1},   theta_k = theta_{k-1} + w_theta

    Measurement (SPEC A.2, paper eq. 3 with the small-angle eq. 5)::

        z_k = A_m(theta) (u_ref,k - C_k dr_k) + v_k,   A_m = I - [theta x],
        H_k = [ -A_m(theta) C_k,  0_3x3,  [u_k x] ],   u_k = u_ref,k - C_k dr_k,

    since ``-[theta x] u = [u x] theta``. The update uses the Joseph form. Star images
    (``stars`` variant) are linear measurements of theta alone, ``y = G theta + noise``
    (:mod:`opnav.approach.stars`), added in information form after the Mars update.
    Internally theta is carried in arcsec, so that its column of ``H``
    (``[u x]`` times one arcsec, a few km) is of the same order as the
    position columns; inputs and outputs are in rad.

    On the linear-Gaussian model (``H`` evaluated at the truth) this recursion
    is the Kalman filter of ``[dX; theta]`` and its theta covariance is the
    Bayesian Cramér-Rao bound (:func:`opnav.approach.crlb.crlb_curve` runs the
    same recursion along the truth, without data). The EKF differs only by
    evaluating ``u_k`` and ``A_m`` at its own estimate; the bilinear term
    ``[C dr x] theta`` (about 100 km x 1e-4 rad = 0.01 km, against a lateral
    noise of about 1 km) makes the difference negligible.

Tuning
    ``theta_prior_sigma`` (rad): the prior on theta, ``N(theta0, sigma^2 I)``;
    ``q_theta`` (rad^2 per step): random-walk noise, zero for a constant bias.

Use
    :func:`run_augmented` runs every Monte-Carlo seed at once (leading axis
    ``S``), on the :class:`~opnav.approach.ekf.Window` arrays of the EM-EKF,
    from the same start state ``x0, P0``.

Units: km, km/s, rad (arcsec internally for theta).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from opnav.core.rotations import skew

from opnav.core.compiled import kernel, warms

from .dynamics import ARCSEC
from . import kalman
from .ekf import Window
from .kalman import _condition1, _loglik1, _predict_cov1, _predict_mean1, carray
from .stars import theta_information_update


@dataclass
class AugmentedResult:
    """Augmented-EKF output; index 0 of the time axis is the start sample."""

    theta: np.ndarray  # (S, n+1, 3) rad
    P_theta: np.ndarray  # (S, n+1, 3, 3) rad^2
    xf: np.ndarray  # (S, n+1, 6) filtered state deviation
    P_pos_trace: np.ndarray  # (S, n+1) km^2, trace of the position covariance
    loglik: np.ndarray  # (S,) innovation log-likelihood of the augmented filter


@kernel(inline="always")
def _jacobian1(A, C, U, H):
    """``H = [-A C, 0_3x3, U]`` (3, 9) of one member."""
    for i in range(3):
        for j in range(3):
            H[i, j] = -(A[i, 0] * C[0, j] + A[i, 1] * C[1, j] + A[i, 2] * C[2, j])
            H[i, 3 + j] = 0.0
            H[i, 6 + j] = U[i, j]


@kernel
def _jacobian_batch(A, C, U, H):
    for b in range(H.shape[0]):
        _jacobian1(A[b if A.shape[0] > 1 else 0], C[b if C.shape[0] > 1 else 0], U[b if U.shape[0] > 1 else 0], H[b])


@kernel
def _augmented_samples(k0, k1, z, model, lin, state, out):
    """The augmented EKF (module docstring) over samples ``k0..k1-1`` for every seed, in place
    on ``y`` (S, 9) and ``P`` (S, 9, 9): time update with ``F = diag(Phi_k, I)`` and ``Qa``
    (:func:`opnav.approach.kalman._predict_mean1`, ``_predict_cov1``), then the Mars update
    in Joseph form (``_condition1``) with ``H = [-A_m C_k, 0, [u_k x] arcsec]`` at the
    filter's own estimate (``linear``: ``H`` with ``A_lin`` and ``U_lin[k]`` fixed and
    ``z_hat = u_ref + H y``); ``ll`` (S,) gathers the innovation log-likelihood, and
    ``th_out, Pth_out, xf, ptr`` (S, n+1, ...) the outputs of every sample (theta in arcsec).

    ``model = (Phi, C, u_ref, Rvar, Qa)`` the window (Rvar (n+1, S, 3)), ``lin = (linear,
    A_lin, U_lin)``, ``state = (y, P)``, ``out = (th_out, Pth_out, xf, ptr, ll)``."""
    Phi, C, u_ref, Rvar, Qa = model
    linear, A_lin, U_lin = lin
    y, P = state
    th_out, Pth_out, xf, ptr, ll = out
    S = y.shape[0]
    F = np.zeros((9, 9))
    for i in range(6, 9):
        F[i, i] = 1.0
    FP = np.empty((9, 9))
    yp = np.empty(9)
    H = np.empty((3, 9))
    A = np.empty((3, 3))
    U = np.empty((3, 3))
    u = np.empty(3)
    nu = np.empty(3)
    K = np.empty((9, 3))
    Sinv = np.empty((3, 3))
    PHt = np.empty((9, 3))
    Sm = np.empty((3, 3))
    T1 = np.empty((9, 9))
    T2 = np.empty((9, 9))
    for s in range(S):
        for k in range(k0, k1):
            for i in range(6):
                for j in range(6):
                    F[i, j] = Phi[k, i, j]
            _predict_mean1(y[s], F, yp)
            _predict_cov1(P[s], F, Qa, T1, FP)
            for i in range(9):
                y[s, i] = yp[i]
                for j in range(9):
                    P[s, i, j] = T1[i, j]
            if linear:
                _jacobian1(A_lin, C[k], U_lin[k], H)
                for i in range(3):
                    acc = u_ref[k, i]
                    for j in range(9):
                        acc += H[i, j] * y[s, j]
                    nu[i] = z[s, k, i] - acc
            else:
                t0, t1, t2 = y[s, 6] * ARCSEC, y[s, 7] * ARCSEC, y[s, 8] * ARCSEC
                A[0, 0], A[0, 1], A[0, 2] = 1.0, t2, -t1  # A_m = I - [theta x]
                A[1, 0], A[1, 1], A[1, 2] = -t2, 1.0, t0
                A[2, 0], A[2, 1], A[2, 2] = t1, -t0, 1.0
                for i in range(3):
                    u[i] = u_ref[k, i] - (C[k, i, 0] * y[s, 0] + C[k, i, 1] * y[s, 1] + C[k, i, 2] * y[s, 2])
                U[0, 0], U[0, 1], U[0, 2] = 0.0, -u[2] * ARCSEC, u[1] * ARCSEC  # [u x] arcsec
                U[1, 0], U[1, 1], U[1, 2] = u[2] * ARCSEC, 0.0, -u[0] * ARCSEC
                U[2, 0], U[2, 1], U[2, 2] = -u[1] * ARCSEC, u[0] * ARCSEC, 0.0
                _jacobian1(A, C[k], U, H)
                for i in range(3):
                    nu[i] = z[s, k, i] - (A[i, 0] * u[0] + A[i, 1] * u[1] + A[i, 2] * u[2])
            det = _condition1(True, y[s], P[s], (H, 0, Rvar[k, s], nu), True, (K, Sinv), (PHt, Sm, T1, T2))
            ll[s] += _loglik1(nu, Sinv, det)
            for i in range(3):
                th_out[s, k, i] = y[s, 6 + i]
                for j in range(3):
                    Pth_out[s, k, i, j] = P[s, 6 + i, 6 + j]
            for i in range(6):
                xf[s, k, i] = y[s, i]
            ptr[s, k] = P[s, 0, 0] + P[s, 1, 1] + P[s, 2, 2]


def run_augmented(z: np.ndarray, x0: np.ndarray, P0: np.ndarray, theta0: np.ndarray,
                  theta_prior_sigma: float, win: Window, q_theta: float = 0.0,
                  u_lin: np.ndarray | None = None) -> AugmentedResult:
    """Augmented EKF over a window for every seed (module docstring).

    z (S, n+1, 3) km (index 0 ignored); x0 (S, 6); P0 (6, 6) or (S, 6, 6);
    theta0 (S, 3) or (3,) rad; theta_prior_sigma rad; q_theta rad^2 per step.

    ``u_lin`` (n+1, 3), km: if given, the filter is the *linear* Kalman filter
    of the model linearised at fixed points, ``z_k = u_ref,k + H_k Y_k + v_k``
    with ``H_k = [-A_m(theta0) C_k, 0, [u_lin,k x]]`` (theta0 of the first
    seed); its covariance is then the Bayesian Cramér-Rao bound of that
    linear-Gaussian model, independent of the data.

    Compiled between star images (:func:`_augmented_samples`).
    """
    z = np.asarray(z, float)
    S, n = z.shape[0], win.n
    if z.shape[1] != n + 1:
        raise ValueError(f"z has {z.shape[1]} samples, the window {n + 1}")
    if not theta_prior_sigma > 0:
        raise ValueError("theta_prior_sigma must be positive")
    y = np.zeros((S, 9))
    y[:, :6] = x0
    y[:, 6:] = np.broadcast_to(np.asarray(theta0, float), (S, 3)) / ARCSEC
    P = np.zeros((S, 9, 9))
    P[:, :6, :6] = np.broadcast_to(P0, (S, 6, 6))
    P[:, 6:, 6:] = np.eye(3) * (theta_prior_sigma / ARCSEC) ** 2
    Qa = augmented_noise(win.Q, q_theta / ARCSEC**2)
    th_out = np.empty((S, n + 1, 3))
    Pth_out = np.empty((S, n + 1, 3, 3))
    xf = np.empty((S, n + 1, 6))
    ptr = np.empty((S, n + 1))
    th_out[:, 0], Pth_out[:, 0], xf[:, 0] = y[:, 6:], P[:, 6:, 6:], y[:, :6]
    ptr[:, 0] = np.trace(P[:, :3, :3], axis1=1, axis2=2)
    ll = np.zeros(S)
    linear = u_lin is not None
    A_lin = np.eye(3) - skew(y[0, 6:] * ARCSEC) if linear else np.eye(3)
    U_lin = skew(np.asarray(u_lin, float)) * ARCSEC if linear else np.zeros((n + 1, 3, 3))
    Rvar = win.Rvar if win.Rvar.ndim == 3 else win.Rvar[:, None, :]
    c = carray
    model = (c(win.Phi), c(win.C), c(win.u_ref), c(np.broadcast_to(Rvar, (n + 1, S, 3))), c(Qa))
    lin = (linear, c(A_lin), c(U_lin))
    zc = c(z)
    # star images (a linear measurement of theta alone, opnav.approach.stars) between compiled stretches
    stars = [] if win.stars is None or win.star_y is None else [(int(k), i) for i, k in enumerate(win.stars.idx)]
    star_yw = win.star_yw
    k0 = 1
    for k, i in [*stars, (n, None)]:
        _augmented_samples(k0, k + 1, zc, model, lin, (y, P), (th_out, Pth_out, xf, ptr, ll))
        k0 = k + 1
        if i is None:
            continue
        G = win.stars.G[i] * ARCSEC  # per arcsec
        Wd = win.stars.w[i]
        J = np.einsum("ak,a,al->kl", G, Wd, G)
        P = carray(theta_information_update(P, np.broadcast_to(J, (S, 3, 3))))
        g = np.einsum("ak,a,sa->sk", G, Wd, star_yw[:, i] - y[:, 6:] @ G.T)
        y = carray(y + np.einsum("sij,sj->si", P[:, :, 6:], g))
        th_out[:, k], Pth_out[:, k], xf[:, k] = y[:, 6:], P[:, 6:, 6:], y[:, :6]
        ptr[:, k] = np.trace(P[:, :3, :3], axis1=1, axis2=2)
    return AugmentedResult(th_out * ARCSEC, Pth_out * ARCSEC**2, xf, ptr, ll)


def augmented_noise(Q: np.ndarray, q_theta: float) -> np.ndarray:
    """Process noise (..., 9, 9) of ``[dX; theta]``: ``Q (..., 6, 6)`` and ``q_theta I`` (theta's units squared)."""
    Q = np.asarray(Q)
    Qa = np.zeros(Q.shape[:-2] + (9, 9))
    Qa[..., :6, :6] = Q
    Qa[..., 6:, 6:] = np.eye(3) * q_theta
    return Qa


def augmented_jacobian(A: np.ndarray, C: np.ndarray, U: np.ndarray) -> np.ndarray:
    """``H = [-A_m C, 0_3x3, U]`` (..., 3, 9) of the augmented state ``[dX; theta]``,
    ``U = [u x]`` in the measurement's km per unit of theta (module docstring; compiled,
    the same :func:`_jacobian1` as the filter's)."""
    lead = kalman._lead(np.shape(A)[:-2], np.shape(C)[:-2], np.shape(U)[:-2])
    H = np.empty((math.prod(lead), 3, 9))
    _jacobian_batch(*(kalman._flat(a, lead, 2) for a in (A, C, U)), H)
    return H.reshape(lead + (3, 9))


@warms
def _warm() -> None:
    """The kernels once with the pipeline's argument types (the filter, its linear form)."""
    from .ekf import Window

    n1 = 3
    win = Window(np.broadcast_to(np.eye(6), (n1, 6, 6)).copy(), np.broadcast_to(np.eye(3), (n1, 3, 3)).copy(),
                 np.ones((n1, 3)), np.ones((n1, 3)), np.eye(6))
    run_augmented(np.zeros((1, n1, 3)), np.zeros((1, 6)), np.eye(6), np.zeros(3), 1e-4, win)
    run_augmented(np.zeros((1, n1, 3)), np.zeros((1, 6)), np.eye(6), np.zeros(3), 1e-4, win, u_lin=np.ones((n1, 3)))
    augmented_jacobian(np.eye(3), np.ones((2, 3, 3)), np.ones((2, 3, 3)))
