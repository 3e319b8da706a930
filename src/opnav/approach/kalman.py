"""The one Kalman predict and the one measurement update of paper A (eq. 6), batched over seeds.

Description
    Every filter of paper A is built from these two steps, as dynamax builds
    its filters from one ``_predict`` and one ``_condition_on``:

    * the EM-EKF (:func:`opnav.approach.ekf.run_filter`, paper eq. 6) and the
      prior propagated without data (:func:`opnav.approach.ekf.predict_only`);
    * the augmented EKF of ``[dX; theta]`` (:func:`opnav.approach.augmented.run_augmented`);
    * the Cramér-Rao bound recursion (:func:`opnav.approach.crlb.crlb_curve`),
      the covariance of the same augmented filter on the linear-Gaussian model.

    :func:`predict` (time update, eq. 6)::

        m_k|k-1 = F m_k-1,        P_k|k-1 = F P_k-1 F^T + Q

    :func:`condition_on` (measurement update with a diagonal noise ``R = diag(rvar)``
    and 3-vector measurements; ``H`` may cover only some state columns ``cols``,
    zeros elsewhere, e.g. the position block of the EKF)::

        S = H P H^T + R,   K = P H^T S^-1,   m = m + K nu
        P = P - K S K^T                        (standard form; ``joseph=False``)
        P = (I - K H) P (I - K H)^T + K R K^T  (Joseph form; ``joseph=True``)

    symmetrised as ``(P + P^T) / 2``. The innovation ``nu = z - h(m)`` is the
    caller's (it holds the measurement model). :func:`innovation_loglik` is the
    term of the prediction-error decomposition of the log-likelihood.

Shapes
    Leading axes ``...`` (seeds, windows, or none) broadcast: ``m (..., d)``,
    ``P (..., d, d)``, ``F (d, d)`` or ``(..., d, d)``, ``Q (d, d)``, ``H (..., 3, c)``, ``rvar (..., 3)``.
    ``m`` and ``nu`` may be ``None`` for a covariance-only recursion.
Units: those of the state and measurement (km, km/s; theta in rad or arcsec).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

LOG2PI = np.log(2.0 * np.pi)


_INV3_TERMS = np.array([[4, 2, 1, 0, 1, 0], [8, 5, 5, 8, 2, 4], [5, 1, 2, 2, 0, 1], [5, 8, 4, 2, 5, 1]])
_INV3_OUT = np.array([0, 1, 2, 1, 3, 4, 2, 4, 5])


def inv_sym3(M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse and determinant of stacked symmetric 3x3 matrices ``M (..., 3, 3)``
    (cofactors; faster than ``numpy.linalg.inv`` for small stacks).

    With ``M = [[a, b, c], [b, d, e], [c, e, f]]`` the six cofactors ``A00 = d f - e e``,
    ``A01 = c e - b f``, ``A02 = b e - c d``, ``A11 = a f - c c``, ``A12 = b c - a e``,
    ``A22 = a d - b b`` are formed as one ``X Y - U V`` over the six (the operands gathered
    from the flat matrix by ``_INV3_TERMS``), ``det = a A00 + b A01 + c A02`` (summed in
    that order) and ``M^-1 = A / det``."""
    flat = M.reshape(M.shape[:-2] + (9,))
    g = flat[..., _INV3_TERMS]  # (..., 4, 6): X, Y, U, V of the six cofactors
    cof = g[..., 0, :] * g[..., 1, :] - g[..., 2, :] * g[..., 3, :]
    p = flat[..., :3] * cof[..., :3]
    det = p[..., 0] + p[..., 1] + p[..., 2]
    return (cof * (1.0 / det)[..., None])[..., _INV3_OUT].reshape(M.shape), det


def _t(A: np.ndarray) -> np.ndarray:
    return A.mT


def predict(m: np.ndarray | None, P: np.ndarray, F: np.ndarray, Q: np.ndarray
            ) -> tuple[np.ndarray | None, np.ndarray]:
    """Time update ``(F m, F P F^T + Q)`` (module docstring); ``m`` may be None.
    ``F`` (d, d) is shared by the batch, or (..., d, d) one per batch member. (The stacked
    products of a shared ``F`` are faster here than one matrix product over the batch for
    the EM-EKF's 6 states and up to 100 seeds, and give the same bits.)"""
    Ft = _t(F)
    if m is not None:
        m = m @ Ft if F.ndim == 2 else (m[..., None, :] @ Ft)[..., 0, :]
    FP = F @ P
    if F.ndim == 2 and FP.ndim > 2:  # (F P) F^T of every batch member as one product (same bits)
        return m, (FP.reshape(-1, FP.shape[-1]) @ Ft).reshape(FP.shape) + Q
    return m, FP @ Ft + Q


class Update(NamedTuple):
    """Result of :func:`condition_on`: posterior ``m, P``, gain ``K (..., d, 3)``,
    inverse innovation covariance ``Sinv (..., 3, 3)`` and ``det S (...)``."""

    m: np.ndarray | None
    P: np.ndarray
    K: np.ndarray
    Sinv: np.ndarray
    det: np.ndarray


def condition_on(m: np.ndarray | None, P: np.ndarray, H: np.ndarray, rvar: np.ndarray,
                 nu: np.ndarray | None, cols: slice = slice(None), joseph: bool = False) -> Update:
    """Measurement update with innovation ``nu`` (module docstring).

    ``H (..., 3, c)`` multiplies the state columns ``cols`` (c of them); the
    other columns of the measurement Jacobian are zero.
    """
    PHt = P[..., :, cols] @ _t(H)  # (..., d, 3)
    S = H @ PHt[..., cols, :]
    Sd = S.view()
    Sd.shape = S.shape[:-2] + (9,)  # the flat view of a product (fails rather than copy)
    Sd[..., ::4] += rvar  # the diagonal
    Sinv, det = inv_sym3(S)
    K = PHt @ Sinv
    if m is not None:
        m = m + (K @ nu[..., None])[..., 0]
    if joseph:
        d = P.shape[-1]
        KH = np.zeros(np.broadcast_shapes(K.shape[:-2], P.shape[:-2]) + (d, d))
        KH[..., :, cols] = K @ H
        IKH = np.eye(d) - KH
        P = IKH @ P @ _t(IKH) + (K * np.asarray(rvar)[..., None, :]) @ _t(K)
    else:
        P = P - K @ _t(PHt)
    P = 0.5 * (P + _t(P))
    return Update(m, P, K, Sinv, det)


def innovation_loglik(nu: np.ndarray, Sinv: np.ndarray, det: np.ndarray) -> np.ndarray:
    """``-1/2 (log det S + nu^T S^-1 nu + 3 log 2 pi)`` per sample (...), the
    prediction-error decomposition term of the observed-data log-likelihood."""
    return -0.5 * (np.log(det) + np.einsum("...i,...ij,...j->...", nu, Sinv, nu) + 3.0 * LOG2PI)
