"""The Mars-approach scenario: truth, reference, measurements and variants (SPEC A.1-A.3b).

Description
    :func:`build_geometry` makes everything shared by all seeds of one variant:
    the truth arc (DOP853 from 1e6 km, hyperbolic approach with ``v_inf`` and
    an aim-point offset), the reference trajectory (the prior mean, i.e. the
    truth plus the paper's initial error [100,100,100] km / [0.1,0.1,0.1] km/s,
    propagated nonlinearly) with its one-step STMs, the camera attitude of the
    variant (tracking Mars; rolling about the boresight in ``roll``), and the
    measurement variances from the pinhole camera.

    :func:`simulate` draws the measurements of given seeds: the truth uses the
    *exact* misalignment rotation; each seed's random stream is
    ``SeedSequence([base_seed, case_index, seed_index])``, independent of how
    seeds are grouped into jobs. The same stream also draws the initial error
    in the ``sampled`` initial-error mode.

Scenario variants (SPEC A.3b)
    ``literal``          camera tracks Mars, no roll; EM windows start from the
                         theta = 0 filter's own ``X_N0, P_N0``.
    ``prior``            as literal, but windows start from the prior
                         ``mu_X0, P_X0`` propagated to ``N0`` without data.
    ``roll``             as prior, with the camera rolling about its boresight.
    ``reference-start``  DIAGNOSTIC: windows start from the *true* state with
                         the filter's ``P_N0``; information the measurements do
                         not hold.
    ``stars``            beyond the paper: as prior (no roll), plus star-field images every
                         ``stars.every_K`` samples (:mod:`opnav.approach.stars`: Hipparcos
                         stars, magnitude-dependent centroid noise, per-image attitude
                         knowledge and a star/Mars mode drift), which measure the camera
                         attitude directly.
Units: km, km/s, s, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import camera, dynamics
from .dynamics import ARCSEC
from .ekf import Window
from .setup import Setup

VARIANTS = ("literal", "prior", "roll", "reference-start", "stars")
START_OF = {"literal": "filter", "prior": "prior", "roll": "prior", "reference-start": "truth", "stars": "prior"}


@dataclass
class Geometry:
    t: np.ndarray  # (n+1,) s
    X_true: np.ndarray  # (n+1, 6)
    X_ref: np.ndarray  # (n+1, 6)
    X_mars: np.ndarray  # (n+1, 6)
    Phi: np.ndarray  # (n+1, 6, 6)
    C: np.ndarray  # (n+1, 3, 3) A_c^i
    u_ref: np.ndarray  # (n+1, 3)
    u_true: np.ndarray  # (n+1, 3) A_c^i (X_M - r_true)
    rho_ref: np.ndarray  # (n+1,)
    Q: np.ndarray
    P0: np.ndarray  # prior covariance at t0
    e_fixed: np.ndarray  # (6,) the paper's initial error (prior mean - truth)
    variant: str
    ifov_arcsec: float = 10.0  # pixel size of the camera the variances are made for
    stars: object = None  # stars.StarField (``stars`` variant), else None
    star_sigma_rad: float = 0.0  # star centroid 1-sigma at stars.sigma_ref_mag, rad
    attitude_sigma_rad: float = 0.0  # attitude knowledge of each Mars image, 1-sigma per axis, rad

    @property
    def dx_true(self) -> np.ndarray:
        """True deviation from the reference (n+1, 6)."""
        return self.X_true - self.X_ref

    def window(self, Rvar: np.ndarray, star_y: np.ndarray | None = None) -> Window:
        """The model arrays of the whole arc; ``star_y``: the seeds' star measurements."""
        return Window(self.Phi, self.C, self.u_ref, Rvar, self.Q, self.stars, star_y)

    def star_info(self) -> np.ndarray | None:
        """Information on theta of the star image at each sample (n+1, 3, 3), or None."""
        return None if self.stars is None else self.stars.info_per_sample(self.t.shape[0] - 1)

    def simulate_stars(self, theta_true_rad: np.ndarray, base_seed: int, case_index: int,
                       seed_indices) -> np.ndarray | None:
        """Star measurements of the seeds (S, I, 2m), each from its own stream
        ``SeedSequence([base_seed, case_index, seed_index, 1])`` (apart from the Mars noise's),
        or None without star images."""
        if self.stars is None:
            return None
        from . import stars

        rngs = [np.random.default_rng(np.random.SeedSequence([base_seed, case_index, int(i), 1]))
                for i in seed_indices]
        return stars.simulate(self.stars, theta_true_rad, rngs)

    def along_reference(self) -> "Geometry":
        """The same geometry with the truth's Mars vector ``u_true`` replaced by the reference's
        ``u_ref``: what an estimator may evaluate a bound at (the truth is not known to it)."""
        from dataclasses import replace

        return replace(self, u_true=self.u_ref)

    def measurement_variance(self, sigma3_px) -> np.ndarray:
        """Rvar (n+1, 3), km^2, that the filters, EM and the bounds use: the pinhole camera's at
        the reference range (paper eq. 3-4, :meth:`pixel_variance`) plus, across the line of
        sight, what the Mars image's attitude error makes, ``(rho sigma_a)^2`` (to first order
        ``[u x] delta`` with ``u`` along the boresight: lateral only)."""
        R = self.pixel_variance(sigma3_px)
        if self.attitude_sigma_rad > 0.0:
            R = R.copy()
            R[:, :2] += (self.rho_ref[:, None] * self.attitude_sigma_rad) ** 2
        return R

    def pixel_variance(self, sigma3_px) -> np.ndarray:
        """The pixel noise alone (n+1, 3), km^2 (paper eq. 3-4): what the simulation draws;
        the attitude error is drawn as a rotation (:func:`simulate`)."""
        return camera.noise_sigma_km(self.rho_ref, self.ifov_arcsec, sigma3_px) ** 2


