import numpy as np

from opnav.core.config import load_config
from opnav.report.landing.tables import error_bounds_table, initial_state_table
from opnav.landing.setup import Setup
from conftest import REPO


def test_tables_render_config_beside_published():
    cfg = Setup.from_config(load_config(REPO / "config" / "config.yaml")["landing"])
    t1 = initial_state_table(cfg)
    assert list(t1["state"]) == ["position", "velocity", "attitude -(yaw, pitch, roll), Z-Y-X, roll 0"]
    assert np.isclose(t1.loc[0, "norm (config)"], np.linalg.norm([3300, 5870, 6570]))
    t2 = error_bounds_table(cfg)
    # a uniform distribution on [-b, b] has standard deviation b / sqrt(3)
    assert np.allclose(t2["1-sigma"], t2["bound (config)"] / np.sqrt(3))


def test_b_t1_shows_our_thrust_derived_attitude():
    cfg = Setup.from_config(load_config(REPO / "config" / "config.yaml")["landing"])
    t1 = initial_state_table(cfg)
    assert "simulated (ours)" in t1.columns
    att = t1.loc[2, "simulated (ours)"]
    assert att != t1.loc[2, "published"]           # ours is computed, not copied
    assert t1.loc[0, "simulated (ours)"] == t1.loc[0, "config"]


def test_initial_attitude_in_the_papers_convention():
    """-(yaw, pitch, roll) of the roll-0 Z-Y-X attitude whose body +z is the
    initial thrust: rebuilding R_BtoL = Rz(yaw) Ry(pitch) from the triple must
    give back that thrust axis; a terminal horizontal acceleration turns the
    azimuth and hardly the tilt."""
    from scipy.spatial.transform import Rotation

    from opnav.landing.scenario import initial_attitude_report
    from opnav.landing.trajectory import truth_states

    cfg = Setup.from_config(load_config(REPO / "config" / "config.yaml")["landing"])
    rep = initial_attitude_report(cfg)
    yaw, pitch, roll = (-x for x in rep.paper_convention_deg)
    R_BtoL = Rotation.from_euler("ZYX", [yaw, pitch, roll], degrees=True).as_matrix()
    s = cfg.initial_state
    tr = truth_states(np.array([0.0]), s.r_m, s.v_mps, cfg.duration_s, cfg.gravity_mps2)
    np.testing.assert_allclose(R_BtoL[:, 2], tr.R_LtoB[0][2], atol=1e-12)
    other = cfg.replace(terminal_accel_mps2=(0.0, 0.3))
    rep2 = initial_attitude_report(other)
    assert abs(rep2.azimuth_deg - rep.azimuth_deg) > 1.0
    tr2 = truth_states(np.array([cfg.duration_s]), s.r_m, s.v_mps, cfg.duration_s,
                       cfg.gravity_mps2, a_T=[0.0, 0.3])
    np.testing.assert_allclose(tr2.a[0], [0.0, 0.3, 0.0], atol=1e-9)
    np.testing.assert_allclose(tr2.r[0], 0.0, atol=1e-6)
