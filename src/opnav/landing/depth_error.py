"""Depth estimation error model of paper B (eq. 19-26).

Description
-----------
The lander at C observes landmark p twice, ``t_s`` apart (``t_s`` = filter
step). Under assumption 2 (straight, uniformly decelerated motion over
``t_s``) the velocity line from C meets the ground at D. With

* ``beta``: angle at C between the velocity and the line of sight C->p,
* ``alpha``: angle at D between the velocity and p->D (interior angle of the
  triangle C, D, p at D),

the depth (range C->p) is, by the law of sines,
``d = |CD| sin(alpha) / sin(alpha + beta)``. The estimated baseline is
``b = |v t_s + a t_s^2 / 2|`` (eq. 19), its error a ball of radius
``r_e = eps_v t_s`` (eq. 21-22) with ``eps_v`` a bound on the velocity error
taken from the filter covariance (``n_sigma * sqrt(max eig P_vv)``). Then::

    |r^(k+s)| = sqrt(b^2 + d^2 - 2 b d cos(beta))          (eq. 25)
    sin(theta) = b sin(beta) / |r^(k+s)|                    (eq. 24)
    dr = 2 r_e / sin(theta)                                 (eq. 23)

Planning (eq. 26, SPEC B.3) works in the vertical plane that holds the
velocity, where alpha takes one of two values and dr is a function of beta
alone. We use a *signed* beta: ``beta > 0`` rotates the line of sight from the
velocity toward the horizon (landmarks beyond D, ``alpha = pi - gamma``),
``beta < 0`` toward the nadir and behind (landmarks short of D,
``alpha = gamma``), with ``gamma`` the flight-path angle below the horizon.

Domain and bad inputs
---------------------
``beta`` must lie in ``(0, pi - alpha)`` (the line of sight meets the ground
in front of the lander). Outside it, and at ``beta = 0`` (no parallax), the
depth error is ``+inf`` by definition (the landmark cannot be triangulated);
it is never NaN. Non-positive ``|CD|`` or baseline, a negative error radius,
zero velocity, or a velocity that does not descend raise
:class:`DegenerateGeometry` (a ``ValueError``).

One home per equation: the planner's compiled forms are in
:mod:`opnav.landing.kernels` (``baseline``, ``error_radius``, ``depth_error``,
``ground_point``, ``plane``); this module gives them a numpy-facing API and
keeps the paper's own vectorised definition (law of sines, eq. 23-25 over beta
and alpha: :func:`depth`, :func:`depth_error`, :func:`signed_depth_error`,
:func:`depth_error_at_landmarks`), the reference the kernels are tested
against and the "as the paper defines it" timing path.

Units: m, s, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.landing import kernels as K

__all__ = ["DegenerateGeometry", "depth", "depth_error", "PlaneGeometry", "plane_geometry",
           "signed_depth_error", "ground_point", "baseline", "error_radius",
           "angles_to_landmarks", "depth_error_at_landmarks"]


class DegenerateGeometry(ValueError):
    """The depth-error model does not apply (zero velocity, a velocity that does
    not descend, a lander not above the ground, a zero baseline): the planner
    falls back to its documented choice (``opnav.landing.planner``)."""


#: why :func:`kernels.plane` / the planner's call refused a geometry (status codes)
REASONS = {K.ZERO_VELOCITY: "depth error: zero velocity, the velocity line is undefined",
           K.NOT_ABOVE: "depth error: lander not above the ground",
           K.NOT_DESCENDING: "depth error: velocity does not descend, it never meets the ground",
           K.ZERO_BASELINE: "depth error: zero baseline (zero velocity)",
           K.NO_INTERVAL: "no visible interval"}


def _check_positive(name: str, x: float) -> float:
    x = float(x)
    if not np.isfinite(x) or x <= 0:
        raise DegenerateGeometry(f"depth error: {name} must be positive and finite, got {x}")
    return x


def depth(beta, alpha, cd: float) -> np.ndarray:
    """Range C->p (m) of the ground landmark seen at ``beta`` (rad), law of sines;
    ``+inf`` outside ``(0, pi - alpha)``."""
    cd = _check_positive("|CD|", cd)
    beta = np.asarray(beta, float)
    alpha = np.asarray(alpha, float)
    if np.any(~np.isfinite(beta)) or np.any((alpha <= 0) | (alpha >= np.pi)):
        raise ValueError("depth error: beta must be finite and alpha in (0, pi)")
    s = np.sin(alpha + beta)
    ok = (beta > 0) & (alpha + beta < np.pi) & (s > 0)
    return np.where(ok, cd * np.sin(alpha) / np.where(ok, s, 1.0), np.inf)


def depth_error(beta, alpha, cd: float, b: float, r_e: float) -> np.ndarray:
    """Depth estimation error ``dr`` (m), eq. 23-25 as the paper writes them,
    vectorised over ``beta`` (and ``alpha``, broadcast). ``+inf`` outside
    ``(0, pi - alpha)``."""
    b = _check_positive("baseline", b)
    r_e = float(r_e)
    if not np.isfinite(r_e) or r_e < 0:
        raise ValueError(f"depth error: error radius must be >= 0, got {r_e}")
    beta = np.asarray(beta, float)
    d = depth(beta, alpha, cd)
    fin = np.isfinite(d)
    dd = np.where(fin, d, 0.0)
    rks = np.sqrt(np.maximum(b * b + dd * dd - 2 * b * dd * np.cos(beta), 0.0))   # eq. 25
    sin_t = np.where(fin & (rks > 0), b * np.sin(beta) / np.where(rks > 0, rks, 1.0), 0.0)  # eq. 24
    with np.errstate(divide="ignore"):
        return np.where(fin & (sin_t > 0), 2.0 * r_e / np.where(sin_t > 0, sin_t, 1.0), np.inf)  # eq. 23


@dataclass(frozen=True)
class PlaneGeometry:
    """The vertical plane holding the velocity (all in {L}, m); ``q`` the kernels'
    per-run constants (``kernels.NQ``) of the plane."""

    C: np.ndarray          # lander position
    v_hat: np.ndarray      # unit velocity
    w_hat: np.ndarray      # unit, in-plane, perpendicular to v_hat, toward the horizon side
    cd: float              # |CD|, m
    gamma: float           # flight-path angle below the horizon, rad (0, pi/2]

    @property
    def q(self) -> np.ndarray:
        q = np.zeros(K.NQ)
        q[0:3], q[3:6], q[6:9], q[9], q[10] = self.C, self.v_hat, self.w_hat, self.cd, self.gamma
        return q


def plane_geometry(r_L, v_L) -> PlaneGeometry:
    """Geometry of the vertical plane through C holding the velocity
    (``kernels.plane``; a vertical velocity takes the plane through {L} +x).
    Raises :class:`DegenerateGeometry` for zero velocity, a velocity that does not
    descend, or a lander not above the ground."""
    q = np.zeros(K.NQ)
    st = K.plane(np.asarray(r_L, float), np.asarray(v_L, float), q)
    if st != K.OK:
        raise DegenerateGeometry(REASONS[st])
    return PlaneGeometry(q[0:3].copy(), q[3:6].copy(), q[6:9].copy(), float(q[9]), float(q[10]))


def signed_depth_error(beta_signed, geom: PlaneGeometry, b: float, r_e: float) -> np.ndarray:
    """Depth error (m) for signed beta (rad) in the velocity's vertical plane (the
    paper's definition, :func:`depth_error`)."""
    bs = np.asarray(beta_signed, float)          # alpha = pi - gamma beyond D (beta > 0), else gamma
    return depth_error(np.abs(bs), np.where(bs > 0, np.pi - geom.gamma, geom.gamma), geom.cd, b, r_e)