def initial_truth(setup: Setup) -> np.ndarray:
    """Heliocentric truth state at t0: Mars state + hyperbolic approach state (km, km/s)."""
    g = setup.geometry
    Xm = dynamics.kepler_state(setup.mars, 0.0)
    d = np.asarray(g.v_inf_dir, float)
    d /= np.linalg.norm(d)
    perp = np.cross(d, [0.0, 0.0, 1.0])
    perp /= np.linalg.norm(perp)
    r_rel = -g.range_km * d + g.aim_offset_km * perp
    r_rel *= g.range_km / np.linalg.norm(r_rel)
    vmag = np.sqrt(g.v_inf_kms ** 2 + 2.0 * dynamics.MU_MARS / g.range_km)
    return Xm + np.concatenate([r_rel, vmag * d])


def n_samples(setup: Setup) -> int:
    """Samples after t0 that the arc needs: N0 + L*N."""
    return setup.segments.n_samples


def mars_disc_px(range_km: float, ifov_arcsec: float) -> float:
    """Apparent diameter of Mars, px, seen from ``range_km`` (km, > Mars radius)
    with pixels of ``ifov_arcsec`` arcsec."""
    return 2.0 * np.rad2deg(np.arcsin(dynamics.R_MARS_KM / range_km)) * 3600.0 / ifov_arcsec


