"""Pinhole camera: mounting, field-of-view check, pixel-noise bearings (SPEC B.2).

Description
-----------
The camera frame {C} has its +z axis (boresight) tilted by ``tilt_deg`` from
the body -z axis toward the body direction of azimuth ``tilt_azimuth_deg``
(measured in the body x-y plane from +x toward +y). With the defaults (45 deg
toward azimuth -107 deg) the landing site stays within about 7 deg of the
boresight for the whole descent; a nadir-looking camera would not see it (the
site is 40-51 deg from body -z, see SPEC B.2). ``x_C`` is the body direction
``(Rz(azimuth) e_y) x z_C`` (an image row), ``y_C = z_C x x_C``.

A landmark is in view when it is in front of the camera and its pixel lies on
the ``N x N`` detector of square field of view ``fov_deg`` (full angle):
focal length ``f = (N/2) / tan(fov/2)`` pixels. A bearing is measured by
adding white Gaussian noise (``sigma_px`` pixels per axis) to the pixel and
mapping it back to a unit vector in {B}. The filter models this as isotropic
bearing noise of ``sigma_b = sigma_px / f`` rad per component (paper eq. 13).

Units: pixels, rad (deg in config), m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.landing.setup import CameraSettings

__all__ = ["Camera", "make_camera"]


@dataclass(frozen=True)
class Camera:
    R_BtoC: np.ndarray     # (3, 3): v_C = R_BtoC v_B
    focal_px: float
    half_px: float         # N / 2
    sigma_px: float
    margin_px: float = 0.0  # planning margin inside the detector edge

    @property
    def sigma_b(self) -> float:
        """Bearing noise 1-sigma per component, rad."""
        return self.sigma_px / self.focal_px

    @property
    def boresight_B(self) -> np.ndarray:
        return self.R_BtoC[2]

    def in_view(self, dirs_B: np.ndarray, margin_px: float = 0.0) -> np.ndarray:
        """Boolean mask: body-frame directions (n, 3) (any length) inside the FOV,
        at least ``margin_px`` pixels inside the detector edge."""
        d = np.asarray(dirs_B, float).reshape(-1, 3) @ self.R_BtoC.T
        z = d[:, 2]
        lim = (self.half_px - margin_px) / self.focal_px
        return (z > 0) & (np.abs(d[:, 0]) < lim * z) & (np.abs(d[:, 1]) < lim * z)

    def measure(self, dir_B: np.ndarray, noise_px: np.ndarray) -> np.ndarray:
        """Noisy unit bearing(s) in {B} of the true direction(s) ``dir_B`` (..., 3),
        given the standard-normal pixel noise draws ``noise_px`` (..., 2). Raises
        ``ValueError`` for a direction behind the camera."""
        d = np.asarray(dir_B, float) @ self.R_BtoC.T
        if np.any(d[..., 2] <= 0):
            raise ValueError("landmark behind the camera: no image point")
        uv = self.focal_px * d[..., :2] / d[..., 2:3] + self.sigma_px * np.asarray(noise_px, float)
        c = np.concatenate([uv, np.full(uv.shape[:-1] + (1,), self.focal_px)], axis=-1)
        c /= np.linalg.norm(c, axis=-1, keepdims=True)
        return c @ self.R_BtoC


def make_camera(cam: CameraSettings) -> Camera:
    """Build the :class:`Camera` from the ``landing.camera`` settings (``setup.CameraSettings``)."""
    fov = np.radians(float(cam.fov_deg))
    if not 0 < fov < np.pi:
        raise ValueError(f"landing.camera.fov_deg must be in (0, 180), got {cam.fov_deg}")
    half = float(cam.pixels) / 2.0
    focal = half / np.tan(fov / 2)
    tilt = np.radians(float(cam.tilt_deg))
    az = np.radians(float(cam.tilt_azimuth_deg))
    horiz = np.array([np.cos(az), np.sin(az), 0.0])
    z_C = np.cos(tilt) * np.array([0.0, 0.0, -1.0]) + np.sin(tilt) * horiz
    e_y = np.array([-np.sin(az), np.cos(az), 0.0])
    x_C = np.cross(e_y, z_C)
    x_C /= np.linalg.norm(x_C)
    y_C = np.cross(z_C, x_C)
    R_BtoC = np.stack([x_C, y_C, z_C])
    return Camera(R_BtoC=R_BtoC, focal_px=focal, half_px=half, sigma_px=float(cam.sigma_px),
                  margin_px=float(cam.plan_margin_px))
