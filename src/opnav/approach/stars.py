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
    Real stars: the 42,212 Hipparcos stars brighter than magnitude 8.03 vendored in
    ``opnav/data/hipparcos_mag8.npz`` (from cedar-solve 0.5.1's tetra3 database, Apache-2.0;
    provenance and licence beside it), ICRS at epoch 2024, rotated here into the ecliptic
    J2000 frame of the approach dynamics (obliquity 84381.406 arcsec, IAU 2006). About one
    star per square degree to magnitude 8: the 2.84 deg field holds a handful, so an image
    holds ``min(per_image, stars in the field)`` stars (the rest of its rows carry no
    information: zero sensitivity).

Noise and attitude knowledge (issue 44: what paper A objects to)
    * Centroid noise grows with magnitude (photon-limited: 1/SNR ~ 10^(0.2 m)) above a floor:
      ``sigma(m) = hypot(sigma_floor_px, sigma_px 10^(0.2 (m - sigma_ref_mag)))`` px per axis.
    * Each star image's attitude is known only to ``attitude_sigma_arcsec`` (1-sigma per axis,
      independent per image): the camera may be the only sensor and its star and Mars modes
      are not synchronised (paper A's objection), so the attitude of a star image relative to
      the Mars images comes from propagation across the slew. And a constant ``mode_drift_arcsec``
      (1-sigma per axis, drawn once per run) separates the star mode from the Mars mode
      (thermo-elastic and slew-dependent: what the stars calibrate is the star-mode camera).
      Both rotate every star of an image together, like theta: the star data measure
      ``theta + drift + delta_i``, so the bound has a floor near
      ``hypot(attitude / sqrt(images), drift)`` whatever the number of stars.
    * The estimators know these statistics: the joint covariance of all star rows
      ``R = diag(sigma^2) + G_i s_a^2 G_i^T (per image) + G s_d^2 G^T (all images)`` is whitened
      by its Cholesky factor ``L`` (block lower-triangular, so each image's whitened rows
      depend on it and earlier images only): ``G~ = L^-1 G``, ``y~ = L^-1 y``, weights 1. The
      whitened images are independent, and every consumer (CRLB, EM M-step, augmented EKF)
      adds them image by image as before. Each window is whitened by the covariance of its own
      images' rows (:meth:`StarField.select`): a sliding window's star data are marginalised
      exactly over the drift and the attitude errors, and nothing of the images before it enters
      (issue 54: the arc's whitened rows of a window's images, conditioned on earlier images, gave
      6.66 arcsec for the last window of the full profile against 5.09 exact). For growing windows
      and all the data the window's whitening is the arc's restricted to its leading images.
Units: rad (directions, theta), px and arcsec in the config.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from importlib import resources

import numpy as np

from opnav.core.rotations import skew

from .camera import misalignment_exact, rot_x
from .dynamics import ARCSEC

CATALOGUE_FILE = "hipparcos_mag8.npz"
MAG_RANGE = (-2, 8.03)  # magnitude limits a config may ask for: brighter than Sirius (-1.44) .. the catalogue's end
OBLIQUITY_J2000_RAD = 84381.406 * ARCSEC  # IAU 2006 mean obliquity at J2000
NO_STAR_SIGMA_RAD = 1.0  # rows of an image with fewer stars than per_image: no information (G = 0)


@dataclass(frozen=True)
class StarField:
    """The star images of an arc (no per-seed data): sample index of each image (I,), the
    directions in the calibrated camera frame (I, m, 3), the focal-plane coordinates
    without misalignment ``p0`` (I, 2m), the *whitened* sensitivity to theta ``G`` (I, 2m, 3)
    and weights ``w`` (ones; module docstring), the raw sensitivity ``G_raw``, the centroid
    1-sigma of each row ``sigma`` (rad, (I, 2m)), the magnitudes ``mag`` (I, m; NaN: no
    star), the HIP numbers ``hip`` (I, m; 0: no star), the stars in each image ``n_stars``
    (I,), the whitening factor ``L`` (2mI, 2mI) and the attitude and drift 1-sigmas (rad).
    Every image has m rows pairs; those beyond ``n_stars`` carry no information."""

    idx: np.ndarray
    v: np.ndarray
    p0: np.ndarray
    G: np.ndarray
    w: np.ndarray
    G_raw: np.ndarray = None
    sigma: np.ndarray = None
    mag: np.ndarray = None
    hip: np.ndarray = None
    n_stars: np.ndarray = None
    L: np.ndarray = None
    attitude_sigma_rad: float = 0.0
    drift_sigma_rad: float = 0.0

    def select(self, a: int, b: int) -> "StarField":
        """The images of samples a+1..b, with indices relative to a (a window's), whitened by the
        joint covariance of *their own* rows (:func:`whitening`): the window's star data
        marginalised exactly over the drift and the attitude errors, with nothing conditioned on
        images outside it. For images from the arc's first on (growing windows, all the data) this
        is the arc's whitening restricted to them (the Cholesky factor of a leading block is the
        leading block of the factor)."""
        k = (self.idx > a) & (self.idx <= b)
        sub = (lambda x: None if x is None else x[k])
        if self.G_raw is None:  # a field made without its raw rows: the arc's whitened rows
            return StarField(self.idx[k] - a, self.v[k], self.p0[k], self.G[k], self.w[k], None, sub(self.sigma),
                             sub(self.mag), sub(self.hip), sub(self.n_stars), None, self.attitude_sigma_rad,
                             self.drift_sigma_rad)
        L, G = whitening(self.G_raw[k], self.sigma[k], self.attitude_sigma_rad, self.drift_sigma_rad)
        return StarField(self.idx[k] - a, self.v[k], self.p0[k], G, np.ones(G.shape[:2]), self.G_raw[k],
                         self.sigma[k], sub(self.mag), sub(self.hip), sub(self.n_stars), L,
                         self.attitude_sigma_rad, self.drift_sigma_rad)

    def whiten(self, y: np.ndarray) -> np.ndarray:
        """Raw star measurements ``y`` (S, I, 2m) of this field's images, whitened by its factor:
        ``L^-1 y`` (S, I, 2m), rad (the rows :meth:`info_per_sample` and the consumers read)."""
        if self.L is None:
            raise ValueError("StarField.whiten: this field has no whitening factor (made without raw rows)")
        from scipy.linalg import solve_triangular

        S = y.shape[0]
        if self.idx.size == 0:
            return np.zeros_like(y)
        return solve_triangular(self.L, y.reshape(S, -1).T, lower=True).T.reshape(y.shape)

    def info_per_sample(self, n: int) -> np.ndarray:
        """Information on theta each sample 0..n adds, (n+1, 3, 3), rad^-2 (zero without image)."""
        out = np.zeros((n + 1, 3, 3))
        J = np.einsum("iak,ia,ial->ikl", self.G, self.w, self.G)
        for i, k in enumerate(self.idx):
            if k <= n:
                out[k] += J[i]
        return out


def catalogue() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The vendored Hipparcos catalogue (module docstring): unit directions in the ecliptic J2000
    frame (N, 3), visual magnitudes (N,) and HIP numbers (N,)."""
    return _catalogue()


@functools.lru_cache(maxsize=1)
def _catalogue():
    with resources.files("opnav").joinpath("data", CATALOGUE_FILE).open("rb") as f:
        d = np.load(f)
        ra, dec = d["ra_rad"].astype(float), d["dec_rad"].astype(float)
        mag, hip = d["vmag"].astype(float), d["hip"].astype(np.int64)
    eq = np.stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], axis=1)
    ecl = eq @ rot_x(OBLIQUITY_J2000_RAD).T  # equatorial -> ecliptic: rotate the frame about x by epsilon
    for a in (ecl, mag, hip):
        a.setflags(write=False)
    return ecl, mag, hip


def centroid_sigma_px(mag: np.ndarray, sigma_px: float, ref_mag: float, floor_px: float) -> np.ndarray:
    """Centroid 1-sigma per focal-plane axis, px, of stars of magnitude ``mag`` (module docstring):
    ``hypot(floor_px, sigma_px 10^(0.2 (mag - ref_mag)))``."""
    return np.hypot(floor_px, sigma_px * 10.0 ** (0.2 * (np.asarray(mag, float) - ref_mag)))


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
               half_fov_rad: float, sigma_of_mag, cat, attitude_sigma_rad: float = 0.0,
               drift_sigma_rad: float = 0.0) -> StarField:
    """The star images of an arc whose Mars-tracking attitude is ``C`` (n+1, 3, 3): one every
    ``every_K`` samples after ``N0``, each with up to ``per_image`` of the brightest catalogue
    stars brighter than ``mag_limit`` in the slewed camera's field (``ValueError`` if a field has
    none, or if the arc holds no image). ``sigma_of_mag``: centroid 1-sigma (rad) of a magnitude
    (:func:`centroid_sigma_px` times the IFOV); ``cat``: :func:`catalogue`'s directions,
    magnitudes and HIP numbers; the attitude and drift 1-sigmas per axis, rad."""
    dirs, mag, hip = cat
    bright = mag <= mag_limit
    dirs, mag, hip = dirs[bright], mag[bright], hip[bright]
    n = C.shape[0] - 1
    idx = np.arange(N0 + every_K, n + 1, every_K)
    if idx.size == 0:
        raise ValueError(f"approach.stars.every_K: the first star image (sample N0 + every_K = {N0 + every_K}) "
                         f"lies beyond the arc's last sample {n}; lower every_K or lengthen the arc")
    R = rot_x(np.deg2rad(slew_deg))
    I, m = idx.size, per_image
    v = np.zeros((I, m, 3))
    v[..., 2] = 1.0  # rows without a star: the boresight, zero weight below
    mags = np.full((I, m), np.nan)
    hips = np.zeros((I, m), dtype=np.int64)
    n_stars = np.zeros(I, dtype=int)
    for i, k in enumerate(idx):
        A = R @ C[k]
        vk = dirs @ A.T
        p = focal_plane(np.where(vk[:, 2:3] > 0, vk, np.nan))
        inside = np.nonzero(np.all(np.abs(p) <= np.tan(half_fov_rad), axis=1))[0]
        if inside.size == 0:
            raise ValueError(f"approach.stars: no star brighter than magnitude {mag_limit:g} in the field of the "
                             f"image at sample {k}; raise stars.mag_limit (catalogue complete to 8.0)")
        pick = inside[np.lexsort((hip[inside], mag[inside]))[:m]]  # brightest; ties by HIP number
        j = pick.size
        v[i, :j], mags[i, :j], hips[i, :j], n_stars[i] = vk[pick], mag[pick], hip[pick], j
    real = np.repeat(~np.isnan(mags), 2, axis=1)  # (I, 2m)
    p0 = focal_plane(v).reshape(I, -1)
    G_raw = np.where(real[..., None], sensitivity(v).reshape(I, -1, 3), 0.0)
    sig_star = np.broadcast_to(np.asarray(sigma_of_mag(np.nan_to_num(mags, nan=0.0)), float), mags.shape)
    sig = np.where(real, np.repeat(sig_star, 2, axis=1), NO_STAR_SIGMA_RAD)
    L, G = whitening(G_raw, sig, attitude_sigma_rad, drift_sigma_rad)
    return StarField(idx, v, p0, G, np.ones((I, 2 * m)), G_raw, sig, mags, hips, n_stars, L,
                     float(attitude_sigma_rad), float(drift_sigma_rad))


@dataclass(frozen=True)
class CountSettings:
    """What makes a star count real (:func:`count_settings`): the magnitude limit, the field's
    half-width (rad) and whether it was widened past the camera's."""

    mag_limit: float
    half_fov_rad: float
    widened: bool


