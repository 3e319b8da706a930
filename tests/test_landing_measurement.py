"""Finite-difference checks of the bearing Jacobians (paper B eq. 15-18) and of
the attitude-error convention R_LtoB_true = Exp(-dtheta) R_LtoB_est."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from opnav.landing.measurement import BehindCameraError, bearing, bearing_jacobian
from opnav.rotations import exp_so3, skew


def _case(seed):
    rng = np.random.default_rng(seed)
    r = rng.uniform(-5000, 5000, 3) + np.array([0, 0, 6000.0])
    p = np.r_[rng.uniform(-8000, 8000, 2), 0.0]
    R = Rotation.random(random_state=rng).as_matrix()
    return r, R, p


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_jacobians_match_central_differences(seed):
    r, R, p = _case(seed)
    Hr, Ht, Hp = bearing_jacobian(r, R, p)
    h, ha = 1e-2, 1e-6
    for j in range(3):
        e = np.eye(3)[j]
        fd_r = (bearing(r + h * e, R, p) - bearing(r - h * e, R, p)) / (2 * h)
        fd_p = (bearing(r, R, p + h * e) - bearing(r, R, p - h * e)) / (2 * h)
        # attitude error on the body side: R_true = Exp(-dtheta) R_est
        fd_t = (bearing(r, exp_so3(-ha * e) @ R, p) - bearing(r, exp_so3(ha * e) @ R, p)) / (2 * ha)
        np.testing.assert_allclose(Hr[:, j], fd_r, rtol=1e-5, atol=1e-10)
        np.testing.assert_allclose(Hp[:, j], fd_p, rtol=1e-5, atol=1e-10)
        np.testing.assert_allclose(Ht[:, j], fd_t, rtol=1e-5, atol=1e-9)


def test_exp_so3_matches_scipy_and_small_angle_convention():
    rng = np.random.default_rng(1)
    for _ in range(20):
        phi = rng.normal(size=3)
        np.testing.assert_allclose(exp_so3(phi), Rotation.from_rotvec(phi).as_matrix(), atol=1e-12)
    d = np.array([1e-7, -2e-7, 3e-7])
    np.testing.assert_allclose(exp_so3(-d), np.eye(3) - skew(d), atol=1e-13)
    np.testing.assert_allclose(skew(d) @ np.array([1.0, 2, 3]), np.cross(d, [1.0, 2, 3]))


def test_bearing_is_unit_and_points_at_landmark():
    r, R, p = _case(3)
    b = bearing(r, R, p)
    assert np.isclose(np.linalg.norm(b), 1.0)
    np.testing.assert_allclose(R.T @ b, (p - r) / np.linalg.norm(p - r), atol=1e-12)


def test_zero_range_is_a_clear_error():
    with pytest.raises(BehindCameraError):
        bearing(np.zeros(3), np.eye(3), np.zeros(3))
    with pytest.raises(ValueError):
        bearing(np.array([np.nan, 0, 0]), np.eye(3), np.zeros(3))
