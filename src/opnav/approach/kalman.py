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


def inv_sym3(M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse and determinant of stacked symmetric 3x3 matrices ``M (..., 3, 3)``
    (cofactors; faster than ``numpy.linalg.inv`` for small stacks)."""
    a, b, c = M[..., 0, 0], M[..., 0, 1], M[..., 0, 2]
    d, e, f = M[..., 1, 1], M[..., 1, 2], M[..., 2, 2]
    A00, A01, A02 = d * f - e * e, c * e - b * f, b * e - c * d
    A11, A12, A22 = a * f - c * c, b * c - a * e, a * d - b * b
    det = a * A00 + b * A01 + c * A02
    out = np.empty_like(M)
    r = 1.0 / det
    out[..., 0, 0] = A00 * r
    out[..., 0, 1] = out[..., 1, 0] = A01 * r
    out[..., 0, 2] = out[..., 2, 0] = A02 * r
    out[..., 1, 1] = A11 * r
    out[..., 1, 2] = out[..., 2, 1] = A12 * r
    out[..., 2, 2] = A22 * r
    return out, det


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
    return m, F @ P @ Ft + Q


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
