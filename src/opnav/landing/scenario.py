"""Paper B's simulation scenario as tables: initial state (Table 1) and
Monte-Carlo initial-error bounds (Table 2), rendered from the config.

Units: position m, velocity m/s, attitude deg, frame {L} (landing site origin,
z up).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from opnav import published


def _vec(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


def derived_initial_attitude_deg(landing_cfg: dict) -> np.ndarray:
    """Our initial (roll, pitch, yaw), deg: body +z along the guidance thrust at
    t = 0 with the configured yaw (``opnav.landing.trajectory``)."""
    from opnav.landing.trajectory import euler_rpy_deg, truth_states

    s = landing_cfg["initial_state"]
    tr = truth_states(np.array([0.0]), s["r_m"], s["v_mps"], float(landing_cfg["duration_s"]),
                      landing_cfg["gravity_mps2"], float(landing_cfg.get("yaw_deg", 0.0)),
                      landing_cfg.get("terminal_accel_mps2"))
    return euler_rpy_deg(tr.R_LtoB[0])


def thrust_tilt_azimuth_deg(landing_cfg: dict) -> tuple[float, float]:
    """Initial thrust axis (body +z in {L}) as (tilt from the vertical, azimuth
    from +x toward +y), deg."""
    from opnav.landing.trajectory import truth_states

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


def initial_state_table(landing_cfg: dict) -> pd.DataFrame:
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


def error_bounds_table(landing_cfg: dict) -> pd.DataFrame:
    """B-T2: Monte-Carlo initial-error bounds (paper Table 2), uniform per axis."""
    b = landing_cfg["mc"]["bounds"]
    pub = published.paper_b()["table2_error_bounds"]
    n = landing_cfg["mc"]["n_runs"]
    rows = [
        ("position", "m", b["r_m"], pub["r_m"]),
        ("velocity", "m/s", b["v_mps"], pub["v_mps"]),
        ("attitude", "deg", b["att_deg"], pub["att_deg"]),
    ]
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
