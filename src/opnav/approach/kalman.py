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
_DIAG = [0, 1, 2]


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


def shared_left(F: np.ndarray, P: np.ndarray) -> np.ndarray:
    """``F @ P`` for one ``F (d, d)`` and a stack ``P (..., d, d)`` as a single matrix product
    (``F [P_1 P_2 ...]``), without one small product per member. For d = 6 (the EM-EKF's
    state) every entry is the stacked product's, bit for bit, with the pinned numpy's
    OpenBLAS (a test checks it); not for every size (d = 9 differs in the last bits), so
    only the 6-state filter and smoother use it."""
    if P.ndim == 2:
        return F @ P
    Pm = np.moveaxis(P, -2, 0)
    return np.moveaxis((F @ Pm.reshape(Pm.shape[0], -1)).reshape((F.shape[0],) + Pm.shape[1:]), 0, -2)


def shared_right(X: np.ndarray, G: np.ndarray) -> np.ndarray:
    """``X @ G`` for a stack ``X (..., a, d)`` and one ``G (d, e)`` as a single matrix product
    (rows of every member stacked); bit for bit the stacked product for d = 6 (see :func:`shared_left`)."""
    return (X.reshape(-1, X.shape[-1]) @ G).reshape(X.shape[:-1] + (G.shape[-1],))


def predict(m: np.ndarray | None, P: np.ndarray, F: np.ndarray, Q: np.ndarray, single: bool = False
            ) -> tuple[np.ndarray | None, np.ndarray]:
    """Time update ``(F m, F P F^T + Q)`` (module docstring); ``m`` may be None.
    ``F`` (d, d) is shared by the batch, or (..., d, d) one per batch member.
    ``single``: a shared ``F``'s products as single matrix products (:func:`shared_left`;
    the 6-state filter)."""
    Ft = _t(F)
    if m is not None:
        m = m @ Ft if F.ndim == 2 else (m[..., None, :] @ Ft)[..., 0, :]
    if single and F.ndim == 2:
        return m, shared_right(shared_left(F, P), Ft) + Q
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
    S[..., _DIAG, _DIAG] += rvar
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
