"""Paper B truth, IMU and filter propagation: guidance constraints, zero-noise
dead reckoning, and the transition matrix (eq. 6-10) against finite differences."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from opnav.landing import ekf, imu
from opnav.landing.trajectory import euler_rpy_deg, guidance_coefficients, truth_states

R0 = [3300.0, 5870.0, 6570.0]
V0 = [-56.0, -66.0, -90.0]
G = [0.0, 0.0, -3.711]
T = 198.0


def test_guidance_meets_touchdown_and_thrust_attitude():
    t = np.linspace(0, T, 1981)
    tr = truth_states(t, R0, V0, T, G)
    np.testing.assert_allclose(tr.r[0], R0)
    np.testing.assert_allclose(tr.v[0], V0)
    np.testing.assert_allclose(tr.r[-1], 0, atol=1e-8)
    np.testing.assert_allclose(tr.v[-1], 0, atol=1e-10)
    np.testing.assert_allclose(tr.a[-1], 0, atol=1e-12)     # vertical terminal thrust
    assert tr.r[:, 2].min() > -1e-8                           # never below ground
    # body +z along the specific force, yaw held at 0
    f = tr.a - np.asarray(G)
    zb = tr.R_LtoB[:, 2, :]
    np.testing.assert_allclose(zb, f / np.linalg.norm(f, axis=1, keepdims=True), atol=1e-12)
    np.testing.assert_allclose(euler_rpy_deg(tr.R_LtoB)[:, 2], 0, atol=1e-9)
    # derivative consistency of the polynomial
    np.testing.assert_allclose(np.gradient(tr.r[:, 0], t)[1:-1], tr.v[1:-1, 0], atol=2e-3)


def test_guidance_rejects_bad_duration():
    with pytest.raises(ValueError, match="duration"):
        guidance_coefficients(R0, V0, 0.0)


@pytest.mark.parametrize("dt", [0.1, 0.05])
def test_zero_noise_dead_reckoning_reproduces_truth(dt):
    n_sub = int(round(1.0 / dt))
    t = np.arange(int(round(T / dt)) + 1) * dt
    tr = truth_states(t, R0, V0, T, G)
    f, w = imu.synthesize(tr.v, tr.R_LtoB, dt, G)
    pre = imu.preintegrate(f, w, dt, n_sub)
    r, v, R = imu.dead_reckon(tr.r[0], tr.v[0], tr.R_LtoB[0], pre, G)
    np.testing.assert_allclose(v, tr.v[::n_sub], atol=1e-8)
    np.testing.assert_allclose(R, tr.R_LtoB[::n_sub], atol=1e-10)
    np.testing.assert_allclose(r, tr.r[::n_sub], atol=1e-2)     # trapezoidal error of the quartic


def test_imu_noise_drift_is_small_and_random():
    dt = 0.1
    t = np.arange(1981) * dt
    tr = truth_states(t, R0, V0, T, G)
    f, w = imu.synthesize(tr.v, tr.R_LtoB, dt, G)
    fn, wn = imu.add_noise(f, w, 5e-4, np.radians(2.78e-5), np.random.default_rng(1))
    assert not np.allclose(fn, f)
    pre = imu.preintegrate(fn, wn, dt, 10)
    r, v, _ = imu.dead_reckon(tr.r[0], tr.v[0], tr.R_LtoB[0], pre, G)
    assert np.abs(v[-1] - tr.v[-1]).max() < 0.02      # ~2e-3 m/s 1-sigma random walk
    assert np.abs(r[-1] - tr.r[-1]).max() < 2.0


def _boxminus(a, b):
    dth = -Rotation.from_matrix(a.R @ b.R.T).as_rotvec()
    return np.concatenate([a.r - b.r, a.v - b.v, dth, a.p - b.p])


def test_transition_matrix_matches_finite_differences():
    dt = 0.1
    t = np.arange(1981) * dt
    tr = truth_states(t, R0, V0, T, G)
    f, w = imu.synthesize(tr.v, tr.R_LtoB, dt, G)
    pre = imu.preintegrate(f, w, dt, 10)
    Q = np.zeros((12, 12))
    for j in (0, 60, 150):
        st = ekf.NavState(tr.r[10 * j], tr.v[10 * j], tr.R_LtoB[10 * j], np.array([100.0, 50, 0]),
                          np.eye(12))

        def prop(dx):
            s = st.copy()
            ekf.inject(s, dx)
            return ekf.propagate(s, pre.dR[j], pre.dv[j], pre.dp[j], 1.0, G, Q)

        base = prop(np.zeros(12))
        J = np.zeros((12, 12))
        h = 1e-6
        for i in range(12):
            e = np.zeros(12)
            e[i] = h
            J[:, i] = (_boxminus(prop(e), base) - _boxminus(prop(-e), base)) / (2 * h)
        Phi = ekf.transition_matrix(st.r, st.v, st.R, base.r, base.v, base.R, 1.0, G)
        np.testing.assert_allclose(Phi, J, atol=1e-5)


def test_oc_transition_maps_the_nullspace_and_update_annihilates_it():
    rng = np.random.default_rng(2)
    C_i = Rotation.random(random_state=rng).as_matrix()
    C_ip = Rotation.from_rotvec(rng.normal(scale=0.01, size=3)).as_matrix() @ C_i
    r_i, v_i, p = rng.normal(size=3) * 1000, rng.normal(size=3) * 50, np.r_[rng.normal(size=2) * 1e3, 0]
    r_j, v_j = r_i + v_i, v_i + rng.normal(size=3)
    C_j = Rotation.from_rotvec(rng.normal(scale=0.05, size=3)).as_matrix() @ C_i
    Phi = ekf.transition_matrix(r_i, v_i, C_i, r_j, v_j, C_j, 1.0, G)
    # the plain Phi maps the direction at the posterior exactly (eq. 8-10)
    np.testing.assert_allclose(Phi @ ekf.nullspace(r_i, v_i, C_i, p), ekf.nullspace(r_j, v_j, C_j, p),
                               atol=1e-8)
    N_i = ekf.nullspace(r_i + 5, v_i - 0.1, C_ip, p + 3)      # a prior that differs
    N_j = ekf.nullspace(r_j, v_j, C_j, p)
    Phi_oc = ekf.oc_transition(Phi, N_i, N_j, C_ip, C_j, 1.0)
    np.testing.assert_allclose(Phi_oc @ N_i, N_j, atol=1e-8)