def ground_point(beta_signed, geom: PlaneGeometry) -> np.ndarray:
    """Eq. 26: ground point(s) (n, 3) (m) hit by the line of sight at signed beta
    (``kernels.ground_point``); rows of ``inf`` where it misses the ground."""
    q = geom.q
    pts = [K.ground_point(float(b), q) for b in np.atleast_1d(np.asarray(beta_signed, float))]
    return np.array([p[1:] if p[0] else (np.inf,) * 3 for p in pts], float).reshape(-1, 3)


def baseline(v_L, a_L, t_s: float) -> float:
    """Estimated baseline ``|v t_s + a t_s^2/2|`` (m), eq. 19 (``kernels.baseline``)."""
    return K.baseline(np.asarray(v_L, float), np.asarray(a_L, float), float(t_s))


def error_radius(P_vv, t_s: float, n_sigma: float) -> float:
    """Error-ball radius ``r_e = eps_v t_s`` (m), eq. 22 (``kernels.error_radius``)."""
    return K.error_radius(np.asarray(P_vv, float), float(t_s), float(n_sigma))


def angles_to_landmarks(r_L, v_L, p_L: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(alpha, beta, |CD|)`` for arbitrary ground points ``p_L`` (n, 3): beta =
    angle(v, p - C), alpha = angle(v, D - p) (the triangle C, D, p is planar)."""
    geom = plane_geometry(r_L, v_L)
    D = geom.C + geom.cd * geom.v_hat
    p = np.asarray(p_L, float).reshape(-1, 3)
    lc, ld = p - geom.C, D - p
    with np.errstate(invalid="ignore", divide="ignore"):
        cb = (lc @ geom.v_hat) / np.linalg.norm(lc, axis=1)
        ca = (ld @ geom.v_hat) / np.linalg.norm(ld, axis=1)
    beta = np.arccos(np.clip(np.nan_to_num(cb, nan=1.0), -1, 1))
    alpha = np.arccos(np.clip(np.nan_to_num(ca, nan=1.0), -1, 1))
    return np.clip(alpha, 1e-12, np.pi - 1e-12), beta, geom.cd


def depth_error_at_landmarks(r_L, v_L, a_L, p_L, t_s: float, r_e: float) -> np.ndarray:
    """Depth error (m) of each ground landmark ``p_L`` (n, 3), eq. 23-25 (B-F5)."""
    alpha, beta, cd = angles_to_landmarks(r_L, v_L, p_L)
    return depth_error(beta, alpha, cd, baseline(v_L, a_L, t_s), r_e)
