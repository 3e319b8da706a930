"""Rotation helpers shared by both papers: the cross-product matrix (hat), the
SO(3) exponential and logarithm, batched over leading dimensions.

Description
-----------
One home for the small-rotation algebra that both papers linearise with:

* :func:`skew` -- ``[a x]`` (the "hat" map), ``skew(a) @ b == cross(a, b)``;
* :func:`exp_so3` -- rotation matrix of a rotation vector (Rodrigues' formula),
  the *active* rotation ``Rotation.from_rotvec(phi).as_matrix()``;
* :func:`log_so3` -- its inverse, the rotation vector of a rotation matrix
  (angles below pi), ``Rotation.from_matrix(R).as_rotvec()``.

All three take arrays with any leading dimensions (``(..., 3)`` vectors,
``(..., 3, 3)`` matrices), e.g. runs x candidates x ..., and return the same
leading shape. They are written out (not through
``scipy.spatial.transform.Rotation``) because the filters call them in their
inner loops on single vectors, where scipy's object construction costs more
than the arithmetic, and because the batched paths want arbitrary leading
dimensions; Exp and Log are compiled kernels (:func:`exp_so3_into`,
:func:`log_so3_into`, which the landing filter's kernels call); tests pin them against scipy (``tests/test_rotations.py``).

Where they are used
-------------------
* Paper B (landing): error-state convention ``R_LtoB_true = Exp(-dtheta) @
  R_LtoB_est`` (``opnav.landing.measurement``); the bearing Jacobian's
  ``[rho x]`` / ``[b x]`` blocks (eq. 16, ``opnav.landing.measurement``); the
  EKF's transition matrix, attitude correction and landmark initialisation
  (``opnav.landing.ekf``); IMU synthesis and pre-integration
  (``opnav.landing.imu``); the attitude error of the descent
  (``opnav.landing.descent``, :func:`log_so3`); the CasADi cross-check
  (``opnav.landing.casadi_model``) writes the same model symbolically with
  ``casadi.skew`` and a Cayley map (symbolic only, it lives there).
* Paper A (approach): the small-angle misalignment ``A = I - [theta x]`` (eq. 5,
  ``opnav.approach.camera``), its sensitivity ``[u x]`` (``opnav.approach.crlb``)
  and the augmented filter's linearisation (``opnav.approach.augmented``), all
  by :func:`skew`. (The truth's exact misalignment ``Exp(-theta)``,
  ``camera.misalignment_exact``, is still scipy's ``Rotation``: the same
  rotation to round-off, left so paper A's simulated data keep their bits.)

Conventions: angles in rad; ``exp_so3`` is the active rotation (it rotates a
vector by ``|phi|`` about ``phi / |phi|``); ``log_so3(exp_so3(phi)) == phi``
for ``|phi| < pi``.
"""

from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel, warms

__all__ = ["skew", "cross", "exp_so3", "exp_so3_into", "log_so3", "log_so3_into"]

_EYE3 = np.eye(3)


