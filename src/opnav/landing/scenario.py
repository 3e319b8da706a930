"""Paper B's simulation scenario: the ``landing`` config parsed once into the
frozen :class:`Scenario` shared by every run and method (truth trajectory,
noise-free IMU, landmark field, camera, process noise, filter and planner
settings; :func:`build_scenario`), the camera scenarios of the config
(:func:`camera_scenarios`), and the scenario as tables: initial state
(Table 1) and Monte-Carlo initial-error bounds (Table 2).

Units: position m, velocity m/s, attitude deg, frame {L} (landing site origin,
z up).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from opnav.core import published
from opnav.landing.trajectory import Truth, truth_states

if TYPE_CHECKING:  # pandas only for the B-T1/B-T2 tables: not imported by every Monte-Carlo job
    import pandas as pd

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


def _scenario_from_json(text: str) -> Scenario:
    # the simulation's parts imported here, where a scenario is built: the B-T1/B-T2 and
    # B-T3 summary jobs and the Snakefile parse use this module's config-only functions
    from opnav.landing import ekf, imu
    from opnav.landing.camera import camera_from_config
    from opnav.landing.landmarks import make_field
    from opnav.landing.planner import PlannerConfig, alternative_path
    from opnav.landing.methods import spec_items as methods_spec_items

    c = json.loads(text)
    T = float(c["duration_s"])
    Dt = float(c["filter"]["dt_s"])
    rate = float(c["imu"]["rate_hz"])
    n_sub = int(round(rate * Dt))
    if n_sub < 1 or abs(n_sub / rate - Dt) > 1e-9:
        raise ValueError(f"landing.imu.rate_hz ({rate}) times landing.filter.dt_s ({Dt}) "
                         "must be a positive integer")
    n_steps = int(round(T / Dt))
    if abs(n_steps * Dt - T) > 1e-9:
        raise ValueError(f"landing.duration_s ({T}) must be a multiple of landing.filter.dt_s ({Dt})")
    dt = Dt / n_sub
    g = np.asarray(c["gravity_mps2"], float)
    s0 = c["initial_state"]
    yaw = float(c.get("yaw_deg", 0.0))
    t_imu = np.arange(n_steps * n_sub + 1) * dt
    tr_imu = truth_states(t_imu, s0["r_m"], s0["v_mps"], T, g, yaw, c.get("terminal_accel_mps2"))
    tr = Truth(t=tr_imu.t[::n_sub], r=tr_imu.r[::n_sub], v=tr_imu.v[::n_sub],
               a=tr_imu.a[::n_sub], R_LtoB=tr_imu.R_LtoB[::n_sub])
    f, w = imu.synthesize(tr_imu.v, tr_imu.R_LtoB, dt, g)
    sa = float(c["imu"]["sigma_a_mps2"])
    sw = math.radians(float(c["imu"]["sigma_w_degps"]))
    pl = c["planner"]
    pcfg = PlannerConfig(t_s=Dt, n_sigma_v=float(pl["n_sigma_v"]), tol_rad=float(pl["tol_rad"]),
                         margin_px=float(pl["margin_px"]), eval_path=str(pl["eval_path"]),
                         noise_scale=float(c["filter"]["meas_noise_scale"]),
                         depth_sigma_frac=float(c["filter"]["depth_sigma_frac"]),
                         obs_per_landmark=int(c["filter"]["obs_per_landmark"]),
                         oc=bool(c["filter"]["observability_constrained"]),
                         g=tuple(float(x) for x in g),
                         custom=methods_spec_items(c.get("custom_methods")))
    lm = c["landmarks"]
    b = c["mc"]["bounds"]
    fl = c["filter"]
    return Scenario(truth=tr, truth_imu=tr_imu, f=f, w=w, g=g, dt_imu=dt, n_sub=n_sub, Dt=Dt,
                    n_steps=n_steps, Q=ekf.process_noise(sa, sw, dt, n_sub), sigma_a=sa, sigma_w=sw,
                    camera=camera_from_config(c["camera"]),
                    field=make_field(float(lm["half_width_m"]), int(lm["count"]), int(lm["seed"]),
                                     near_site=lm["near_site"]),
                    planner=pcfg, planner_alt=alternative_path(pcfg), obs_per_landmark=int(fl["obs_per_landmark"]),
                    depth_sigma_frac=float(fl["depth_sigma_frac"]),
                    min_update_alt=float(fl["min_update_altitude_m"]),
                    update_margin_m=float(fl["update_altitude_margin_m"]),
                    oc=bool(fl["observability_constrained"]),
                    iterations=int(fl["iterations"]),
                    noise_scale=float(fl["meas_noise_scale"]),
                    bounds=(float(b["r_m"]), float(b["v_mps"]), math.radians(float(b["att_deg"]))),
                    base_seed=int(c["mc"]["base_seed"]))


_KEYS = ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu", "camera", "landmarks",
         "filter", "planner", "mc", "custom_methods")


def build_scenario(landing_cfg: dict) -> Scenario:
    """The shared scenario of a ``landing`` config (cached per distinct config)."""
    sub = {k: landing_cfg[k] for k in _KEYS if k in landing_cfg}
    return _cached(json.dumps(sub, sort_keys=True))


@lru_cache(maxsize=4)
def _cached(text: str) -> Scenario:
    return _scenario_from_json(text)


def _vec(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


def derived_initial_attitude_deg(landing_cfg: dict) -> np.ndarray:
    """Our initial (roll, pitch, yaw), deg: body +z along the guidance thrust at
    t = 0 with the configured yaw (``opnav.landing.trajectory``)."""
    from opnav.landing.trajectory import euler_rpy_deg

    s = landing_cfg["initial_state"]
    tr = truth_states(np.array([0.0]), s["r_m"], s["v_mps"], float(landing_cfg["duration_s"]),
                      landing_cfg["gravity_mps2"], float(landing_cfg.get("yaw_deg", 0.0)),
                      landing_cfg.get("terminal_accel_mps2"))
    return euler_rpy_deg(tr.R_LtoB[0])


def thrust_tilt_azimuth_deg(landing_cfg: dict) -> tuple[float, float]:
    """Initial thrust axis (body +z in {L}) as (tilt from the vertical, azimuth
    from +x toward +y), deg."""

    s = landing_cfg["initial_state"]
    tr = truth_states(np.array([0.0]), s["r_m"], s["v_mps"], float(landing_cfg["duration_s"]),
                      landing_cfg["gravity_mps2"], float(landing_cfg.get("yaw_deg", 0.0)),
                      landing_cfg.get("terminal_accel_mps2"))
    z = tr.R_LtoB[0][2]
    return (float(np.degrees(np.arccos(np.clip(z[2], -1.0, 1.0)))),
            float(np.degrees(np.arctan2(z[1], z[0]))))


def initial_attitude_report(landing_cfg: dict) -> dict:
    """Our initial attitude in the convention that matches the paper's Table 1
    triple: ``-(yaw, pitch, roll)`` of the Z-Y-X sequence with roll 0 that
    points body +z along the initial thrust, i.e. ``-(azimuth, tilt, 0)``
    (deg). The tilt follows from the Table 1 state and the touchdown; the
    azimuth also from the unstated terminal horizontal acceleration."""
    tilt, az = thrust_tilt_azimuth_deg(landing_cfg)
    return {"paper_convention_deg": [-az, -tilt, 0.0], "tilt_deg": tilt, "azimuth_deg": az,
            "rpy_deg": [float(x) for x in derived_initial_attitude_deg(landing_cfg)]}


def initial_state_table(landing_cfg: dict) -> "pd.DataFrame":
    """B-T1: the lander's initial state in {L} (paper Table 1), config beside
    published, and the simulation's initial state (the attitude derived from the
    guidance thrust direction)."""
    s = landing_cfg["initial_state"]
    pub = published.paper_b()["table1_initial_state"]
    att = initial_attitude_report(landing_cfg)["paper_convention_deg"]
    rows = [
        ("position", "m", s["r_m"], pub["r_m"], s["r_m"]),
        ("velocity", "m/s", s["v_mps"], pub["v_mps"], s["v_mps"]),
        ("attitude -(yaw, pitch, roll), Z-Y-X, roll 0", "deg", s["att_deg"], pub["att_deg"],
         np.round(att, 2)),
    ]
    import pandas as pd

    return pd.DataFrame(
        {
            "state": [r[0] for r in rows],
            "unit": [r[1] for r in rows],
            "config": [_vec(r[2]) for r in rows],
            "published": [_vec(r[3]) for r in rows],
            "simulated (ours)": [_vec(r[4]) for r in rows],
            "norm (config)": [float(np.linalg.norm(r[2])) for r in rows],
        }
    )


def error_bounds_table(landing_cfg: dict) -> "pd.DataFrame":
    """B-T2: Monte-Carlo initial-error bounds (paper Table 2), uniform per axis."""
    b = landing_cfg["mc"]["bounds"]
    pub = published.paper_b()["table2_error_bounds"]
    n = landing_cfg["mc"]["n_runs"]
    rows = [
        ("position", "m", b["r_m"], pub["r_m"]),
        ("velocity", "m/s", b["v_mps"], pub["v_mps"]),
        ("attitude", "deg", b["att_deg"], pub["att_deg"]),
    ]
    import pandas as pd

    return pd.DataFrame(
        {
            "state": [r[0] for r in rows],
            "unit": [r[1] for r in rows],
            "bound (config)": [float(r[2]) for r in rows],
            "bound (published)": [float(r[3]) for r in rows],
            "distribution": ["uniform in [-bound, +bound] per axis"] * 3,
            "1-sigma": [float(r[2]) / np.sqrt(3.0) for r in rows],
            "runs": [n] * 3,
        }
    )


def camera_scenarios(landing_cfg: dict) -> dict[str, dict]:
    """The ``landing`` config of every camera scenario (``landing.scenarios``:
    name -> overlay on ``landing.camera``), in config order; each holds the
    merged ``camera`` and no ``scenarios`` key. Raises ``ValueError`` naming
    ``landing.headline_scenario`` if it is not one of the scenarios."""
    scen = landing_cfg.get("scenarios") or {"default": {}}
    head = landing_cfg.get("headline_scenario")
    if head is not None and head not in scen:
        raise ValueError(f"landing.headline_scenario: {head!r} is not one of landing.scenarios "
                         f"({', '.join(scen)})")
    out = {}
    for name, overlay in scen.items():
        cfg = {k: v for k, v in landing_cfg.items() if k not in ("scenarios", "headline_scenario")}
        cfg["camera"] = {**landing_cfg["camera"], **(overlay or {})}
        out[name] = cfg
    return out


def headline_scenario(landing_cfg: dict) -> str:
    """The scenario the manuscript leads with (validated by :func:`camera_scenarios`)."""
    scen = camera_scenarios(landing_cfg)
    return landing_cfg.get("headline_scenario") or next(iter(scen))