def count_settings(C: np.ndarray, N0: int, every_K: int, count: int, mag_cap: float, slew_deg: float,
                   half_fov_rad: float, cat) -> CountSettings:
    """The magnitude limit and field at which *every* star image of the arc (:func:`star_field`'s
    images of the Mars-tracking attitude ``C``) holds at least ``count`` stars, so that with
    ``per_image = count`` each image holds exactly ``count`` (issue 54, item 4: the stars sweep
    changes what it says it changes). The camera's field (half-width ``half_fov_rad``) with the
    brightest magnitude limit that gives every image ``count`` stars (the largest, over the
    images, of the ``count``-th brightest magnitude in the field); where even ``mag_cap`` (the
    catalogue's limit) leaves an image short, ``mag_cap`` and the field widened (a square field,
    the camera's pixel scale: more pixels) just enough for every image. Returns ``mag_limit``,
    ``half_fov_rad`` and ``widened`` (bool)."""
    dirs, mag, _ = cat
    keep = mag <= mag_cap
    dirs, mag = dirs[keep], mag[keep]
    n = C.shape[0] - 1
    idx = np.arange(N0 + every_K, n + 1, every_K)
    if idx.size == 0:
        raise ValueError(f"approach.stars.every_K: the first star image (sample N0 + every_K = {N0 + every_K}) "
                         f"lies beyond the arc's last sample {n}; lower every_K or lengthen the arc")
    R = rot_x(np.deg2rad(slew_deg))
    need_mag, need_tan = -np.inf, 0.0
    for k in idx:
        vk = dirs @ (R @ C[k]).T
        front = vk[:, 2] > 0
        cheb = np.full(vk.shape[0], np.inf)  # the square field's half-width (tan) that contains a star
        cheb[front] = np.abs(vk[front, :2] / vk[front, 2:3]).max(1)
        inside = cheb <= np.tan(half_fov_rad)
        if inside.sum() >= count:
            need_mag = max(need_mag, float(np.sort(mag[inside])[count - 1]))
        else:
            need_mag = np.inf
        need_tan = max(need_tan, float(np.sort(cheb)[count - 1]))
    if np.isfinite(need_mag):
        return CountSettings(need_mag, float(half_fov_rad), False)
    if not np.isfinite(need_tan):
        raise ValueError(f"approach.stars.study_count: {count} stars per image are not in the sky in front of the "
                         f"camera to magnitude {mag_cap:g}")
    return CountSettings(float(mag_cap), float(np.arctan(need_tan * (1.0 + 1e-9))), True)


