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

Jacobians (eq. 15-18), with ``rho = p_L - r_L``, ``u = rho / |rho|`` and
``b = R_LtoB u``::

    H_C = R_LtoB (|rho|^2 I - rho rho^T) / |rho|^3 = (R_LtoB - b u^T) / |rho|   (eq. 18)
    d b / d r_L     = -H_C                                   (eq. 15)
    d b / d dtheta  =  H_C [rho x] R_LtoB^T = [b x]          (eq. 16)
    d b / d p_L     =  H_C                                   (eq. 17)

(the second forms are identities: ``R (I - u u^T) = R - b u^T`` and
``R [u x] R^T = [R u x]`` with ``(I - u u^T)[u x] = [u x]``).

Landmark selection (paper B sec. 2.2, eq. 13-14 with n_s = n_p = 1): one known
landmark and one candidate unknown landmark give the stacked 6-vector
``z = [b_known; b_cand]`` and the 6 x 12 Jacobian (:func:`selection_jacobian`)
with respect to the error state ``[dr (3), dv (3), dtheta (3), dp_cand (3)]``
(eq. 5)::

    H = [[-H_C,k, 0, [b_k x], 0   ],
         [-H_C,c, 0, [b_c x], H_C,c]]

Tangent-plane form (:func:`tangent_jacobian`): a unit bearing has two degrees
of freedom, ``b^T H_C = 0`` and ``b^T [b x] = 0``, so the information a bearing
carries is that of ``T^T H`` with ``T = R_LtoB [t1, t2]`` (3 x 2) any orthonormal
basis orthogonal to ``b`` (``t1, t2`` orthogonal to ``u`` in {L}); then
``T^T H_C = [t1; t2]^T / |rho|`` and ``T^T [b x] = [-t2_B; t1_B]^T``
(``t_B = R_LtoB t``).

ONE home: every numpy evaluation of eq. 12 and 14-18 in the package is a
function of this module, batched over arbitrary leading dimensions (runs x
candidates x ...; inputs broadcast). The symbolic CasADi derivation
(:mod:`opnav.landing.casadi_model`) is its cross-check only
(tests/test_landing_metrics.py compares them; tests/test_landing_measurement.py
checks central differences). A single vector and a batch give the same bits.

Units: positions m, angles rad; the bearing is dimensionless; H_C and the
position / landmark columns 1/m, the attitude columns dimensionless (1/rad).
"""

from __future__ import annotations

import math

import numpy as np

from opnav.rotations import skew

__all__ = ["bearing", "bearing_jacobian", "jacobian_blocks", "selection_jacobian",
           "tangent_basis", "tangent_jacobian", "tangent_jacobian_scalar", "BehindCameraError",
           "N_STATE", "N_MEAS", "SL_R", "SL_V", "SL_THETA", "SL_P"]

#: column slices of the selection error state [dr, dv, dtheta, dp_cand] (eq. 5)
SL_R = slice(0, 3)
SL_V = slice(3, 6)
SL_THETA = slice(6, 9)
SL_P = slice(9, 12)
N_STATE = 12
#: rows of the stacked two-bearing measurement [b_known; b_cand] (eq. 13)
N_MEAS = 6


class BehindCameraError(ValueError):
    """The landmark coincides with the lander (zero range): no bearing exists."""


def _line_of_sight(r_L, p_L) -> tuple[np.ndarray, np.ndarray]:
    """``(u, 1/|rho|)``: unit line of sight (..., 3) and inverse range (...) (1/m)
    from ``r_L`` to ``p_L`` (broadcast)."""
    d = np.asarray(p_L, dtype=float) - np.asarray(r_L, dtype=float)
    # d0^2 + d1^2 + d2^2 left to right: the bits of np.sum over the 3-axis (numpy sums
    # fewer than 8 terms in order), without the reduction's overhead (3-5x, measured)
    rho = np.sqrt(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1] + d[..., 2] * d[..., 2])
    if not np.all(np.isfinite(rho)):
        raise ValueError(f"non-finite lander/landmark position: r_L={r_L}, p_L={p_L}")
    if np.any(rho == 0.0):
        raise BehindCameraError("landmark coincides with the lander: bearing undefined")
    inv = 1.0 / rho
    return d * inv[..., None], inv


def _rotate(R_LtoB, u) -> np.ndarray:
    """``R_LtoB @ u`` over leading dimensions (matmul: the same bits for one
    vector and for a batch)."""
    return (np.asarray(R_LtoB, dtype=float) @ u[..., None])[..., 0]


def bearing(r_L, R_LtoB, p_L) -> np.ndarray:
    """Unit line of sight from the lander at ``r_L`` to ``p_L``, in {B} (eq. 12).

    Parameters (broadcast over leading dimensions): ``r_L`` (..., 3) m,
    ``R_LtoB`` (..., 3, 3), ``p_L`` (..., 3) m. Returns (..., 3) unit vectors.
    Raises :class:`BehindCameraError` at zero range. Whether the landmark is
    inside the camera's field of view is not checked here (see
    ``opnav.landing.camera``).
    """
    u, _ = _line_of_sight(r_L, p_L)
    return _rotate(R_LtoB, u)


def jacobian_blocks(R_LtoB, u, inv_rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(b, H_C, [b x])`` from the unit line of sight ``u`` (..., 3) in {L} and
    the inverse range ``inv_rho`` (...) (1/m): the bearing (eq. 12), ``H_C =
    (R_LtoB - b u^T) / |rho|`` (eq. 18, 1/m) and the attitude block ``[b x]``
    (eq. 16), batched. The core of every function below (callers that already
    hold ``u`` and the range, e.g. the metrics' per-candidate path, call it
    directly)."""
    R = np.asarray(R_LtoB, dtype=float)
    if u.ndim == 1 and R.ndim == 2:  # one landmark (the metrics' per-candidate path): the
        b = R @ u                     # same operations without the broadcasting overhead
        return b, (R - b[:, None] * u[None, :]) * inv_rho, skew(b)
    b = _rotate(R, u)
    HC = (R - b[..., :, None] * u[..., None, :]) * np.asarray(inv_rho)[..., None, None]
    return b, HC, skew(b)