def build_geometry(setup: Setup, variant: str, n: int | None = None) -> Geometry:
    """Truth, reference with STMs, attitude of ``variant`` (see module docstring)."""
    if variant not in VARIANTS:
        raise ValueError(f"unknown approach variant {variant!r}; use one of {VARIANTS}")
    n = setup.segments.n_samples if n is None else n
    t = setup.dt_s * np.arange(n + 1)
    el = setup.mars
    X0 = initial_truth(setup)
    X_true = dynamics.propagate(X0, t, el)
    e_fixed = setup.initial_error.e_fixed
    X_ref, Phi = dynamics.propagate_with_stm(X0 + e_fixed, t, el)
    X_mars = dynamics.kepler_state(el, t)
    los = X_mars[:, :3] - X_true[:, :3]
    r = setup.roll
    roll = (camera.roll_angle(t, r.rate_deg_s, list(r.steps_deg), r.step_interval_s)
            if variant == "roll" else np.zeros_like(t))
    rho = np.linalg.norm(los, axis=1)
    cam = setup.camera
    disc_px = mars_disc_px(rho.min(), cam.ifov_arcsec)
    if disc_px > cam.pixels:
        raise ValueError(f"approach.camera: Mars ({disc_px:.0f} px across) does not fit the "
                         f"{cam.pixels} px detector; raise camera.ifov_arcsec or the range")
    C, u_ref, u_true = _camera_frame(X_true, X_ref, X_mars, roll)
    field, sig = (star_field_of(setup, C) if variant == "stars" else (None, 0.0))
    return Geometry(t, X_true, X_ref, X_mars, Phi, C, u_ref, u_true,
                    np.linalg.norm(u_ref, axis=1), setup.Q, setup.prior_sigma.P0, e_fixed, variant,
                    cam.ifov_arcsec, field, sig, cam.attitude_sigma_arcsec * ARCSEC)


def star_field_of(setup: Setup, C: np.ndarray, half_fov_rad: float | None = None):
    """The ``stars`` variant's star images along the Mars-tracking attitude ``C`` (n+1, 3, 3)
    with the setup's ``stars`` and ``camera`` (:func:`opnav.approach.stars.star_field`), and the
    centroid 1-sigma at ``stars.sigma_ref_mag`` (rad). ``half_fov_rad``: the star images' field
    half-width (default the camera's, ``pixels * ifov / 2``; the stars sweep widens it)."""
    from . import stars
    st, cam = setup.stars, setup.camera

    def sigma_of_mag(m):
        return stars.sigma_rad(stars.centroid_sigma_px(m, st.sigma_px, st.sigma_ref_mag, st.sigma_floor_px),
                               cam.ifov_arcsec)

    field = stars.star_field(C, setup.segments.N0, st.every_K, st.per_image, st.mag_limit, st.slew_deg,
                             camera_half_fov_rad(setup) if half_fov_rad is None else half_fov_rad,
                             sigma_of_mag, stars.catalogue(),
                             st.attitude_sigma_arcsec * ARCSEC, st.mode_drift_arcsec * ARCSEC)
    return field, float(stars.sigma_rad(st.sigma_px, cam.ifov_arcsec))


def camera_half_fov_rad(setup: Setup) -> float:
    """Half-width of the camera's square field, ``pixels * ifov / 2``, rad."""
    cam = setup.camera
    return 0.5 * cam.pixels * cam.ifov_arcsec * ARCSEC


def with_stars(geo: Geometry, setup: Setup, half_fov_rad: float | None = None) -> Geometry:
    """The same ``stars`` arc with the star images of ``setup.stars`` (no orbit propagated again),
    in a field of half-width ``half_fov_rad`` (default the camera's)."""
    from dataclasses import replace

    field, sig = star_field_of(setup, geo.C, half_fov_rad)
    return replace(geo, stars=field, star_sigma_rad=sig)


def _camera_frame(X_true, X_ref, X_mars, roll_rad):
    """``A_c^i`` tracking Mars, rolled by ``roll_rad``, and the Mars vector in it at the
    reference and at the truth (paper eq. 3)."""
    los = X_mars[:, :3] - X_true[:, :3]
    C = camera.tracking_attitude(los, roll_rad)
    return C, np.einsum("kij,kj->ki", C, X_mars[:, :3] - X_ref[:, :3]), np.einsum("kij,kj->ki", C, los)


