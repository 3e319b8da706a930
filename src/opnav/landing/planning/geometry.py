"""The plane holding the velocity, the line of sight's ground point (eq. 26) and the
visible interval of paper B's planner (sec. 2.2), and the plane as numpy sees it
(:class:`PlaneGeometry`, :func:`plane_geometry`, :func:`ground_points`).

Planning works in the vertical plane through the lander C that holds the velocity, with a
*signed* beta: ``beta > 0`` rotates the line of sight from the velocity toward the horizon
(landmarks beyond D, the velocity line's ground point: ``alpha = pi - gamma``), ``beta < 0``
toward the nadir (``alpha = gamma``), ``gamma`` the flight-path angle below the horizon.
Units: m, rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from opnav.core.compiled import kernel
from opnav.landing.planning.layout import (NOT_ABOVE, NOT_DESCENDING, NQ, OK, Q_C, Q_CD, Q_GAMMA, Q_VHAT,
                                           Q_WHAT, REASONS, ZERO_VELOCITY, DegenerateGeometry)


@kernel
def plane(r, v, q) -> int:
    """Fill the plane's slots of q (``Q_C`` ... ``Q_GAMMA``) from position r (m) and velocity v
    (m/s); returns a status (0: ok). A vertical velocity takes the plane through {L} +x."""
    sp = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if not (sp >= 1e-9) or not math.isfinite(sp):
        return ZERO_VELOCITY
    if not (r[2] > 0):
        return NOT_ABOVE
    a0, a1, a2 = v[0] / sp, v[1] / sp, v[2] / sp
    if a2 >= 0:
        return NOT_DESCENDING
    nh = math.hypot(a0, a1)
    h0, h1 = (1.0, 0.0) if nh < 1e-9 else (a0 / nh, a1 / nh)
    hv = h0 * a0 + h1 * a1
    w0, w1, w2 = h0 - hv * a0, h1 - hv * a1, -hv * a2
    nw = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    for i in range(3):
        q[Q_C + i] = r[i]
    q[Q_VHAT], q[Q_VHAT + 1], q[Q_VHAT + 2] = a0, a1, a2
    q[Q_WHAT], q[Q_WHAT + 1], q[Q_WHAT + 2] = w0 / nw, w1 / nw, w2 / nw
    q[Q_CD] = r[2] / -a2
    q[Q_GAMMA] = math.asin(min(1.0, -a2))
    return OK


@kernel
def plane_depth(beta, q) -> float:
    """Range (m) to the ground along the line of sight at signed beta (rad) in the
    plane q, law of sines ``|CD| sin(alpha) / sin(alpha + |beta|)``; +inf where it
    misses the ground or beta = 0."""
    g = q[Q_GAMMA]
    alpha = math.pi - g if beta > 0 else g
    s = math.sin(alpha + abs(beta))
    if beta == 0.0 or alpha + abs(beta) >= math.pi or s <= 0.0:
        return math.inf
    return q[Q_CD] * math.sin(alpha) / s


@kernel
def ground_point(beta, q):
    """Eq. 26: (hit, x, y, z) (m) of the line of sight at signed beta (rad) in the plane q."""
    d = plane_depth(beta, q)
    if d == math.inf:
        return False, 0.0, 0.0, 0.0
    cb, sb = math.cos(beta), math.sin(beta)
    return (True, q[Q_C] + d * (cb * q[Q_VHAT] + sb * q[Q_WHAT]),
            q[Q_C + 1] + d * (cb * q[Q_VHAT + 1] + sb * q[Q_WHAT + 1]),
            q[Q_C + 2] + d * (cb * q[Q_VHAT + 2] + sb * q[Q_WHAT + 2]))


@kernel
def visible_interval(q, M, k):
    """(n, lo0, hi0, lo1, hi1): the n <= 2 sub-intervals of signed beta (rad) whose
    lines of sight u = cos(beta) v_hat + sin(beta) w_hat meet the ground inside the
    field of view, negative side first. M = R_BtoC R_LtoB; k = (half width -
    margin) / focal (tangent of the half field of view). Each side plane of the
    square field of view (k z -+ x > 0, k z -+ y > 0 in camera axes) and the ground
    (u_z < 0) is an open half circle of directions centred at phi_i; they meet
    unless the centres do not fit in an arc shorter than pi, in
    (max phi_i - pi/2, min phi_i + pi/2)."""
    if k <= 0:
        return 0, 0.0, 0.0, 0.0, 0.0
    A = np.empty(3)
    C = np.empty(3)
    for i in range(3):
        A[i] = M[i, 0] * q[Q_VHAT] + M[i, 1] * q[Q_VHAT + 1] + M[i, 2] * q[Q_VHAT + 2]
        C[i] = M[i, 0] * q[Q_WHAT] + M[i, 1] * q[Q_WHAT + 1] + M[i, 2] * q[Q_WHAT + 2]
    pi = math.pi
    phis = np.sort(np.array([math.atan2(k * C[2] - C[0], k * A[2] - A[0]),
                             math.atan2(k * C[2] + C[0], k * A[2] + A[0]),
                             math.atan2(k * C[2] - C[1], k * A[2] - A[1]),
                             math.atan2(k * C[2] + C[1], k * A[2] + A[1]), q[Q_GAMMA] - pi / 2]))
    j, gap = 4, phis[0] + 2 * pi - phis[4]          # the widest gap, first on ties
    for i in (3, 2, 1, 0):
        if phis[i + 1] - phis[i] >= gap:
            j, gap = i, phis[i + 1] - phis[i]
    if gap <= pi:
        return 0, 0.0, 0.0, 0.0, 0.0
    b0 = (phis[j] + 2 * pi if j < 4 else phis[4]) - pi / 2
    b1 = phis[(j + 1) % 5] + pi / 2
    shift = 2 * pi * round((q[Q_GAMMA] - pi / 2 - 0.5 * (b0 + b1)) / (2 * pi))  # into (-(pi - g), g)
    b0, b1 = b0 + shift + 1e-12, b1 + shift - 1e-12
    n, lo0, hi0, lo1, hi1 = 0, 0.0, 0.0, 0.0, 0.0
    eps = 1e-9                                       # split at beta = 0 (no parallax)
    if b0 < 0 and min(b1, -eps) > b0:
        n, lo0, hi0 = 1, b0, min(b1, -eps)
    if b1 > 0 and b1 > max(b0, eps):
        if n == 0:
            lo0, hi0 = max(b0, eps), b1
        else:
            lo1, hi1 = max(b0, eps), b1
        n += 1
    return n, lo0, hi0, lo1, hi1


@dataclass(frozen=True)
class PlaneGeometry:
    """The vertical plane holding the velocity (all in {L}, m): :func:`plane`'s slots of q
    as named fields; :attr:`q` gives them back as a q vector (``layout.NQ``)."""

    C: np.ndarray          # lander position
    v_hat: np.ndarray      # unit velocity
    w_hat: np.ndarray      # unit, in-plane, perpendicular to v_hat, toward the horizon side
    cd: float              # |CD|, m
    gamma: float           # flight-path angle below the horizon, rad (0, pi/2]

    @property
    def q(self) -> np.ndarray:
        q = np.zeros(NQ)
        q[Q_C:Q_C + 3], q[Q_VHAT:Q_VHAT + 3], q[Q_WHAT:Q_WHAT + 3] = self.C, self.v_hat, self.w_hat
        q[Q_CD], q[Q_GAMMA] = self.cd, self.gamma
        return q

    @classmethod
    def of(cls, q) -> PlaneGeometry:
        """The plane stored in q's slots (views of q)."""
        return cls(q[Q_C:Q_C + 3], q[Q_VHAT:Q_VHAT + 3], q[Q_WHAT:Q_WHAT + 3], q[Q_CD], q[Q_GAMMA])