def bearing_jacobian(r_L, R_LtoB, p_L) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobians of :func:`bearing` (eq. 15-18), batched over leading dimensions.

    Returns ``(H_r, H_theta, H_p)``, each (..., 3, 3): derivatives with respect
    to the lander position ``r_L`` (1/m), the attitude error ``dtheta`` (body
    side, see the module docstring; dimensionless) and the landmark position
    ``p_L`` (1/m).
    """
    u, inv = _line_of_sight(r_L, p_L)
    _, HC, Sb = jacobian_blocks(R_LtoB, u, inv)
    return -HC, Sb, HC                                                # eq. 15, 16, 17


def selection_jacobian(r_L, R_LtoB, p_known_L, p_cand_L) -> np.ndarray:
    """The 6 x 12 Jacobian of ``[b_known; b_cand]`` (paper B eq. 13-18 with one
    known and one candidate landmark, sec. 2.2) with respect to ``[dr, dv,
    dtheta, dp_cand]``: (..., 6, 12), broadcast over leading dimensions (e.g.
    ``r_L`` (runs, 1, 3), ``R_LtoB`` (runs, 1, 3, 3), ``p_cand_L`` (runs, n, 3)
    -> (runs, n, 6, 12)). The velocity columns are zero (v enters no bearing)."""
    Hr_k, Ht_k, _ = bearing_jacobian(r_L, R_LtoB, p_known_L)
    Hr_c, Ht_c, Hp_c = bearing_jacobian(r_L, R_LtoB, p_cand_L)
    shape = np.broadcast_shapes(Hr_k.shape[:-2], Hr_c.shape[:-2])
    H = np.zeros(shape + (N_MEAS, N_STATE))
    H[..., 0:3, SL_R] = Hr_k
    H[..., 0:3, SL_THETA] = Ht_k
    H[..., 3:6, SL_R] = Hr_c
    H[..., 3:6, SL_THETA] = Ht_c
    H[..., 3:6, SL_P] = Hp_c
    return H


def tangent_basis(u) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal ``(t1, t2)`` (..., 3) orthogonal to the unit vectors ``u``
    (..., 3): ``t1 = u x a / |u x a|`` with ``a`` the {L} axis e_x if
    ``|u_z| > 0.9`` else e_z, ``t2 = u x t1`` (written out component by
    component: :func:`tangent_jacobian_scalar` repeats this arithmetic in floats)."""
    u = np.asarray(u, dtype=float)
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    use_x = np.abs(u2) > 0.9
    zero = np.zeros_like(u0)
    a0 = np.where(use_x, zero, u1)      # u x e_x = (0, u2, -u1); u x e_z = (u1, -u0, 0)
    a1 = np.where(use_x, u2, -u0)
    a2 = np.where(use_x, -u1, zero)
    na = 1.0 / np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    a0, a1, a2 = a0 * na, a1 * na, a2 * na
    t1 = np.stack([a0, a1, a2], axis=-1)
    t2 = np.stack([u1 * a2 - u2 * a1, u2 * a0 - u0 * a2, u0 * a1 - u1 * a0], axis=-1)
    return t1, t2