def with_roll_rate(geo: Geometry, rate_deg_s: float) -> Geometry:
    """The same arc with the camera rolling about its boresight at ``rate_deg_s`` (the
    ``roll`` variant's attitude at another rate; the orbit is not propagated again)."""
    from dataclasses import replace

    C, u_ref, u_true = _camera_frame(geo.X_true, geo.X_ref, geo.X_mars, camera.roll_angle(geo.t, rate_deg_s))
    return replace(geo, C=C, u_ref=u_ref, u_true=u_true, rho_ref=np.linalg.norm(u_ref, axis=1), variant="roll")


def measurement_variance(geo: Geometry, setup: Setup, sigma3_px) -> np.ndarray:
    """:meth:`Geometry.measurement_variance`, for callers holding the config as well: the
    geometry carries the camera it was built for, and a different ``camera.ifov_arcsec``
    in ``setup`` is an error, not a silent override."""
    ifov = setup.camera.ifov_arcsec
    if ifov != geo.ifov_arcsec:
        raise ValueError(f"approach.camera.ifov_arcsec = {ifov:g} differs from the geometry's {geo.ifov_arcsec:g}")
    return geo.measurement_variance(sigma3_px)


def seed_streams(base_seed: int, case_index: int, seed_indices) -> list[np.random.Generator]:
    """One generator per Monte-Carlo run: SeedSequence([base_seed, case_index, seed_index])."""
    return [np.random.default_rng(np.random.SeedSequence([base_seed, case_index, int(i)]))
            for i in seed_indices]


def simulate(geo: Geometry, Rvar: np.ndarray, theta_true_rad: np.ndarray,
             rngs: list[np.random.Generator]) -> tuple[np.ndarray, np.ndarray]:
    """Measurements z (S, n+1, 3) with the exact misalignment, and initial-error draws (S, 6).

    ``z_k = A_m_exact(theta) A(delta_k) A_c^i (X_M - r_true) + v_k`` with ``v_k ~ N(0, Rvar)``
    (``Rvar``: the pixel noise, :meth:`Geometry.pixel_variance`) and ``delta_k`` the Mars image's
    attitude-knowledge error (``geo.attitude_sigma_rad`` per axis, independent per sample; the
    true camera attitude is the known ``A_c^i`` turned by it, exactly); the initial-error draws
    are ``N(0, P_X0)`` samples used only in the ``sampled`` initial-error mode. Per run: the
    pixel noise, then the initial error, then the attitude errors from its stream (no attitude
    error: the same draws as without it).
    """
    A = camera.misalignment_exact(theta_true_rad)
    clean = geo.u_true @ A.T
    sd = np.sqrt(Rvar)
    n1 = clean.shape[0]
    L0 = np.linalg.cholesky(geo.P0)
    z, e0 = [], []
    for g in rngs:
        noise = g.standard_normal((n1, 3)) * sd
        e0.append(L0 @ g.standard_normal(6))
        if geo.attitude_sigma_rad > 0.0:
            rot = camera.misalignment_exact(geo.attitude_sigma_rad * g.standard_normal((n1, 3)))  # (n1, 3, 3)
            z.append(np.einsum("ij,kjl,kl->ki", A, rot, geo.u_true) + noise)
        else:
            z.append(clean + noise)
    z = np.stack(z)
    z[:, 0] = np.nan
    return z, np.stack(e0)


def prior_mean_deviation(geo: Geometry, e0_draws: np.ndarray, mode: str) -> np.ndarray:
    """Prior mean at t0 in deviation coordinates (S, 6): 0 in ``fixed`` mode (the
    reference *is* the prior mean); ``e_sampled - e_fixed`` in ``sampled`` mode."""
    if mode == "fixed":
        return np.zeros_like(e0_draws)
    if mode == "sampled":
        return e0_draws - geo.e_fixed
    raise ValueError(f"approach.initial_error.mode must be 'fixed' or 'sampled', got {mode!r}")


def arcsec(x):
    return np.asarray(x) / ARCSEC


def rad(x):
    return np.asarray(x, float) * ARCSEC
