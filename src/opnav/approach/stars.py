"""Star-field calibration of the camera misalignment (the ``stars`` variant; beyond the paper).

Description
    How flight teams calibrate a camera's alignment (GIANT's static alignment, Orion,
    OSIRIS-REx): image stars, whose directions are known and carry no parallax. Every
    ``stars.every_K`` samples after N0 the camera switches to star mode (as paper A
    describes): its attitude is the Mars-tracking ``A_c^i`` turned by ``stars.slew_deg``
    about the camera x axis (Mars out of the field; the attitude is known, as the
    Mars-tracking one is), and it images the ``stars.per_image`` brightest catalogue stars
    brighter than ``stars.mag_limit`` inside its field (``pixels * ifov``). The star image is
    taken between two Mars samples: no Mars sample is lost (a choice; one sample in K).

    Measurement of star j in image i: its focal-plane (gnomonic) coordinates in the
    *measured* camera frame, ``p = (d_x, d_y) / d_z`` with ``d = A_m(theta) v`` and ``v`` the
    catalogue direction in the calibrated camera frame, plus white noise of
    ``stars.sigma_px`` (1-sigma, px) times the IFOV on each axis. The truth uses the exact
    rotation; the estimators use the model linearised at theta = 0 (error O(theta^2), about
    1e-8 rad), ``y = p - p(v) = G theta + noise`` with ``G = (1/v_z) [[1, 0, -p_x],
    [0, 1, -p_y]] [v x]``. Stars off the boresight also see the roll tz, so tz becomes
    observable. The star terms are a linear-Gaussian measurement of theta alone:
    information ``J = sum G^T W G`` and ``h = sum G^T W y`` (:func:`normal_equations`), added
    to the EM M-step's normal equations, to the CRLB's theta block and to the augmented EKF.

Catalogue
    Synthetic, drawn once from ``stars.catalogue_seed`` (no star catalogue ships with the
    installed packages): ``stars.catalogue_size`` directions uniform on the sphere, magnitudes
    from the differential count law ``dN/dm ~ 10^(0.46 m)`` between 0 and 10 (Bahcall &
    Soneira's slope near the galactic average), so about 12 % of the stars are brighter than
    magnitude 8: with the default 350 000 stars, about 41 000, the real sky's count to V = 8,
    and about 5 per square degree to magnitude 9.5 (some 40 in a 2.8 deg field). Only
    directions and magnitudes matter here (no colours, no proper motion).
Units: rad (directions, theta), px and arcsec in the config.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.core.rotations import skew

from .camera import misalignment_exact, rot_x
from .dynamics import ARCSEC

MAG_RANGE = (0.0, 10.0)
COUNT_SLOPE = 0.46  # d log10 N / dm


@dataclass(frozen=True)
class StarField:
    """The star images of an arc (no per-seed data): sample index of each image (I,), the
    directions in the calibrated camera frame (I, m, 3), the focal-plane coordinates
    without misalignment ``p0`` (I, 2m), their sensitivity to theta at 0, ``G`` (I, 2m, 3),
    and the weights ``w = 1 / sigma^2`` (rad^-2, (I, 2m)). Every image holds m stars."""

    idx: np.ndarray
    v: np.ndarray
    p0: np.ndarray
    G: np.ndarray
    w: np.ndarray

    def select(self, a: int, b: int) -> "StarField":
        """The images of samples a+1..b, with indices relative to a (a window's)."""
        k = (self.idx > a) & (self.idx <= b)
        return StarField(self.idx[k] - a, self.v[k], self.p0[k], self.G[k], self.w[k])

    def info_per_sample(self, n: int) -> np.ndarray:
        """Information on theta each sample 0..n adds, (n+1, 3, 3), rad^-2 (zero without image)."""
        out = np.zeros((n + 1, 3, 3))
        J = np.einsum("iak,ia,ial->ikl", self.G, self.w, self.G)
        for i, k in enumerate(self.idx):
            if k <= n:
                out[k] += J[i]
        return out


def catalogue(seed: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Synthetic star catalogue (module docstring): unit directions (size, 3), magnitudes (size,)."""
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0x57A2]))
    d = rng.standard_normal((size, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    lo, hi = MAG_RANGE
    u = rng.random(size)
    a = np.log(10.0) * COUNT_SLOPE
    mag = np.log(np.exp(a * lo) + u * (np.exp(a * hi) - np.exp(a * lo))) / a  # inverse CDF of 10^(0.46 m)
    return d, mag


def focal_plane(d: np.ndarray) -> np.ndarray:
    """Gnomonic coordinates ``(d_x, d_y) / d_z`` (..., 2) of directions (..., 3)."""
    return d[..., :2] / d[..., 2:3]


def sensitivity(v: np.ndarray) -> np.ndarray:
    """``d p / d theta`` at theta = 0 (..., 2, 3) for directions ``v`` (..., 3) in the camera
    frame: ``d = v + [v x] theta`` (small angle), ``dp = (dd_xy - p dd_z) / v_z``."""
    p = focal_plane(v)
    Dp = np.zeros(v.shape[:-1] + (2, 3))
    Dp[..., 0, 0] = Dp[..., 1, 1] = 1.0
    Dp[..., :, 2] = -p
    return (Dp / v[..., 2, None, None]) @ skew(v)


def star_field(C: np.ndarray, N0: int, every_K: int, per_image: int, mag_limit: float, slew_deg: float,
               half_fov_rad: float, sigma_rad: float, cat: tuple[np.ndarray, np.ndarray]) -> StarField:
    """The star images of an arc whose Mars-tracking attitude is ``C`` (n+1, 3, 3): one every
    ``every_K`` samples after ``N0``, each with the ``per_image`` brightest catalogue stars
    brighter than ``mag_limit`` in the slewed camera's field (``ValueError`` if a field has fewer, or
    if the arc holds no image)."""
    dirs, mag = cat
    bright = mag <= mag_limit
    dirs, mag = dirs[bright], mag[bright]
    n = C.shape[0] - 1
    idx = np.arange(N0 + every_K, n + 1, every_K)
    if idx.size == 0:
        raise ValueError(f"approach.stars.every_K: the first star image (sample N0 + every_K = {N0 + every_K}) "
                         f"lies beyond the arc's last sample {n}; lower every_K or lengthen the arc")
    R = rot_x(np.deg2rad(slew_deg))
    vs = []
    for k in idx:
        A = R @ C[k]
        v = dirs @ A.T
        p = focal_plane(np.where(v[:, 2:3] > 0, v, np.nan))
        inside = np.nonzero(np.all(np.abs(p) <= np.tan(half_fov_rad), axis=1))[0]
        if inside.size < per_image:
            raise ValueError(f"approach.stars: only {inside.size} stars brighter than magnitude {mag_limit:g} in the "
                             f"field of image at sample {k}; lower stars.per_image or raise mag_limit/catalogue_size")
        pick = inside[np.argsort(mag[inside], kind="stable")[:per_image]]
        vs.append(v[pick])
    v = np.stack(vs) if vs else np.zeros((0, per_image, 3))
    p0 = focal_plane(v).reshape(len(idx), -1)
    G = sensitivity(v).reshape(len(idx), -1, 3)
    w = np.full(p0.shape, 1.0 / sigma_rad**2)
    return StarField(idx, v, p0, G, w)


def simulate(field: StarField, theta_true_rad: np.ndarray, rngs: list[np.random.Generator],
             sigma_rad: float) -> np.ndarray:
    """Star measurements ``y = p(A_exact(theta) v) - p0 + noise`` (S, I, 2m), rad."""
    A = misalignment_exact(theta_true_rad)
    clean = focal_plane(field.v @ A.T).reshape(field.p0.shape) - field.p0
    return np.stack([clean + sigma_rad * g.standard_normal(clean.shape) for g in rngs])


def normal_equations(field: StarField, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stars' ``J = sum G^T W G`` (3, 3) and ``h = sum G^T W y`` (S, 3), rad^-2 and rad^-1."""
    J = np.einsum("iak,ia,ial->kl", field.G, field.w, field.G)
    h = np.einsum("iak,ia,sia->sk", field.G, field.w, y)
    return J, h


def loglik(field: StarField, y: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Log-likelihood of the star measurements at theta (S,), up to a constant."""
    r = y - np.einsum("iak,sk->sia", field.G, theta)
    return -0.5 * np.einsum("ia,sia->s", field.w, r**2)


def theta_information_update(P: np.ndarray, J: np.ndarray, cols=slice(6, 9)) -> np.ndarray:
    """Covariance after adding information ``J`` (..., 3, 3) on the theta block ``cols`` of
    ``P`` (..., d, d): ``(P^-1 + E J E^T)^-1 = P - P E (I + J P_tt)^-1 J E^T P`` (J may be
    singular)."""
    Pc = P[..., :, cols]
    M = np.eye(3) + J @ P[..., cols, cols]
    out = P - Pc @ np.linalg.solve(M, J) @ np.swapaxes(Pc, -1, -2)
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def sigma_rad(sigma_px: float, ifov_arcsec: float) -> float:
    """Star centroid noise, rad, from the 1-sigma pixel error and the IFOV."""
    return sigma_px * ifov_arcsec * ARCSEC
