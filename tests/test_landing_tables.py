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


def test_b_t1_shows_our_thrust_derived_attitude():
    cfg = load_config(REPO / "config" / "config.yaml")["landing"]
    t1 = initial_state_table(cfg)
    assert "simulated (ours)" in t1.columns
    att = t1.loc[2, "simulated (ours)"]
    assert att != t1.loc[2, "published"]           # ours is computed, not copied
    assert t1.loc[0, "simulated (ours)"] == t1.loc[0, "config"]
