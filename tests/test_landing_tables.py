import numpy as np

from opnav.config import load_config
from opnav.landing.scenario import error_bounds_table, initial_state_table
from conftest import REPO


def test_tables_render_config_beside_published():
    cfg = load_config(REPO / "config" / "config.yaml")["landing"]
    t1 = initial_state_table(cfg)
    assert list(t1["state"]) == ["position", "velocity", "attitude (roll, pitch, yaw)"]
    assert np.isclose(t1.loc[0, "norm (config)"], np.linalg.norm([3300, 5870, 6570]))
    t2 = error_bounds_table(cfg)
    # a uniform distribution on [-b, b] has standard deviation b / sqrt(3)
    assert np.allclose(t2["1-sigma"], t2["bound (config)"] / np.sqrt(3))
