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

where ``Exp(phi) = opnav.core.rotations.exp_so3(phi)`` (= ``Rotation.from_rotvec(phi).as_matrix()``)
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

ONE home: eq. 12 and 15-18 are written once, as compiled kernels over one
landmark (``opnav.core.compiled.kernel``): :func:`line_of_sight` (u, 1/|rho|),
:func:`blocks` (b and H_C) and :func:`tangent_rows` (the tangent-plane rows).
The filter's kernels (``opnav.landing.ekf``) and the planner's call them
directly; the Python functions below run them over arbitrary leading dimensions
(runs x candidates x ...; inputs broadcast). The symbolic CasADi derivation
(:mod:`opnav.landing.casadi_model`) is the reference
(tests/test_landing_metrics.py compares them; tests/test_landing_measurement.py
checks central differences and the printed forms of eq. 12 and 18). A single
vector and a batch give the same bits.

Units: positions m, angles rad; the bearing is dimensionless; H_C and the
position / landmark columns 1/m, the attitude columns dimensionless (1/rad).
"""

from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel, warms
from opnav.core.rotations import skew

__all__ = ["line_of_sight", "blocks", "tangent_rows", "bearing", "bearing_jacobian", "selection_jacobian",
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


# ---------------------------------------------------------------- kernels (the one home)

@kernel
def line_of_sight(r_L, p_L, u) -> float:
    """Unit line of sight ``u`` (3,) <- ``(p_L - r_L) / |p_L - r_L|`` from ``r_L``
    to ``p_L`` (3,) m; returns the inverse range ``1/|rho|`` (1/m): 0.0 at zero
    range, NaN if a coordinate is not finite (``u`` then unset)."""
    d0 = p_L[0] - r_L[0]
    d1 = p_L[1] - r_L[1]
    d2 = p_L[2] - r_L[2]
    rho = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if not math.isfinite(rho):
        return math.nan
    if rho == 0.0:
        return 0.0
    inv = 1.0 / rho
    u[0] = d0 * inv
    u[1] = d1 * inv
    u[2] = d2 * inv
    return inv


@kernel
def blocks(R_LtoB, u, inv_rho, b, HC) -> None:
    """The bearing ``b = R_LtoB u`` (eq. 12) and ``H_C = (R_LtoB - b u^T) / |rho|``
    (eq. 18, 1/m) into ``b`` (3,) and ``HC`` (3, 3), from the unit line of sight
    ``u`` (3,) in {L} and the inverse range (1/m). With them eq. 15-17 are
    ``-H_C``, ``[b x]`` and ``H_C``."""
    for i in range(3):
        b[i] = R_LtoB[i, 0] * u[0] + R_LtoB[i, 1] * u[1] + R_LtoB[i, 2] * u[2]
    for i in range(3):
        for j in range(3):
            HC[i, j] = (R_LtoB[i, j] - b[i] * u[j]) * inv_rho


@kernel
def _bearing_batch(r, R, p, b, HC) -> int:
    """:func:`line_of_sight` and :func:`blocks` over ``n`` rows (r (n, 3), R (n, 3,
    3), p (n, 3) -> b (n, 3), HC (n, 3, 3)); returns 0, 1 (zero range) or 2
    (not finite) at the first bad row."""
    u = np.empty(3)
    for k in range(r.shape[0]):
        inv = line_of_sight(r[k], p[k], u)
        if not inv == inv:
            return 2
        if inv == 0.0:
            return 1
        blocks(R[k], u, inv, b[k], HC[k])
    return 0


@warms
def _warm() -> None:
    r = np.zeros((1, 3))
    p = np.ones((1, 3))
    _bearing_batch(r, np.eye(3)[None].copy(), p, np.empty((1, 3)), np.empty((1, 3, 3)))
    G = np.empty((1, 2, N_STATE))
    _tangent_batch(np.eye(3)[None].copy(), p, np.ones(1), G)
    tangent_rows(np.eye(3), p[0], 1.0, G[0])
    _basis_batch(p, np.empty((1, 3)), np.empty((1, 3)))
    blocks(np.eye(3), p[0], 1.0, np.empty(3), np.empty((3, 3)))


def _flat(a: np.ndarray, shape: tuple, tail: tuple) -> np.ndarray:
    """``a`` broadcast to ``shape + tail`` as contiguous writable rows (n, *tail) (no
    copy when it already is)."""
    if a.shape != shape + tail or not (a.flags.c_contiguous and a.flags.writeable):
        a = np.array(np.broadcast_to(a, shape + tail), order="C")   # writable: one kernel signature
    return a.reshape((-1,) + tail)


def _rows(r_L, R_LtoB, p_L):
    """Broadcast ``(r_L, R_LtoB, p_L)`` over their leading dimensions and flatten
    them to rows: ``(shape, r (n, 3), R (n, 3, 3), p (n, 3))``."""
    r = np.asarray(r_L, dtype=float)
    R = np.asarray(R_LtoB, dtype=float)
    p = np.asarray(p_L, dtype=float)
    shape = np.broadcast_shapes(r.shape[:-1], R.shape[:-2], p.shape[:-1])
    return shape, _flat(r, shape, (3,)), _flat(R, shape, (3, 3)), _flat(p, shape, (3,))


def _evaluate(r_L, R_LtoB, p_L) -> tuple[np.ndarray, np.ndarray]:
    """``(b, H_C)`` (..., 3), (..., 3, 3) of eq. 12 and 18 by the kernels, broadcast."""
    shape, r, R, p = _rows(r_L, R_LtoB, p_L)
    b = np.empty(r.shape)
    HC = np.empty(R.shape)
    status = _bearing_batch(r, R, p, b, HC)
    if status == 2:
        raise ValueError(f"non-finite lander/landmark position: r_L={r_L}, p_L={p_L}")
    if status == 1:
        raise BehindCameraError("landmark coincides with the lander: bearing undefined")
    return b.reshape(shape + (3,)), HC.reshape(shape + (3, 3))


def bearing(r_L, R_LtoB, p_L) -> np.ndarray:
    """Unit line of sight from the lander at ``r_L`` to ``p_L``, in {B} (eq. 12).

    Parameters (broadcast over leading dimensions): ``r_L`` (..., 3) m,
    ``R_LtoB`` (..., 3, 3), ``p_L`` (..., 3) m. Returns (..., 3) unit vectors.
    Raises :class:`BehindCameraError` at zero range. Whether the landmark is
    inside the camera's field of view is not checked here (see
    ``opnav.landing.camera``).
    """
    return _evaluate(r_L, R_LtoB, p_L)[0]


def bearing_jacobian(r_L, R_LtoB, p_L) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobians of :func:`bearing` (eq. 15-18), batched over leading dimensions.

    Returns ``(H_r, H_theta, H_p)``, each (..., 3, 3): derivatives with respect
    to the lander position ``r_L`` (1/m), the attitude error ``dtheta`` (body
    side, see the module docstring; dimensionless) and the landmark position
    ``p_L`` (1/m).
    """
    b, HC = _evaluate(r_L, R_LtoB, p_L)
    return -HC, skew(b), HC                                           # eq. 15, 16, 17


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