def joint_covariance(G_raw: np.ndarray, sigma: np.ndarray, attitude_sigma_rad: float,
                     drift_sigma_rad: float) -> np.ndarray:
    """The joint covariance (D, D), D = I 2m, rad^2, of the star rows of I images (module
    docstring): centroid noise ``diag(sigma^2)``, each image's attitude error
    ``G_i s_a^2 G_i^T`` and the drift shared by all images ``G s_d^2 G^T``; ``G_raw`` (I, 2m, 3),
    ``sigma`` (I, 2m)."""
    I, m2 = sigma.shape
    D = I * m2
    Gf = G_raw.reshape(D, 3)
    R = np.diag(sigma.reshape(D) ** 2) + drift_sigma_rad**2 * Gf @ Gf.T
    for i in range(I):
        blk = slice(i * m2, (i + 1) * m2)
        R[blk, blk] += attitude_sigma_rad**2 * G_raw[i] @ G_raw[i].T
    return R


def whitening(G_raw: np.ndarray, sigma: np.ndarray, attitude_sigma_rad: float,
              drift_sigma_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """The Cholesky factor ``L`` (D, D) of :func:`joint_covariance` and the whitened
    sensitivity ``L^-1 G`` (I, 2m, 3) of these images' rows (no image: empty arrays)."""
    from scipy.linalg import solve_triangular

    I, m2 = sigma.shape
    if I == 0:
        return np.zeros((0, 0)), np.zeros((0, m2, 3))
    L = np.linalg.cholesky(joint_covariance(G_raw, sigma, attitude_sigma_rad, drift_sigma_rad))
    return L, solve_triangular(L, G_raw.reshape(I * m2, 3), lower=True).reshape(I, m2, 3)


def simulate(field: StarField, theta_true_rad: np.ndarray, rngs: list[np.random.Generator]) -> np.ndarray:
    """Raw star measurements ``y`` (S, I, 2m), rad: ``y = p(A_exact(theta) A_exact(e_i) v) - p0 +
    noise`` per image i, with the attitude error ``e_i = drift + delta_i`` of each run (drift drawn
    once, then delta_i per image, then the centroid noise, from the run's stream); rows without a
    star hold noise only. A window whitens its own images' rows (:meth:`StarField.whiten` of
    :meth:`StarField.select`)."""
    A = misalignment_exact(theta_true_rad)
    I, m2 = field.p0.shape
    real = np.repeat(field.n_stars[:, None] > np.arange(m2 // 2)[None], 2, axis=1)
    out = []
    for g in rngs:
        drift = field.drift_sigma_rad * g.standard_normal(3)
        delta = field.attitude_sigma_rad * g.standard_normal((I, 3))
        clean = np.stack([focal_plane(field.v[i] @ (A @ misalignment_exact(drift + delta[i])).T).reshape(-1)
                          for i in range(I)]) - field.p0
        out.append(np.where(real, clean, 0.0) + field.sigma * g.standard_normal((I, m2)))
    return np.stack(out)


def normal_equations(field: StarField, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stars' ``J = sum G^T W G`` (3, 3) and ``h = sum G^T W y`` (S, 3), rad^-2 and rad^-1,
    of the field's whitened rows ``G`` and whitened measurements ``y``."""
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


def sigma_rad(sigma_px, ifov_arcsec: float):
    """Star centroid noise, rad, from the 1-sigma pixel error and the IFOV."""
    return np.asarray(sigma_px, float) * ifov_arcsec * ARCSEC
