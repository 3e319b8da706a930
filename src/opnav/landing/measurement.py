"""Bearing measurement of a ground landmark and its Jacobian (paper B eq. 11-18).

Description
-----------
The camera measures the unit line-of-sight vector from the lander C to a
landmark p, expressed in the body frame {B} (paper B eq. 12)::

    b = R_LtoB (p_L - r_L) / || R_LtoB (p_L - r_L) ||

with ``r_L`` the lander position and ``p_L`` the landmark position in the
landing frame {L} (m), and ``R_LtoB`` the rotation matrix that maps a vector's
{L} components to its {B} components (``v_B = R_LtoB @ v_L``; the paper's
``C(q)``).

Error-state convention (ONE convention for the whole package)
-------------------------------------------------------------
Position, velocity and landmark errors are additive, ``x_true = x_est + dx``.
The attitude error ``dtheta`` (rad, 3-vector expressed in {B}) is a small
rotation applied on the body side::

    R_LtoB_true = Exp(-dtheta) @ R_LtoB_est  ~=  (I - [dtheta x]) @ R_LtoB_est

where ``Exp(phi) = opnav.rotations.exp_so3(phi)`` (= ``Rotation.from_rotvec(phi).as_matrix()``)
and ``[a x]`` is the cross-product matrix. Equivalently
``R_BtoL_true = R_BtoL_est @ Exp(dtheta)``. This is the paper's
``dq = q (x) q_hat^-1 ~= [dtheta/2, 1]`` with JPL quaternions, and it is the
convention under which the paper's eq. 16 holds as printed. The EKF corrects
its attitude with ``R_LtoB <- Exp(-dtheta_hat) @ R_LtoB``.

Jacobians (eq. 15-18), with ``rho = p_L - r_L`` and ``H_C = R_LtoB (|rho|^2 I
- rho rho^T) / |rho|^3`` (eq. 18)::

    d b / d r_L     = -H_C                         (eq. 15)
    d b / d dtheta  =  H_C [rho x] R_LtoB^T        (eq. 16)  (= N_B [R rho x])
    d b / d p_L     =  H_C                         (eq. 17)

These are pinned by finite-difference tests (tests/test_landing_measurement.py).

Units: positions m, angles rad; the bearing is dimensionless.
"""

from __future__ import annotations

import numpy as np

from opnav.rotations import skew

__all__ = ["bearing", "bearing_jacobian", "BehindCameraError"]


class BehindCameraError(ValueError):
    """The landmark coincides with the lander (zero range): no bearing exists."""


def _rho(r_L: np.ndarray, p_L: np.ndarray) -> np.ndarray:
    rho = np.asarray(p_L, dtype=float) - np.asarray(r_L, dtype=float)
    n = float(np.linalg.norm(rho))
    if not np.isfinite(n):
        raise ValueError(f"non-finite lander/landmark position: r_L={r_L}, p_L={p_L}")
    if n == 0.0:
        raise BehindCameraError("landmark coincides with the lander: bearing undefined")
    return rho


def bearing(r_L: np.ndarray, R_LtoB: np.ndarray, p_L: np.ndarray) -> np.ndarray:
    """Unit line of sight from the lander at ``r_L`` to ``p_L``, in {B} (eq. 12).

    Parameters: ``r_L`` (3,) m, ``R_LtoB`` (3, 3), ``p_L`` (3,) m.
    Returns the (3,) unit vector. Raises :class:`BehindCameraError` at zero range.
    Whether the landmark is inside the camera's field of view is not checked
    here (see ``opnav.landing.camera``).
    """
    rho = _rho(r_L, p_L)
    rb = np.asarray(R_LtoB, dtype=float) @ rho
    return rb / np.linalg.norm(rb)


def bearing_jacobian(r_L: np.ndarray, R_LtoB: np.ndarray, p_L: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobians of :func:`bearing` (eq. 15-18).

    Returns ``(H_r, H_theta, H_p)``, each (3, 3): derivatives with respect to
    the lander position ``r_L`` (m), the attitude error ``dtheta`` (rad, body
    side, see the module docstring) and the landmark position ``p_L`` (m).
    """
    R = np.asarray(R_LtoB, dtype=float)
    rho = _rho(r_L, p_L)
    n = float(np.linalg.norm(rho))
    H_C = R @ ((n * n) * np.eye(3) - np.outer(rho, rho)) / n**3      # eq. 18
    H_theta = H_C @ skew(rho) @ R.T                                   # eq. 16
    return -H_C, H_theta, H_C                                         # eq. 15, 17