@kernel
def _basis(u0, u1, u2):
    """Orthonormal ``(t1, t2)`` orthogonal to the unit vector ``u`` (as two
    3-tuples): ``t1 = u x a / |u x a|`` with ``a`` the {L} axis e_x if
    ``|u_z| > 0.9`` else e_z, ``t2 = u x t1``."""
    if abs(u2) > 0.9:  # t1 = u x e_x
        a0, a1, a2 = 0.0, u2, -u1
    else:  # t1 = u x e_z
        a0, a1, a2 = u1, -u0, 0.0
    na = 1.0 / math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    a0, a1, a2 = a0 * na, a1 * na, a2 * na
    return (a0, a1, a2), (u1 * a2 - u2 * a1, u2 * a0 - u0 * a2, u0 * a1 - u1 * a0)


@kernel
def tangent_rows(R_LtoB, d, scale, G) -> None:
    """``G`` (2, 12) <- ``scale * T^T [H_r, 0, H_theta, H_p]`` of ONE landmark at
    offset ``d = p_L - r_L`` (3,) m from the lander (module docstring: the
    candidate rows of eq. 15-18 on the tangent plane of the bearing, ``T =
    R_LtoB [t1, t2]``); ``scale`` (e.g. 1/sigma, rad^-1) whitens the rows. The
    one home of the tangent-plane form: :func:`tangent_jacobian` runs it over a
    batch, the planner's kernels call it per candidate."""
    rho = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    inv = 1.0 / rho
    u0, u1, u2 = d[0] * inv, d[1] * inv, d[2] * inv
    (a0, a1, a2), (b0, b1, b2) = _basis(u0, u1, u2)
    q = scale * inv
    R = R_LtoB
    G[0, 0], G[0, 1], G[0, 2] = -q * a0, -q * a1, -q * a2          # T^T H_r = -T_L^T / |rho|
    G[1, 0], G[1, 1], G[1, 2] = -q * b0, -q * b1, -q * b2
    for c in range(3, 6):
        G[0, c] = 0.0
        G[1, c] = 0.0
    for i in range(3):                                               # T^T [b x] = [-t2_B; t1_B]
        G[0, 6 + i] = -scale * (R[i, 0] * b0 + R[i, 1] * b1 + R[i, 2] * b2)
        G[1, 6 + i] = scale * (R[i, 0] * a0 + R[i, 1] * a1 + R[i, 2] * a2)
    G[0, 9], G[0, 10], G[0, 11] = q * a0, q * a1, q * a2            # T^T H_p = T_L^T / |rho|
    G[1, 9], G[1, 10], G[1, 11] = q * b0, q * b1, q * b2


