"""Compensation that carries the misalignment's uncertainty: a Schmidt (consider) EKF (issue 44, item 4).

Description
    Compensating with an estimate ``theta_hat`` as if it were exact (the paper's step 4,
    :func:`opnav.approach.ekf.run_filter` with ``theta_hat``) leaves the filter's position
    covariance blind to the estimate's error ``theta - theta_hat``; that error moves every
    measurement sideways by about ``rho |theta - theta_hat|`` and the position NEES grows.
    The Schmidt-Kalman (consider) filter keeps ``theta`` in the covariance as a *consider*
    parameter, ``Y = [dX; theta]`` with ``P_tt`` = the estimate's covariance, and never
    updates it: the gain's theta rows are zero (Schmidt 1966; Tapley, Schutz & Born,
    *Statistical Orbit Determination*, sec. 6.3; Woodbury, Majji & Junkins 2011). The
    cross-covariance ``P_xt`` is propagated and updated, so the position covariance grows by
    what ``P_tt`` moves the data, and the mean is the compensated filter's.

    Measurement, as the EKF's (paper eq. 3, small-angle eq. 5), with the theta column of
    the augmented filter (:mod:`opnav.approach.augmented`)::

        z_k = A_m(theta_hat) (u_ref,k - C_k dr_k) + v_k,
        H_k = [ -A_m(theta_hat) C_k, 0_3x3, [u_k x] ],   u_k = u_ref,k - C_k dr_k(predicted).

    Update with the Schmidt gain ``K_s = [K_x; 0]`` in Joseph form,
    ``P+ = (I - K_s H) P (I - K_s H)^T + K_s R K_s^T`` (valid for any gain). Its blocks are
    those of the full Kalman update (gain ``K = [K_x; K_t] = P H^T S^-1``) but for the theta
    block, which the Schmidt update leaves at its prior: with ``K_x H P = K_x S K^T`` the
    Schmidt ``xx`` block is ``P_xx - K_x S K_x^T`` and its ``xt`` block ``P_xt - K_x H P_.t =
    P_xt - K_x S K_t^T``, the full update's (Tapley, Schutz & Born, sec. 6.3). So the update is
    paper A's one measurement update (:func:`opnav.approach.kalman.condition_on`, Joseph form)
    on ``[dX; theta]``, the theta mean kept at zero and ``P_tt`` put back: one home of the
    Kalman update (issue 56 item 3; the former hand-written update agreed to round-off, tested).
    Star images (``stars`` variant) are measurements of theta alone, which the consider
    filter does not update: they are not used here (the estimate already holds them).

    The estimate's covariance used (:func:`opnav.approach.cases.run_cases`): the squared
    1-sigma bound of the data that estimate used (:func:`opnav.approach.cases.label_bounds`,
    diagonal: the covariance an efficient estimate of that data would have) plus the squared
    distance of the estimate to that data's ML estimate (an EM iterate that stopped short of it
    carries that error too); no truth enters it.
Units: km, km/s, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.core.rotations import skew

from . import kalman
from .camera import misalignment_small
from .ekf import Window


@dataclass
class ConsiderResult:
    """Filtered deviations ``xf`` (S, n+1, 6) and their covariance ``Pf`` (S, n+1, 6, 6; None
    unless kept), the position block including the consider term, and the position NEES
    (S, n+1) when the truth was given (index 0 = the start)."""

    xf: np.ndarray
    Pf: np.ndarray | None
    nees_pos: np.ndarray | None = None


def run_consider(z: np.ndarray, theta_hat: np.ndarray, P_theta: np.ndarray, x0: np.ndarray, P0: np.ndarray,
                 win: Window, dx_true: np.ndarray | None = None, keep_cov: bool = True) -> ConsiderResult:
    """Schmidt EKF over a window for every seed (module docstring).

    z (S, n+1, 3) km (index 0 ignored); theta_hat (S, 3) rad; P_theta (S, 3, 3) or (3, 3) rad^2;
    x0 (S, 6); P0 (6, 6) or (S, 6, 6). ``P_theta = 0`` gives :func:`opnav.approach.ekf.run_filter`
    with ``theta_hat`` (tested). ``dx_true`` (n+1, 6): the truth, for the position NEES (a
    diagnostic computed on the fly); ``keep_cov=False`` keeps no covariance history (memory)."""
    z = np.asarray(z, float)
    S, n = z.shape[0], win.n
    th = np.broadcast_to(np.asarray(theta_hat, float), (S, 3))
    A = misalignment_small(th)  # (S, 3, 3)
    x = np.array(np.broadcast_to(x0, (S, 6)), float)
    P = np.zeros((S, 9, 9))
    P[:, :6, :6] = np.broadcast_to(P0, (S, 6, 6))
    P[:, 6:, 6:] = np.broadcast_to(P_theta, (S, 3, 3))
    Q = np.zeros((9, 9))
    Q[:6, :6] = win.Q
    Rvar = win.Rvar if win.Rvar.ndim == 3 else np.broadcast_to(win.Rvar[:, None, :], (n + 1, S, 3))
    F = np.eye(9)
    xf = np.empty((S, n + 1, 6))
    Pf = np.empty((S, n + 1, 6, 6)) if keep_cov else None
    nees = None if dx_true is None else np.empty((S, n + 1))

    def keep(k):
        xf[:, k] = x
        if keep_cov:
            Pf[:, k] = P[:, :6, :6]
        if nees is not None:
            e = x[:, :3] - dx_true[k, :3]
            nees[:, k] = np.einsum("si,si->s", e, np.linalg.solve(P[:, :3, :3], e[..., None])[..., 0])

    keep(0)
    H = np.zeros((S, 3, 9))
    m = np.zeros((S, 9))  # [dX; theta - theta_hat]: the theta part stays 0 (never updated)
    for k in range(1, n + 1):
        F[:6, :6] = win.Phi[k]
        x = x @ win.Phi[k].T
        P = F @ P @ F.T + Q
        u = win.u_ref[k] - x[:, :3] @ win.C[k].T  # (S, 3)
        H[:, :, :3] = -A @ win.C[k]
        H[:, :, 6:] = skew(u)  # -[theta x] u = [u x] theta
        nu = z[:, k] - np.einsum("sij,sj->si", A, u)
        m[:, :6] = x
        post = kalman.condition_on(m, P, H, Rvar[k], nu, joseph=True)
        x = post.m[:, :6]
        P_tt = P[:, 6:, 6:]
        P = post.P
        P[:, 6:, 6:] = P_tt  # Schmidt: theta is considered, never updated (module docstring)
        keep(k)
    return ConsiderResult(xf, Pf, nees)


def position_nees(xf: np.ndarray, Pf: np.ndarray, dx_true: np.ndarray) -> np.ndarray:
    """Position NEES (3 dof) over time, (S, n+1): ``e^T P_rr^-1 e``."""
    e = xf[:, :, :3] - dx_true[None, :, :3]
    return np.einsum("ski,ski->sk", e, np.linalg.solve(Pf[:, :, :3, :3], e[..., None])[..., 0])
