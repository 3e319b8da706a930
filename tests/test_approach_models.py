"""Paper A models: dynamics/STM, camera misalignment sign, measurement Jacobians, noise."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from opnav.approach import camera, dynamics, ekf
from opnav.approach import scenario as sc
from opnav.approach.dynamics import ARCSEC

from approach_helpers import approach_cfg, approach_setup


@pytest.fixture(scope="module")
def geo():
    cfg = approach_setup(N0=10, N=10, L=2)
    return cfg, sc.build_geometry(cfg, "literal")


def test_mars_kepler_velocity_is_derivative_of_position():
    el = dynamics.KeplerElements.from_config(approach_cfg()["mars_elements"])
    h = 10.0
    X = dynamics.kepler_state(el, np.array([-h, 0.0, h]))
    fd = (X[2, :3] - X[0, :3]) / (2 * h)
    np.testing.assert_allclose(X[1, 3:], fd, rtol=1e-9)
    assert abs(np.linalg.norm(X[1, :3]) / dynamics.AU_KM - 1.5) < 0.2


def test_start_is_1e6_km_from_mars_and_approaching(geo):
    cfg, g = geo
    rel = g.X_true[:, :3] - g.X_mars[:, :3]
    d = np.linalg.norm(rel, axis=1)
    assert d[0] == pytest.approx(1.0e6, rel=1e-9)
    assert d[-1] < d[0]


def test_stm_matches_finite_differences_of_the_flow(geo):
    cfg, g = geo
    el = cfg.mars
    t = g.t[:3]
    _, Phi = dynamics.propagate_with_stm(g.X_ref[0], t, el)
    Phi20 = Phi[2] @ Phi[1]
    fd = np.empty((6, 6))
    for j in range(6):
        h = 10.0 if j < 3 else 1e-2
        dp = np.zeros(6); dp[j] = h
        fd[:, j] = (dynamics.propagate(g.X_ref[0] + dp, t, el)[2]
                    - dynamics.propagate(g.X_ref[0] - dp, t, el)[2]) / (2 * h)
    np.testing.assert_allclose(Phi20, fd, atol=2e-6)


def test_linearised_propagation_matches_nonlinear_for_the_paper_initial_error(geo):
    """The 'verified linearisation' of SPEC A.1: Phi dX vs the nonlinear flow, dX ~ 170 km."""
    cfg, g = geo
    el = cfg.mars
    n = len(g.t) - 1
    Phi_cum = np.eye(6)
    for k in range(1, n + 1):
        Phi_cum = g.Phi[k] @ Phi_cum
    X_true = dynamics.propagate(g.X_ref[0] - g.e_fixed, g.t, el)
    np.testing.assert_allclose(X_true[-1] - g.X_ref[-1], Phi_cum @ (-g.e_fixed), atol=1e-6)


def test_small_angle_matrix_is_paper_eq5():
    tx, ty, tz = 1e-4, 2e-4, 3e-4
    expect = np.array([[1, tz, -ty], [-tz, 1, tx], [ty, -tx, 1]])
    np.testing.assert_allclose(camera.misalignment_small([tx, ty, tz]), expect)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
def test_exact_rotation_has_eq5_as_derivative(direction):
    """Sign pin: d/d(theta) of the exact rotation at 0 equals the small-angle matrix's slope."""
    d = np.asarray(direction)
    h = 1e-6
    fd = (camera.misalignment_exact(h * d) - camera.misalignment_exact(-h * d)) / (2 * h)
    np.testing.assert_allclose(fd, camera.misalignment_small(d) - np.eye(3), atol=1e-8)
    R = camera.misalignment_exact(20 * ARCSEC * d)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)


def test_positive_tx_moves_boresight_vector_along_minus_y():
    """Eq. 5 with tx>0 maps (0,0,rho) to (0, rho*tx, rho) ... check sign explicitly."""
    rho = 1e6
    u = np.array([0.0, 0.0, rho])
    tx = 10 * ARCSEC
    z = camera.misalignment_exact([tx, 0, 0]) @ u
    # eq. 5: y-component = tx * rho (row 2: [-tz, 1, tx])
    assert z[1] == pytest.approx(tx * rho, rel=1e-6)
    z = camera.misalignment_exact([0, 0, 10 * ARCSEC]) @ u  # roll about boresight
    np.testing.assert_allclose(z, u, atol=1e-9)


def test_measurement_jacobians_match_finite_differences(geo):
    cfg, g = geo
    rng = np.random.default_rng(3)
    theta = rng.normal(size=(1, 3)) * 20 * ARCSEC
    dx = rng.normal(size=(1, 6)) * np.r_[100, 100, 100, 0.1, 0.1, 0.1]
    k = 5
    H = ekf.measurement_jacobian(theta, g.C[k])[0]
    fd = np.empty((3, 6))
    for j in range(6):
        h = 1e-2
        e = np.zeros((1, 6)); e[0, j] = h
        fd[:, j] = (ekf.predicted_measurement(theta, g.C[k], g.u_ref[k], dx + e)
                    - ekf.predicted_measurement(theta, g.C[k], g.u_ref[k], dx - e))[0] / (2 * h)
    np.testing.assert_allclose(H, fd, atol=1e-8)
    # H has the minus sign of SPEC A.2 (derivative w.r.t. the spacecraft position)
    np.testing.assert_allclose(H[:, :3], -camera.misalignment_small(theta[0]) @ g.C[k])
    # d z / d theta = [u x] for the truth's exact rotation at theta = 0
    u = g.u_true[k]
    fdt = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3); e[j] = 1e-7
        fdt[:, j] = (camera.misalignment_exact(e) @ u - camera.misalignment_exact(-e) @ u) / 2e-7
    np.testing.assert_allclose(fdt, camera.skew(u), rtol=1e-6, atol=1e-3)
    assert np.allclose(fdt[:, 2], 0.0, atol=1e-3 * np.linalg.norm(u))  # tz: no effect


def test_camera_tracks_mars_and_roll_keeps_boresight(geo):
    cfg, g = geo
    u = g.u_true
    np.testing.assert_allclose(u[:, :2] / u[:, 2:], 0.0, atol=1e-12)
    groll = sc.build_geometry(cfg, "roll")
    np.testing.assert_allclose(groll.C[:, 2], g.C[:, 2], atol=1e-12)
    ang = np.arctan2(np.einsum("ki,ki->k", groll.C[:, 0], g.C[:, 1]),
                     np.einsum("ki,ki->k", groll.C[:, 0], g.C[:, 0]))
    np.testing.assert_allclose(np.rad2deg(ang), cfg.roll.rate_deg_s * g.t, atol=1e-9)


def test_pinhole_noise_conversion():
    rho = np.array([1.0e6])
    s = camera.noise_sigma_km(rho, 10.0, (0.3, 0.3, 0.6))[0]
    assert s[0] == pytest.approx(1.0e6 * 10 * ARCSEC * 0.1)
    alpha = np.arcsin(dynamics.R_MARS_KM / 1.0e6)
    # range from the radius: finite difference of rho(alpha) = R_M / sin(alpha)
    da = 10 * ARCSEC * 0.2
    fd = abs(dynamics.R_MARS_KM / np.sin(alpha + da / 2) - dynamics.R_MARS_KM / np.sin(alpha - da / 2))
    assert s[2] == pytest.approx(fd, rel=1e-5)