@kernel
def _tangent_batch(R, d, scale, G) -> None:
    for k in range(d.shape[0]):
        tangent_rows(R[k], d[k], scale[k], G[k])


@kernel
def _basis_batch(u, t1, t2) -> None:
    for k in range(u.shape[0]):
        (t1[k, 0], t1[k, 1], t1[k, 2]), (t2[k, 0], t2[k, 1], t2[k, 2]) = _basis(u[k, 0], u[k, 1], u[k, 2])


def tangent_basis(u) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal ``(t1, t2)`` (..., 3) orthogonal to the unit vectors ``u``
    (..., 3) (the kernel :func:`tangent_rows`' basis: ``t1 = u x a / |u x a|``
    with ``a`` the {L} axis e_x if ``|u_z| > 0.9`` else e_z, ``t2 = u x t1``)."""
    u = np.asarray(u, dtype=float)
    flat = np.ascontiguousarray(u).reshape(-1, 3)
    t1, t2 = np.empty(flat.shape), np.empty(flat.shape)
    _basis_batch(flat, t1, t2)
    return t1.reshape(u.shape), t2.reshape(u.shape)


def tangent_jacobian(r_L, R_LtoB, p_L, scale=1.0) -> np.ndarray:
    """``scale * T^T [H_r, 0, H_theta, H_p]`` (..., 2, 12): the candidate rows of
    :func:`selection_jacobian` projected on the tangent plane of its bearing
    (module docstring; ``T = R_LtoB [t1, t2]`` from :func:`tangent_basis`),
    batched over leading dimensions by the kernel :func:`tangent_rows`. ``scale``
    (e.g. 1/sigma, rad^-1, broadcast) whitens the rows: the candidate's
    information is ``G^T G`` for ``G = tangent_jacobian(..., 1/sigma)`` when its
    bearing noise is ``sigma^2 I``. Raises like :func:`bearing` at zero range."""
    r = np.asarray(r_L, dtype=float)
    p = np.asarray(p_L, dtype=float)
    R = np.asarray(R_LtoB, dtype=float)
    sc = np.asarray(scale, dtype=float)
    shape = np.broadcast_shapes(r.shape[:-1], p.shape[:-1], R.shape[:-2], sc.shape)
    d = _flat(p - r, shape, (3,))
    rho2 = np.einsum("ni,ni->n", d, d)
    if not np.all(np.isfinite(rho2)):
        raise ValueError(f"non-finite lander/landmark position: r_L={r_L}, p_L={p_L}")
    if np.any(rho2 == 0.0):
        raise BehindCameraError("landmark coincides with the lander: bearing undefined")
    G = np.empty((d.shape[0], 2, N_STATE))
    _tangent_batch(_flat(R, shape, (3, 3)), d, _flat(sc, shape, ()), G)
    return G.reshape(shape + (2, N_STATE))


def tangent_jacobian_scalar(R_rows, d0: float, d1: float, d2: float, rho: float, scale: float
                            ) -> np.ndarray:
    """:func:`tangent_jacobian` (2, 12) of ONE candidate at offset ``d = p_L -
    r_L`` (m), ``R_rows = R_LtoB.tolist()`` (``rho`` unused: the kernel
    :func:`tangent_rows` computes it). Kept for the metrics' per-candidate
    path until it calls :func:`tangent_rows` from its own kernels."""
    G = np.empty((2, N_STATE))
    tangent_rows(np.array(R_rows), np.array([d0, d1, d2]), float(scale), G)
    return G
