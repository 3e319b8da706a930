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

    since ``-[theta x] u = [u x] theta``. The update uses the Joseph form.
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

from .camera import skew
from .dynamics import ARCSEC
from .ekf import LOG2PI, Window


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
    Qa = np.zeros((9, 9))
    Qa[:6, :6] = win.Q
    Qa[6:, 6:] = np.eye(3) * q_theta / ARCSEC**2
    F = np.eye(9)
    I9 = np.eye(9)
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
    for k in range(1, n + 1):
        F[:6, :6] = win.Phi[k]
        y = y @ F.T
        P = F @ P @ F.T + Qa
        C = win.C[k]
        H = np.zeros((S, 3, 9))
        if u_lin is None:
            th = y[:, 6:] * ARCSEC
            A = np.eye(3) - skew(th)  # (S,3,3)
            u = win.u_ref[k] - y[:, :3] @ C.T  # (S,3)
            zhat = np.einsum("sij,sj->si", A, u)
            H[:, :, :3] = -A @ C
            H[:, :, 6:] = skew(u) * ARCSEC
        else:
            H[:, :, :3] = -A_lin @ C
            H[:, :, 6:] = U_lin[k]
            zhat = win.u_ref[k] + np.einsum("sij,sj->si", H, y)
        nu = z[:, k] - zhat
        PHt = P @ H.transpose(0, 2, 1)  # (S,9,3)
        Sm = H @ PHt
        Sm[:, [0, 1, 2], [0, 1, 2]] += win.Rvar[k]
        Sinv = np.linalg.inv(Sm)
        K = PHt @ Sinv
        y = y + np.einsum("sij,sj->si", K, nu)
        IKH = I9 - K @ H
        P = IKH @ P @ IKH.transpose(0, 2, 1) + (K * win.Rvar[k]) @ K.transpose(0, 2, 1)
        P = 0.5 * (P + P.transpose(0, 2, 1))
        ll -= 0.5 * (np.linalg.slogdet(Sm)[1] + np.einsum("si,sij,sj->s", nu, Sinv, nu)
                     + 3.0 * LOG2PI)
        store(k)
    return AugmentedResult(th_out * ARCSEC, Pth_out * ARCSEC**2, xf, ptr, ll)
