"""Paper B's simulation scenario: the landing :class:`~opnav.landing.setup.Setup` built into the
frozen :class:`Scenario` shared by every run and method (truth trajectory,
noise-free IMU, landmark field, camera, process noise, filter and planner
settings; :func:`build_scenario`), the nominal guidance trajectory (:func:`nominal_truth`),
and the initial attitude (:class:`InitialAttitude`); the scenario as tables (B-T1, B-T2) is the
report layer's (``opnav.report.landing.tables``). The camera scenarios of the config
are ``Setup.scenarios_by_name`` (and ``setup.scenario_sections``, the workflow's mappings).

Units: position m, velocity m/s, attitude deg, frame {L} (landing site origin,
z up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from opnav.landing.setup import Setup
from opnav.landing.trajectory import Truth, nominal_truth

if TYPE_CHECKING:
    from opnav.landing.camera import Camera
    from opnav.landing.landmarks import LandmarkField
    from opnav.landing.planner import PlannerConfig


@dataclass(frozen=True)
class Scenario:
    truth: Truth               # at the filter times (n_steps + 1)
    truth_imu: Truth           # at the IMU nodes
    f: np.ndarray              # noise-free IMU specific force (m, 3)
    w: np.ndarray              # noise-free IMU rate (m, 3)
    g: np.ndarray
    dt_imu: float
    n_sub: int
    Dt: float
    n_steps: int
    Q: np.ndarray
    sigma_a: float
    sigma_w: float             # rad/s
    camera: Camera
    field: LandmarkField
    planner: PlannerConfig
    planner_alt: PlannerConfig  # the same on the alternative metric evaluation path (timing)
    obs_per_landmark: int
    depth_sigma_frac: float
    min_update_alt: float
    update_margin_m: float     # vision cut-off margin on the estimated altitude, m
    oc: bool                   # observability-constrained EKF (ekf.oc_transition)
    iterations: int            # iterated-EKF relinearisations per update
    noise_scale: float         # filter bearing noise / true pixel noise
    bounds: tuple              # (m, m/s, rad)
    base_seed: int


def _scenario(setup: Setup) -> Scenario:
    # the simulation's parts imported here, where a scenario is built: the B-T1/B-T2 and
    # B-T3 summary jobs and the Snakefile parse use this module's config-only functions
    from opnav.landing import ekf, imu
    from opnav.landing.camera import make_camera
    from opnav.landing.landmarks import make_field
    from opnav.landing.planner import PlannerConfig, alternative_path

    T = float(setup.duration_s)
    Dt = float(setup.filter.dt_s)
    rate = float(setup.imu.rate_hz)
    n_sub = int(round(rate * Dt))
    if n_sub < 1 or abs(n_sub / rate - Dt) > 1e-9:
        raise ValueError(f"landing.imu.rate_hz ({rate}) times landing.filter.dt_s ({Dt}) "
                         "must be a positive integer")
    n_steps = int(round(T / Dt))
    if abs(n_steps * Dt - T) > 1e-9:
        raise ValueError(f"landing.duration_s ({T}) must be a multiple of landing.filter.dt_s ({Dt})")
    dt = Dt / n_sub
    g = np.asarray(setup.gravity_mps2, float)
    t_imu = np.arange(n_steps * n_sub + 1) * dt
    tr_imu = nominal_truth(setup, t_imu)
    tr = Truth(t=tr_imu.t[::n_sub], r=tr_imu.r[::n_sub], v=tr_imu.v[::n_sub],
               a=tr_imu.a[::n_sub], R_LtoB=tr_imu.R_LtoB[::n_sub])
    f, w = imu.synthesize(tr_imu.v, tr_imu.R_LtoB, dt, g)
    sa = float(setup.imu.sigma_a_mps2)
    sw = math.radians(float(setup.imu.sigma_w_degps))
    pl, fl = setup.planner, setup.filter
    pcfg = PlannerConfig(t_s=Dt, n_sigma_v=float(pl.n_sigma_v), tol_rad=float(pl.tol_rad),
                         margin_px=float(pl.margin_px), eval_path=str(pl.eval_path),
                         noise_scale=float(fl.meas_noise_scale),
                         depth_sigma_frac=float(fl.depth_sigma_frac),
                         obs_per_landmark=int(fl.obs_per_landmark),
                         oc=bool(fl.observability_constrained),
                         g=tuple(float(x) for x in g),
                         custom=setup.custom_items)
    lm = setup.landmarks
    b = setup.mc.bounds
    return Scenario(truth=tr, truth_imu=tr_imu, f=f, w=w, g=g, dt_imu=dt, n_sub=n_sub, Dt=Dt,
                    n_steps=n_steps, Q=ekf.process_noise(sa, sw, dt, n_sub), sigma_a=sa, sigma_w=sw,
                    camera=make_camera(setup.camera),
                    field=make_field(float(lm.half_width_m), int(lm.count), int(lm.seed), near_site=lm.near_site),
                    planner=pcfg, planner_alt=alternative_path(pcfg), obs_per_landmark=int(fl.obs_per_landmark),
                    depth_sigma_frac=float(fl.depth_sigma_frac),
                    min_update_alt=float(fl.min_update_altitude_m),
                    update_margin_m=float(fl.update_altitude_margin_m),
                    oc=bool(fl.observability_constrained),
                    iterations=int(fl.iterations),
                    noise_scale=float(fl.meas_noise_scale),
                    bounds=(float(b.r_m), float(b.v_mps), math.radians(float(b.att_deg))),
                    base_seed=int(setup.mc.base_seed))


def build_scenario(setup: Setup) -> Scenario:
    """The shared scenario of a landing :class:`~opnav.landing.setup.Setup` (cached per distinct setup)."""
    if not isinstance(setup, Setup):
        raise TypeError(f"build_scenario: expected a landing Setup (opnav.landing.setup), got {type(setup).__name__}")
    return _cached(setup)


@lru_cache(maxsize=4)
def _cached(setup: Setup) -> Scenario:
    return _scenario(setup)


def derived_initial_attitude_deg(setup: Setup) -> np.ndarray:
    """Our initial (roll, pitch, yaw), deg: body +z along the guidance thrust at
    t = 0 with the configured yaw (``opnav.landing.trajectory``)."""
    from opnav.landing.trajectory import euler_rpy_deg

    return euler_rpy_deg(nominal_truth(setup, [0.0]).R_LtoB[0])


def thrust_tilt_azimuth_deg(setup: Setup) -> tuple[float, float]:
    """Initial thrust axis (body +z in {L}) as (tilt from the vertical, azimuth
    from +x toward +y), deg."""
    z = nominal_truth(setup, [0.0]).R_LtoB[0][2]
    return (float(np.degrees(np.arccos(np.clip(z[2], -1.0, 1.0)))),
            float(np.degrees(np.arctan2(z[1], z[0]))))


@dataclass(frozen=True)
class InitialAttitude:
    """Our initial attitude in the convention that matches the paper's Table 1 triple:
    ``paper_convention_deg`` = ``-(yaw, pitch, roll)`` of the Z-Y-X sequence with roll 0 that
    points body +z along the initial thrust, i.e. ``-(azimuth, tilt, 0)`` (deg); the thrust's
    tilt and azimuth (deg) and our roll/pitch/yaw (deg). The tilt follows from the Table 1 state
    and the touchdown; the azimuth also from the unstated terminal horizontal acceleration."""

    paper_convention_deg: list
    tilt_deg: float
    azimuth_deg: float
    rpy_deg: list


def initial_attitude_report(setup: Setup) -> InitialAttitude:
    """:class:`InitialAttitude` of ``setup``'s descent."""
    tilt, az = thrust_tilt_azimuth_deg(setup)
    return InitialAttitude([-az, -tilt, 0.0], tilt, az, [float(x) for x in derived_initial_attitude_deg(setup)])
