"""Navigation camera: attitude, misalignment and pixel-to-km noise (paper A eq. 3-5; SPEC A.2).

Description
    * Calibrated camera frame ``A_c^i`` (inertial -> camera, rows are the camera
      axes): z along the line of sight to Mars (the camera tracks Mars), x
      perpendicular to z and to the ecliptic pole, then rotated about the
      boresight by the roll angle of the scenario (``roll`` variant, SPEC A.3b).
    * Installation matrix ``A_b^c`` (body -> camera): a rotation about the camera
      x axis by the installation angle. The body attitude is commanded so the
      *camera* boresight tracks Mars (``A_b^i = A_b^c^T A_c^i``), therefore the
      calibrated camera frame, and with it every measurement, is independent of
      the installation angle; :func:`body_attitude` exposes the body attitude.
    * Misalignment ``A_m^c``: paper eq. 5, ``[[1, tz, -ty], [-tz, 1, tx],
      [ty, -tx, 1]] = I - [theta x]`` to first order. The truth uses the exact
      rotation ``exp(-[theta x])`` (:func:`misalignment_exact`), the estimator
      the small-angle matrix (:func:`misalignment_small`). A rotation about the
      boresight (tz) does not move a vector along the boresight: tz is
      unobservable while the camera looks at Mars.
    * Noise: pixel 3-sigma values for the two centroid axes and the apparent
      radius are converted to km with the pinhole camera: lateral
      ``sigma = rho * IFOV * sigma_px``; range from the radius,
      ``rho = R_M / sin(alpha)`` so ``sigma_rho = rho * sigma_alpha / tan(alpha)``
      with ``sigma_alpha = IFOV * sigma_radius_px``.

Units: km, rad (arcsec only at the edges).
"""

from __future__ import annotations

import numpy as np

from opnav.core.rotations import skew

from .dynamics import ARCSEC, R_MARS_KM


def misalignment_small(theta: np.ndarray) -> np.ndarray:
    """Paper eq. 5: ``A_m^c = I - [theta x]`` (theta in rad, broadcasts)."""
    return np.eye(3) - skew(theta)


def misalignment_exact(theta: np.ndarray) -> np.ndarray:
    """Exact rotation whose first-order form is eq. 5: ``exp(-[theta x])``."""
    from scipy.spatial.transform import Rotation   # imported here: most jobs never call it

    return Rotation.from_rotvec(-np.asarray(theta, float)).as_matrix()


def rot_x(angle_rad: float) -> np.ndarray:
    """Frame rotation about x by ``angle_rad`` (passive, maps old-frame to new-frame coords)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def rot_z(angle_rad: np.ndarray) -> np.ndarray:
    """Frame rotation(s) about z (..., 3, 3)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, s, z], -1), np.stack([-s, c, z], -1),
                     np.stack([z, z, o], -1)], -2)


def tracking_attitude(los: np.ndarray, roll_rad: np.ndarray | float = 0.0) -> np.ndarray:
    """``A_c^i`` (n, 3, 3): camera z along ``los`` (n, 3), then rolled about z by ``roll_rad``."""
    z = los / np.linalg.norm(los, axis=-1, keepdims=True)
    pole = np.array([0.0, 0.0, 1.0])
    x = np.cross(pole, z)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    y = np.cross(z, x)
    A = np.stack([x, y, z], axis=-2)
    roll = np.broadcast_to(np.asarray(roll_rad, float), los.shape[:-1])
    return rot_z(roll) @ A


def body_attitude(A_c_i: np.ndarray, install_deg: float) -> np.ndarray:
    """Body attitude ``A_b^i`` that puts the installed camera's boresight on Mars."""
    return rot_x(np.deg2rad(install_deg)).T @ A_c_i


def roll_angle(t: np.ndarray, rate_deg_s: float = 0.0, steps_deg: list[float] | None = None,
               step_interval_s: float = 0.0) -> np.ndarray:
    """Camera roll about the boresight (rad) at times ``t`` (s).

    A constant ``rate_deg_s`` or, when ``steps_deg`` is non-empty, a staircase
    through the listed angles, each held ``step_interval_s`` (cyclic).
    """
    t = np.asarray(t, float)
    if steps_deg:
        idx = (np.floor((t - t[0]) / step_interval_s).astype(int)) % len(steps_deg)
        return np.deg2rad(np.asarray(steps_deg, float)[idx])
    return np.deg2rad(rate_deg_s) * (t - t[0])


def noise_sigma_km(rho_km: np.ndarray, ifov_arcsec: float, sigma3_px: tuple[float, float, float]
                   ) -> np.ndarray:
    """1-sigma noise (n, 3) of the Mars vector in the camera frame, km (SPEC A.2).

    ``sigma3_px`` = 3-sigma pixel errors of (centroid x, centroid y, radius).
    """
    ifov = ifov_arcsec * ARCSEC
    s = np.asarray(sigma3_px, float) / 3.0
    rho = np.asarray(rho_km, float)
    alpha = np.arcsin(R_MARS_KM / rho)
    lat_x = rho * ifov * s[0]
    lat_y = rho * ifov * s[1]
    rng = rho * (ifov * s[2]) / np.tan(alpha)
    return np.stack([lat_x, lat_y, rng], axis=-1)