def _rotate_sum(R, t) -> np.ndarray:
    """``R @ t`` as ``sum_j R_ij t_j`` in index order (the bits of the float
    arithmetic of :func:`tangent_jacobian_scalar`), written out: the same bits
    as ``np.sum(R * t[..., None, :], axis=-1)`` and 4-5x faster (measured)."""
    return (R[..., :, 0] * t[..., 0, None] + R[..., :, 1] * t[..., 1, None]
            + R[..., :, 2] * t[..., 2, None])


def tangent_jacobian(r_L, R_LtoB, p_L, scale=1.0) -> np.ndarray:
    """``scale * T^T [H_r, 0, H_theta, H_p]`` (..., 2, 12): the candidate rows of
    :func:`selection_jacobian` projected on the tangent plane of its bearing
    (module docstring; ``T = R_LtoB [t1, t2]`` from :func:`tangent_basis`),
    batched over leading dimensions. ``scale`` (e.g. 1/sigma, rad^-1,
    broadcast) whitens the rows: the candidate's information is ``G^T G`` for
    ``G = tangent_jacobian(..., 1/sigma)`` when its bearing noise is ``sigma^2 I``."""
    u, inv = _line_of_sight(r_L, p_L)
    t1, t2 = tangent_basis(u)
    R = np.asarray(R_LtoB, dtype=float)
    t1B, t2B = _rotate_sum(R, t1), _rotate_sum(R, t2)
    sc = np.asarray(scale, dtype=float)
    q = (sc * inv)[..., None]
    sw = sc[..., None]
    G = np.zeros(np.broadcast_shapes(q.shape[:-1], t1B.shape[:-1]) + (2, N_STATE))
    G[..., 0, SL_R] = -q * t1             # T^T H_r = -T_L^T / |rho|   (eq. 15, 18)
    G[..., 0, SL_THETA] = -sw * t2B       # T^T [b x] = [-t2_B; t1_B]  (eq. 16)
    G[..., 0, SL_P] = q * t1              # T^T H_p = T_L^T / |rho|    (eq. 17, 18)
    G[..., 1, SL_R] = -q * t2
    G[..., 1, SL_THETA] = sw * t1B
    G[..., 1, SL_P] = q * t2
    return G


def tangent_jacobian_scalar(R_rows, d0: float, d1: float, d2: float, rho: float, scale: float
                            ) -> np.ndarray:
    """:func:`tangent_jacobian` (2, 12) of ONE candidate at offset ``d = p_L -
    r_L`` (m) with ``rho = |d|``, ``R_rows = R_LtoB.tolist()``, in float
    arithmetic: the same operations in the same order, so the same bits
    (tested, tests/test_landing_measurement.py). It exists for speed: the
    information metrics' golden-section path calls it once per candidate, and
    the array form costs ~10x more on a single vector (numpy call overhead;
    ``benchmarks/bench_metrics.py``, logdet ``seq_scalar``)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R_rows
    inv = 1.0 / rho
    u0, u1, u2 = d0 * inv, d1 * inv, d2 * inv
    if abs(u2) > 0.9:  # t1 = u x e_x
        a0, a1, a2 = 0.0, u2, -u1
    else:  # t1 = u x e_z
        a0, a1, a2 = u1, -u0, 0.0
    na = 1.0 / math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    a0, a1, a2 = a0 * na, a1 * na, a2 * na
    b0, b1, b2 = u1 * a2 - u2 * a1, u2 * a0 - u0 * a2, u0 * a1 - u1 * a0  # t2 = u x t1
    sw = scale
    q = scale * inv
    return np.array([
        [-q * a0, -q * a1, -q * a2, 0.0, 0.0, 0.0,
         -sw * (r00 * b0 + r01 * b1 + r02 * b2), -sw * (r10 * b0 + r11 * b1 + r12 * b2),
         -sw * (r20 * b0 + r21 * b1 + r22 * b2), q * a0, q * a1, q * a2],
        [-q * b0, -q * b1, -q * b2, 0.0, 0.0, 0.0,
         sw * (r00 * a0 + r01 * a1 + r02 * a2), sw * (r10 * a0 + r11 * a1 + r12 * a2),
         sw * (r20 * a0 + r21 * a1 + r22 * a2), q * b0, q * b1, q * b2],
    ])
