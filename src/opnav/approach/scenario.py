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
Units: km, km/s, s, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import camera, dynamics
from .dynamics import ARCSEC
from .ekf import Window

VARIANTS = ("literal", "prior", "roll", "reference-start")
START_OF = {"literal": "filter", "prior": "prior", "roll": "prior", "reference-start": "truth"}


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

    @property
    def dx_true(self) -> np.ndarray:
        """True deviation from the reference (n+1, 6)."""
        return self.X_true - self.X_ref

    def window(self, Rvar: np.ndarray) -> Window:
        return Window(self.Phi, self.C, self.u_ref, Rvar, self.Q)


def initial_truth(cfg: dict) -> np.ndarray:
    """Heliocentric truth state at t0: Mars state + hyperbolic approach state (km, km/s)."""
    el = dynamics.KeplerElements.from_config(cfg["mars_elements"])
    g = cfg["geometry"]
    Xm = dynamics.kepler_state(el, 0.0)
    d = np.asarray(g["v_inf_dir"], float)
    d /= np.linalg.norm(d)
    perp = np.cross(d, [0.0, 0.0, 1.0])
    perp /= np.linalg.norm(perp)
    r_rel = -g["range_km"] * d + g["aim_offset_km"] * perp
    r_rel *= g["range_km"] / np.linalg.norm(r_rel)
    vmag = np.sqrt(g["v_inf_kms"] ** 2 + 2.0 * dynamics.MU_MARS / g["range_km"])
    return Xm + np.concatenate([r_rel, vmag * d])


def n_samples(cfg: dict) -> int:
    """Samples after t0 that the arc needs: N0 + L*N."""
    s = cfg["segments"]
    return s["N0"] + s["L"] * s["N"]


def mars_disc_px(range_km: float, ifov_arcsec: float) -> float:
    """Apparent diameter of Mars, px, seen from ``range_km`` (km, > Mars radius)
    with pixels of ``ifov_arcsec`` arcsec."""
    return 2.0 * np.rad2deg(np.arcsin(dynamics.R_MARS_KM / range_km)) * 3600.0 / ifov_arcsec


def build_geometry(cfg: dict, variant: str, n: int | None = None) -> Geometry:
    """Truth, reference with STMs, attitude of ``variant`` (see module docstring)."""
    if variant not in VARIANTS:
        raise ValueError(f"unknown approach variant {variant!r}; use one of {VARIANTS}")
    n = n_samples(cfg) if n is None else n
    dt = cfg["dt_s"]
    t = dt * np.arange(n + 1)
    el = dynamics.KeplerElements.from_config(cfg["mars_elements"])
    X0 = initial_truth(cfg)
    X_true = dynamics.propagate(X0, t, el)
    ie = cfg["initial_error"]
    e_fixed = np.concatenate([ie["r_km"], ie["v_kms"]]).astype(float)
    X_ref, Phi = dynamics.propagate_with_stm(X0 + e_fixed, t, el)
    X_mars = dynamics.kepler_state(el, t)
    los = X_mars[:, :3] - X_true[:, :3]
    roll_cfg = cfg["roll"]
    roll = (camera.roll_angle(t, roll_cfg["rate_deg_s"], roll_cfg["steps_deg"],
                              roll_cfg["step_interval_s"]) if variant == "roll" else np.zeros_like(t))
    rho = np.linalg.norm(los, axis=1)
    disc_px = mars_disc_px(rho.min(), cfg["camera"]["ifov_arcsec"])
    if disc_px > cfg["camera"]["pixels"]:
        raise ValueError(f"approach.camera: Mars ({disc_px:.0f} px across) does not fit the "
                         f"{cfg['camera']['pixels']} px detector; raise camera.ifov_arcsec or the range")
    C = camera.tracking_attitude(los, roll)
    u_ref = np.einsum("kij,kj->ki", C, X_mars[:, :3] - X_ref[:, :3])
    u_true = np.einsum("kij,kj->ki", C, los)
    ps = cfg["prior_sigma"]
    P0 = np.diag(np.r_[np.full(3, ps["r_km"] ** 2), np.full(3, ps["v_kms"] ** 2)])
    Q = np.diag(np.asarray(cfg["process_noise_diag"], float))
    return Geometry(t, X_true, X_ref, X_mars, Phi, C, u_ref, u_true,
                    np.linalg.norm(u_ref, axis=1), Q, P0, e_fixed, variant)


def measurement_variance(geo: Geometry, cfg: dict, sigma3_px) -> np.ndarray:
    """Rvar (n+1, 3), km^2, from the pinhole camera at the reference range."""
    return camera.noise_sigma_km(geo.rho_ref, cfg["camera"]["ifov_arcsec"], sigma3_px) ** 2


def seed_streams(base_seed: int, case_index: int, seed_indices) -> list[np.random.Generator]:
    """One generator per Monte-Carlo run: SeedSequence([base_seed, case_index, seed_index])."""
    return [np.random.default_rng(np.random.SeedSequence([base_seed, case_index, int(i)]))
            for i in seed_indices]


def simulate(geo: Geometry, Rvar: np.ndarray, theta_true_rad: np.ndarray,
             rngs: list[np.random.Generator]) -> tuple[np.ndarray, np.ndarray]:
    """Measurements z (S, n+1, 3) with the exact misalignment, and initial-error draws (S, 6).

    ``z_k = A_m_exact(theta) A_c^i (X_M - r_true) + v_k``; the draws are
    ``N(0, P_X0)`` samples used only in the ``sampled`` initial-error mode.
    """
    A = camera.misalignment_exact(theta_true_rad)
    clean = geo.u_true @ A.T
    sd = np.sqrt(Rvar)
    n1 = clean.shape[0]
    L0 = np.linalg.cholesky(geo.P0)
    z, e0 = [], []
    for g in rngs:
        noise = g.standard_normal((n1, 3)) * sd
        z.append(clean + noise)
        e0.append(L0 @ g.standard_normal(6))
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
