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

from dataclasses import dataclass

import numpy as np

from opnav.rotations import skew

from .dynamics import ARCSEC
from . import kalman
from .ekf import Window
from .stars import theta_information_update


@dataclass
class AugmentedResult:
    """Augmented-EKF output; index 0 of the time axis is the start sample."""

    theta: np.ndarray  # (S, n+1, 3) rad
    P_theta: np.ndarray  # (S, n+1, 3, 3) rad^2
    xf: np.ndarray  # (S, n+1, 6) filtered state deviation
    P_pos_trace: np.ndarray  # (S, n+1) km^2, trace of the position covariance
    loglik: np.ndarray  # (S,) innovation log-likelihood of the augmented filter


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
    F = np.eye(9)
    th_out = np.empty((S, n + 1, 3))
    Pth_out = np.empty((S, n + 1, 3, 3))
    xf = np.empty((S, n + 1, 6))
    ptr = np.empty((S, n + 1))

    def store(k):
        th_out[:, k] = y[:, 6:]
        Pth_out[:, k] = P[:, 6:, 6:]
        xf[:, k] = y[:, :6]
        ptr[:, k] = np.trace(P[:, :3, :3], axis1=1, axis2=2)

    store(0)
    ll = np.zeros(S)
    if u_lin is not None:
        A_lin = np.eye(3) - skew(y[0, 6:] * ARCSEC)
        U_lin = skew(np.asarray(u_lin, float)) * ARCSEC
    star_at = ({} if win.stars is None or win.star_y is None
               else {int(k): i for i, k in enumerate(win.stars.idx)})
    for k in range(1, n + 1):
        F[:6, :6] = win.Phi[k]
        y, P = kalman.predict(y, P, F, Qa)
        C = win.C[k]
        if u_lin is None:
            th = y[:, 6:] * ARCSEC
            A = np.eye(3) - skew(th)  # (S,3,3)
            u = win.u_ref[k] - y[:, :3] @ C.T  # (S,3)
            zhat = np.einsum("sij,sj->si", A, u)
            H = augmented_jacobian(A, C, skew(u) * ARCSEC)
        else:
            H = np.broadcast_to(augmented_jacobian(A_lin, C, U_lin[k]), (S, 3, 9))
            zhat = win.u_ref[k] + np.einsum("sij,sj->si", H, y)
        nu = z[:, k] - zhat
        y, P, _, Sinv, det = kalman.condition_on(y, P, H, win.Rvar[k], nu, joseph=True)
        ll += kalman.innovation_loglik(nu, Sinv, det)
        if k in star_at:  # a star image: a linear measurement of theta alone (opnav.approach.stars)
            i = star_at[k]
            G = win.stars.G[i] * ARCSEC  # per arcsec
            Wd = win.stars.w[i]
            J = np.einsum("ak,a,al->kl", G, Wd, G)
            P = theta_information_update(P, np.broadcast_to(J, (S, 3, 3)))
            g = np.einsum("ak,a,sa->sk", G, Wd, win.star_y[:, i] - y[:, 6:] @ G.T)
            y = y + np.einsum("sij,sj->si", P[:, :, 6:], g)
        store(k)
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
    ``U = [u x]`` in the measurement's km per unit of theta (module docstring)."""
    AC = -A @ C
    H = np.zeros(np.broadcast_shapes(AC.shape[:-2], np.shape(U)[:-2]) + (3, 9))
    H[..., :3] = AC
    H[..., 6:] = U
    return H
