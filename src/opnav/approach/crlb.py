"""Cramér-Rao lower bound of the misalignment jointly with the unknown state (A-X1; SPEC A.3b).

Description
    The measurement model is linear in ``(dX, theta)`` to first order:

        z_k = H_k dX_k + U_k theta + v_k,  H_k = [-A_m C_k, 0],  U_k = [u_k x],

    with ``u_k = A_c^i,k (X_M - r_k)`` at the truth. With a Gaussian prior on
    the start state and process noise ``Q``, the Bayesian information of theta
    after marginalising every state is the inverse of the theta block of the
    posterior covariance of the augmented linear model. :func:`crlb_curve`
    computes it recursively with a covariance Kalman filter on ``[dX; theta]``
    (theta constant, a diffuse prior ``sigma_theta`` that carries no practical
    information, Joseph update); :func:`batch_crlb` builds the dense joint
    information matrix of ``X_0..X_n, theta`` and inverts it (small cases,
    used by the tests to check the recursion).

    The bound is a property of the data and the prior, not of the estimator:
    ``literal`` and ``prior`` share the measurement geometry (the literal
    filter start uses the same data again); ``roll`` changes the geometry;
    ``reference-start`` replaces the prior by knowledge of the true state
    (diagnostic).
Units: rad (bounds returned in rad, 1-sigma).
"""

from __future__ import annotations

import numpy as np

from opnav.core.rotations import skew

from . import kalman
from .augmented import augmented_jacobian, augmented_noise
from .camera import misalignment_small
from .ekf import Window
from .stars import theta_information_update


def theta_sensitivity(u: np.ndarray) -> np.ndarray:
    """dz/dtheta of the small-angle model, ``[u x]`` (n, 3, 3)."""
    return skew(u)


def crlb_curve(win: Window, u_true: np.ndarray, P_start: np.ndarray, theta: np.ndarray,
               sigma_theta: float = 1.0) -> np.ndarray:
    """1-sigma bound on theta after 0..n samples of ``win`` (n+1, 3), rad.

    ``u_true`` (n+1, 3): Mars vector in the calibrated camera frame at the truth.
    ``P_start``: covariance of the state at the window start (prior).
    """
    return crlb_curves(win.Phi[None], win.C[None], win.Rvar[None], win.Q, u_true[None],
                       np.asarray(P_start)[None], theta, sigma_theta)[0]


def crlb_curves(Phi: np.ndarray, C: np.ndarray, Rvar: np.ndarray, Q: np.ndarray, u_true: np.ndarray,
                P_start: np.ndarray, theta: np.ndarray, sigma_theta: float = 1.0,
                star_info: np.ndarray | None = None) -> np.ndarray:
    """:func:`crlb_curve` for a batch of B windows of equal length at once, (B, n+1, 3), rad.

    Phi (B, n+1, 6, 6), C (B, n+1, 3, 3), Rvar (B, n+1, 3), Q (6, 6), u_true (B, n+1, 3),
    P_start (B, 6, 6), theta (3,) or (B, 3) rad. The covariance recursion of the linear
    augmented Kalman filter of ``[dX; theta]`` (:func:`kalman.predict`,
    :func:`kalman.condition_on`, Joseph form), with theta constant. ``star_info``
    (B, n+1, 3, 3), rad^-2: information on theta of star images at each sample (``stars``
    variant), added to the theta block after that sample's Mars update.
    """
    B, n = Phi.shape[0], Phi.shape[1] - 1
    P = np.zeros((B, 9, 9))
    P[:, :6, :6] = P_start
    P[:, 6:, 6:] = sigma_theta**2 * np.eye(3)
    A = misalignment_small(theta)
    Qa = augmented_noise(Q, 0.0)
    Fa = np.broadcast_to(np.eye(9), (B, 9, 9)).copy()
    out = np.empty((B, n + 1, 3))
    out[:, 0] = np.sqrt(np.diagonal(P, axis1=1, axis2=2)[:, 6:])
    Us = theta_sensitivity(u_true)
    for k in range(1, n + 1):
        Fa[:, :6, :6] = Phi[:, k]
        _, P = kalman.predict(None, P, Fa, Qa)
        H = augmented_jacobian(A, C[:, k], Us[:, k])
        P = kalman.condition_on(None, P, H, Rvar[:, k], None, joseph=True).P
        if star_info is not None and star_info[:, k].any():
            P = theta_information_update(P, star_info[:, k])
        out[:, k] = np.sqrt(np.diagonal(P, axis1=1, axis2=2)[:, 6:])
    return out


def dense_information(win: Window, P0: np.ndarray, Hx: np.ndarray, Ht: np.ndarray | None = None,
                      sigma_theta: float | None = None, y: np.ndarray | None = None,
                      x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Joint information of ``X_0..X_n`` (and ``theta``) of the linear-Gaussian model

    ``X_0 ~ N(x0, P0)``, ``X_k = Phi_k X_{k-1} + w_k`` (``w ~ N(0, Q)``),
    ``y_k = Hx[k] r_k + Ht[k] theta + v_k`` (``v ~ N(0, diag Rvar[k])``), k = 1..n,
    with ``theta ~ N(0, sigma_theta^2 I)`` when ``Ht`` is given (appended last).

    Returns ``(J, h)``: the information matrix and linear term, so the posterior
    is ``N(J^-1 h, J^-1)`` (``h`` is zero where ``y``/``x0`` are not given).
    The dense reference for the recursive bound and the smoother tests.
    """
    n = win.n
    n_th = 0 if Ht is None else 3
    dim = 6 * (n + 1) + n_th
    J = np.zeros((dim, dim))
    h = np.zeros(dim)
    P0i = np.linalg.inv(P0)
    J[:6, :6] += P0i
    if x0 is not None:
        h[:6] += P0i @ x0
    if n_th:
        J[-3:, -3:] += np.eye(3) / sigma_theta**2
    Qi = np.linalg.inv(win.Q)
    for k in range(1, n + 1):
        D = np.zeros((6, dim))
        D[:, 6 * k:6 * k + 6] = np.eye(6)
        D[:, 6 * (k - 1):6 * k] = -win.Phi[k]
        J += D.T @ Qi @ D
        M = np.zeros((3, dim))
        M[:, 6 * k:6 * k + 3] = Hx[k]
        if n_th:
            M[:, -3:] = Ht[k]
        W = np.diag(1.0 / win.Rvar[k])
        J += M.T @ W @ M
        if y is not None:
            h += M.T @ W @ y[k]
    return J, h


def batch_crlb(win: Window, u_true: np.ndarray, P_start: np.ndarray, theta: np.ndarray,
               sigma_theta: float = 1.0) -> np.ndarray:
    """Same bound at n from the dense joint information of ``X_0..X_n, theta`` (3,), rad."""
    A = misalignment_small(theta)
    Hx = np.stack([-A @ C for C in win.C])
    J, _ = dense_information(win, P_start, Hx, theta_sensitivity(u_true), sigma_theta)
    cov = np.linalg.inv(J)
    return np.sqrt(np.diag(cov)[-3:])