def cross(a, b) -> np.ndarray:
    """``np.cross(a, b)`` of broadcast (..., 3) arrays, its arithmetic (``a1 b2 - a2
    b1``, ...: the same bits, tested) without its broadcasting copies: ~8x faster on
    the batched planner's runs x detected landmarks (measured, 10 x 7000)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def skew(a) -> np.ndarray:
    """Cross-product ("hat") matrix ``[a x]``: ``(..., 3) -> (..., 3, 3)``,
    ``skew(a) @ b == np.cross(a, b)``."""
    a = np.asarray(a, dtype=float)
    if a.ndim == 1:  # the filters' inner loop: one vector, minimal overhead
        a0, a1, a2 = a.tolist()
        return np.array([[0.0, -a2, a1], [a2, 0.0, -a0], [-a1, a0, 0.0]])
    S = np.zeros(a.shape[:-1] + (3, 3))
    S[..., 0, 1] = -a[..., 2]
    S[..., 0, 2] = a[..., 1]
    S[..., 1, 0] = a[..., 2]
    S[..., 1, 2] = -a[..., 0]
    S[..., 2, 0] = -a[..., 1]
    S[..., 2, 1] = a[..., 0]
    return S


@kernel
def exp_so3_into(phi, out) -> None:
    """``out`` (3, 3) <- ``Exp(phi)`` of one rotation vector ``phi`` (3,) (rad):
    Rodrigues' formula ``I + sin(t)/t K + (1 - cos t)/t^2 K^2``, ``K = [phi x]``,
    ``t = |phi|``, with ``K^2 = phi phi^T - t^2 I`` written per entry (second-order
    series below t = 1e-8). The one home of Exp: the filters' kernels call it,
    :func:`exp_so3` runs it over a batch."""
    p0, p1, p2 = phi[0], phi[1], phi[2]
    th2 = p0 * p0 + p1 * p1 + p2 * p2
    if th2 < 1e-16:
        a, c = 1.0, 0.5
    else:
        th = math.sqrt(th2)
        a, c = math.sin(th) / th, (1.0 - math.cos(th)) / th2
    out[0, 0] = 1.0 - c * (p1 * p1 + p2 * p2)
    out[1, 1] = 1.0 - c * (p0 * p0 + p2 * p2)
    out[2, 2] = 1.0 - c * (p0 * p0 + p1 * p1)
    out[0, 1] = -a * p2 + c * p0 * p1
    out[1, 0] = a * p2 + c * p0 * p1
    out[0, 2] = a * p1 + c * p0 * p2
    out[2, 0] = -a * p1 + c * p0 * p2
    out[1, 2] = -a * p0 + c * p1 * p2
    out[2, 1] = a * p0 + c * p1 * p2


@kernel
def _exp_batch(phi, out) -> None:
    for k in range(phi.shape[0]):
        exp_so3_into(phi[k], out[k])


@warms
def _warm() -> None:
    _exp_batch(np.zeros((1, 3)), np.empty((1, 3, 3)))
    _log_batch(np.eye(3)[None].copy(), np.empty((1, 3)))


def exp_so3(phi) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of rotation vectors ``phi`` ``(..., 3)``
    (rad), by the kernel :func:`exp_so3_into` over the leading dimensions (a single
    vector and a batch give the same bits)."""
    phi = np.asarray(phi, dtype=float)
    flat = np.array(phi, order="C").reshape(-1, 3)        # a writable copy: one kernel signature
    out = np.empty((flat.shape[0], 3, 3))
    _exp_batch(flat, out)
    return out.reshape(phi.shape[:-1] + (3, 3))


@kernel
def log_so3_into(R, out) -> None:
    """``out`` (3,) <- the rotation vector (rad) of one rotation matrix ``R`` (3, 3):
    angle ``atan2(|w|, (tr R - 1)/2)`` with ``w`` the axial vector of ``(R - R^T)/2``
    (accurate for small angles; angles near pi, where ``w`` vanishes, are not
    supported). The one home of Log: :func:`log_so3` runs it over a batch."""
    w0 = 0.5 * (R[2, 1] - R[1, 2])
    w1 = 0.5 * (R[0, 2] - R[2, 0])
    w2 = 0.5 * (R[1, 0] - R[0, 1])
    s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    f = 1.0 if s < 1e-12 else math.atan2(s, c) / s
    out[0], out[1], out[2] = w0 * f, w1 * f, w2 * f


@kernel
def _log_batch(R, out) -> None:
    for k in range(R.shape[0]):
        log_so3_into(R[k], out[k])


def log_so3(R) -> np.ndarray:
    """Rotation vectors ``(..., 3)`` (rad) of rotation matrices ``R`` ``(..., 3, 3)``:
    ``exp_so3(log_so3(R)) == R``, by the kernel :func:`log_so3_into` over the
    leading dimensions."""
    R = np.asarray(R, dtype=float)
    flat = np.array(R, order="C").reshape(-1, 3, 3)
    out = np.empty((flat.shape[0], 3))
    _log_batch(flat, out)
    return out.reshape(R.shape[:-2] + (3,))