def plane_geometry(r_L, v_L) -> PlaneGeometry:
    """The vertical plane through C (``r_L``, m) holding the velocity ``v_L`` (m/s)
    (:func:`plane`; a vertical velocity takes the plane through {L} +x). Raises
    ``layout.DegenerateGeometry`` for zero velocity, a velocity that does not descend, or a
    lander not above the ground."""
    q = np.zeros(NQ)
    st = plane(np.asarray(r_L, float), np.asarray(v_L, float), q)
    if st != OK:
        raise DegenerateGeometry(REASONS[st])
    return PlaneGeometry(q[Q_C:Q_C + 3].copy(), q[Q_VHAT:Q_VHAT + 3].copy(), q[Q_WHAT:Q_WHAT + 3].copy(),
                         float(q[Q_CD]), float(q[Q_GAMMA]))


def ground_points(beta_signed, geom: PlaneGeometry) -> np.ndarray:
    """Eq. 26 over an array of signed beta (rad): the ground points (n, 3) (m) their lines
    of sight hit in the plane ``geom`` (:func:`ground_point`); rows of ``inf`` where one
    misses the ground."""
    q = geom.q
    pts = [ground_point(float(b), q) for b in np.atleast_1d(np.asarray(beta_signed, float))]
    return np.array([p[1:] if p[0] else (np.inf,) * 3 for p in pts], float).reshape(-1, 3)
