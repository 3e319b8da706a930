"""Paper B's depth estimation error (eq. 19-25), compiled.

The lander observes a landmark twice, ``t_s`` apart. The estimated baseline is
``b = |v t_s + a t_s^2 / 2|`` (eq. 19), its error a ball of radius ``r_e = eps_v t_s``
(eq. 21-22), ``eps_v = n_sigma sqrt(max eig P_vv)`` a bound on the velocity error from the
filter's covariance. A landmark at range ``d`` seen at ``beta`` from the velocity then has
``|r^(k+s)| = sqrt(b^2 + d^2 - 2 b d cos beta)`` (eq. 25), ``sin theta = b sin beta /
|r^(k+s)|`` (eq. 24) and depth error ``dr = 2 r_e / sin theta`` (eq. 23). The paper's own
vectorised form (law of sines over beta and alpha) is ``reference.depth_error``, tested equal.
Units: m, s, rad.
"""
from __future__ import annotations

import math

from opnav.core.compiled import kernel


@kernel
def max_eig_sym3(A) -> float:
    """Largest eigenvalue of the symmetric part of a 3 x 3 matrix (trigonometric closed form)."""
    a00, a11, a22 = A[0, 0], A[1, 1], A[2, 2]
    a01, a02, a12 = 0.5 * (A[0, 1] + A[1, 0]), 0.5 * (A[0, 2] + A[2, 0]), 0.5 * (A[1, 2] + A[2, 1])
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    m = (a00 + a11 + a22) / 3.0
    if p1 <= 1e-30 * max(1.0, m * m):
        return max(a00, a11, a22)
    d0, d1, d2 = a00 - m, a11 - m, a22 - m
    p = math.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1) / 6.0)
    b00, b11, b22, b01, b02, b12 = d0 / p, d1 / p, d2 / p, a01 / p, a02 / p, a12 / p
    det = (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02)
           + b02 * (b01 * b12 - b11 * b02))
    return m + 2.0 * p * math.cos(math.acos(max(-1.0, min(1.0, det / 2.0))) / 3.0)


@kernel
def baseline(v, a, t_s) -> float:
    """Eq. 19: estimated baseline |v t_s + a t_s^2 / 2| (m) from velocity v (m/s),
    acceleration a (m/s^2) over t_s (s)."""
    h = 0.5 * t_s * t_s
    b2 = 0.0
    for i in range(3):
        x = v[i] * t_s + a[i] * h
        b2 += x * x
    return math.sqrt(b2)


@kernel
def error_radius(P_vv, t_s, n_sigma) -> float:
    """Eq. 21-22: error-ball radius r_e = eps_v t_s (m), eps_v = n_sigma sqrt(max eig
    P_vv) (m/s) of the (symmetrised) velocity covariance P_vv (3 x 3, m^2/s^2)."""
    return n_sigma * math.sqrt(max(max_eig_sym3(P_vv), 0.0)) * t_s


@kernel
def depth_error(d, cb, sb, b, r_e) -> float:
    """Eq. 23-25: depth estimation error (m) of a landmark at range d (m) seen at
    beta from the velocity (cos, sin), baseline b (m) > 0, error radius r_e (m);
    +inf without parallax (sin beta <= 0 or |r^(k+s)| = 0)."""
    rks = math.sqrt(max(b * b + d * d - 2.0 * b * d * cb, 0.0))   # eq. 25
    if sb <= 0.0 or rks <= 0.0:
        return math.inf
    return (2.0 * r_e / b) * rks / sb                              # eq. 23-24
