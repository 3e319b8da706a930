"""Truth trajectory of the Mars powered descent (paper B sec. 3, SPEC B.1).

Description
-----------
Polynomial guidance: the acceleration in the landing frame {L} is quadratic in
time, ``a(t) = c0 + c1 t + c2 t^2`` per axis, with the three coefficients per
axis fixed by touchdown at the site at ``t = T``::

    r(T) = 0,  v(T) = 0,  a(T) = (a_x, a_y, 0)

With the default ``a_x = a_y = 0`` (config ``landing.terminal_accel_mps2``)
the terminal thrust is vertical (specific force ``f(T) = -g``, straight up),
the Apollo-style terminal constraint of the SPEC. The paper does not state
its terminal constraint; the initial thrust azimuth depends on it, the
initial tilt hardly (``opnav.landing.scenario.initial_attitude_report``). Planet rotation is neglected (paper assumption 1), gravity ``g`` is
uniform (flat ground, {L} z up).

Attitude follows the thrust: the body +z axis is along the specific force
``f = a - g`` (thrust acceleration); the yaw of the aerospace Z-Y-X Euler
sequence is held at ``yaw_deg`` (default 0): body +x is along
``(Rz(yaw) e_y) x z_B``. The body therefore feels a pure +z specific force.

Units: m, m/s, m/s^2, s; rotations as ``R_LtoB`` matrices (``v_B = R_LtoB v_L``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["guidance_coefficients", "Truth", "truth_states", "euler_rpy_deg"]


def guidance_coefficients(r0: np.ndarray, v0: np.ndarray, T: float, a_T=None) -> np.ndarray:
    """Coefficients ``c`` (3, 3) of ``a(t) = c[0] + c[1] t + c[2] t^2`` (per axis)
    that bring ``(r0, v0)`` to ``r = v = 0`` and ``a = a_T`` at ``t = T`` (s);
    ``a_T`` (m/s^2) is the terminal horizontal acceleration ``(a_x, a_y)``
    (default 0: vertical terminal thrust), its vertical part 0."""
    if not (np.isfinite(T) and T > 0):
        raise ValueError(f"landing.duration_s must be positive, got {T}")
    r0 = np.asarray(r0, float)
    v0 = np.asarray(v0, float)
    # r(T) = r0 + v0 T + c0 T^2/2 + c1 T^3/6 + c2 T^4/12 = 0
    # v(T) = v0 + c0 T + c1 T^2/2 + c2 T^3/3 = 0
    # a(T) = c0 + c1 T + c2 T^2 = 0
    A = np.array([[T**2 / 2, T**3 / 6, T**4 / 12],
                  [T, T**2 / 2, T**3 / 3],
                  [1.0, T, T**2]])
    aT = np.zeros(3)
    if a_T is not None:
        aT[:2] = np.asarray(a_T, float)[:2]
    rhs = np.stack([-r0 - v0 * T, -v0, aT])
    return np.linalg.solve(A, rhs)


@dataclass(frozen=True)
class Truth:
    """Truth states at times ``t`` (n,): ``r, v, a`` (n, 3) in {L}, ``R_LtoB`` (n, 3, 3)."""

    t: np.ndarray
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray
    R_LtoB: np.ndarray


def _attitude_from_thrust(f: np.ndarray, yaw_deg: float) -> np.ndarray:
    z = f / np.linalg.norm(f, axis=1, keepdims=True)
    psi = np.radians(yaw_deg)
    ey = np.array([-np.sin(psi), np.cos(psi), 0.0])
    x = np.cross(ey[None, :], z)
    nx = np.linalg.norm(x, axis=1, keepdims=True)
    if np.any(nx < 1e-9):
        raise ValueError("thrust direction horizontal along the yaw axis: attitude undefined")
    x = x / nx
    y = np.cross(z, x)
    R_BtoL = np.stack([x, y, z], axis=2)          # columns: body axes in {L}
    return np.transpose(R_BtoL, (0, 2, 1))


def truth_states(t: np.ndarray, r0, v0, T: float, g, yaw_deg: float = 0.0, a_T=None) -> Truth:
    """Truth position, velocity, acceleration and attitude at times ``t`` (s).

    Raises ``ValueError`` if the thrust (specific force) vanishes, i.e. the
    attitude is undefined.
    """
    t = np.asarray(t, float)
    r0 = np.asarray(r0, float)
    v0 = np.asarray(v0, float)
    g = np.asarray(g, float)
    c = guidance_coefficients(r0, v0, T, a_T)
    tt = t[:, None]
    a = c[0] + c[1] * tt + c[2] * tt**2
    v = v0 + c[0] * tt + c[1] * tt**2 / 2 + c[2] * tt**3 / 3
    r = r0 + v0 * tt + c[0] * tt**2 / 2 + c[1] * tt**3 / 6 + c[2] * tt**4 / 12
    f = a - g
    if np.any(np.linalg.norm(f, axis=1) < 1e-9):
        raise ValueError("zero thrust acceleration: attitude undefined")
    R = _attitude_from_thrust(f, float(yaw_deg))
    return Truth(t=t, r=r, v=v, a=a, R_LtoB=R)


def euler_rpy_deg(R_LtoB: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (deg) of ``R_BtoL = Rz(yaw) Ry(pitch) Rx(roll)`` (aerospace
    Z-Y-X sequence), for (3, 3) or (n, 3, 3) input; returns (3,) or (n, 3)."""
    # scipy.spatial (~0.1-0.2 s of import) here: truth_states, which config validation
    # at every Snakefile parse calls, does not need it
    from scipy.spatial.transform import Rotation

    R = np.asarray(R_LtoB, float)
    single = R.ndim == 2
    R_BtoL = np.swapaxes(R.reshape(-1, 3, 3), 1, 2)
    ypr = Rotation.from_matrix(R_BtoL).as_euler("ZYX", degrees=True)
    rpy = ypr[:, ::-1]
    return rpy[0] if single else rpy


def nominal_truth(setup, t, terminal: bool = True) -> Truth:
    """The guidance trajectory of the landing ``setup.Setup``'s descent at times ``t`` (s): from
    the Table 1 state to touchdown at ``duration_s`` with the configured yaw and (``terminal``)
    terminal horizontal acceleration (:func:`truth_states`)."""
    s = setup.initial_state
    return truth_states(np.asarray(t, float), s.r_m, s.v_mps, float(setup.duration_s), setup.gravity_mps2,
                        float(setup.yaw_deg), setup.terminal_accel_mps2 if terminal else None)
