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
                      landing_cfg["gravity_mps2"], float(landing_cfg.get("yaw_deg", 0.0)))
    return euler_rpy_deg(tr.R_LtoB[0])


def initial_state_table(landing_cfg: dict) -> pd.DataFrame:
    """B-T1: the lander's initial state in {L} (paper Table 1), config beside
    published, and the simulation's initial state (the attitude derived from the
    guidance thrust direction)."""
    s = landing_cfg["initial_state"]
    pub = published.paper_b()["table1_initial_state"]
    att = derived_initial_attitude_deg(landing_cfg)
    rows = [
        ("position", "m", s["r_m"], pub["r_m"], s["r_m"]),
        ("velocity", "m/s", s["v_mps"], pub["v_mps"], s["v_mps"]),
        ("attitude (roll, pitch, yaw)", "deg", s["att_deg"], pub["att_deg"], np.round(att, 2)),
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
