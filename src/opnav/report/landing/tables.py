"""B-T1 and B-T2 of paper B: the scenario as tables (the lander's initial state in {L}, paper
Table 1, config beside published and the simulated attitude; the Monte-Carlo initial-error
bounds, paper Table 2), rendered from the landing setup (``opnav.landing.setup.Setup``).

Units: m, m/s, deg.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from opnav.core import published
from opnav.landing.scenario import initial_attitude_report

if TYPE_CHECKING:
    import pandas as pd

    from opnav.landing.setup import Setup

__all__ = ["initial_state_table", "error_bounds_table"]


def _vec(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


def initial_state_table(setup: Setup) -> "pd.DataFrame":
    """B-T1: the lander's initial state in {L} (paper Table 1), config beside
    published, and the simulation's initial state (the attitude derived from the
    guidance thrust direction)."""
    s = setup.initial_state
    pub = published.paper_b()["table1_initial_state"]
    att = initial_attitude_report(setup).paper_convention_deg
    rows = [
        ("position", "m", s.r_m, pub["r_m"], s.r_m),
        ("velocity", "m/s", s.v_mps, pub["v_mps"], s.v_mps),
        ("attitude -(yaw, pitch, roll), Z-Y-X, roll 0", "deg", s.att_deg, pub["att_deg"],
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


def error_bounds_table(setup: Setup) -> "pd.DataFrame":
    """B-T2: Monte-Carlo initial-error bounds (paper Table 2), uniform per axis."""
    b = setup.mc.bounds
    pub = published.paper_b()["table2_error_bounds"]
    n = setup.mc.n_runs
    rows = [
        ("position", "m", b.r_m, pub["r_m"]),
        ("velocity", "m/s", b.v_mps, pub["v_mps"]),
        ("attitude", "deg", b.att_deg, pub["att_deg"]),
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
