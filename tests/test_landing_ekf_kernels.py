"""The landing filter's compiled kernels (opnav.landing.ekf, paper B eq. 4-18)
against the pre-kernel numpy EKF of tests/descent_reference.py (an independent
per-run implementation of the same equations) over hypothesis-drawn states,
finite differences of the stacked bearing Jacobian and of the landmark
initialisation, the OC projection, and batch-size independence (bits)."""

import sys
from pathlib import Path

import numpy as np
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from landing_helpers import random_nav_states
from opnav.landing import ekf

sys.path.insert(0, str(Path(__file__).parent))
import descent_reference as REF  # noqa: E402

G = np.array([0.0, 0.0, -3.711])
SIG_B = 2.5e-3


def _runs(seed: int, n: int):
    """``n`` plausible descent states (one per run) and the generator that drew them."""
    rng = np.random.default_rng(seed)
    return rng, random_nav_states(rng, n)


def _one(st_: ekf.NavState, k: int) -> REF.NavState:
    return REF.NavState(st_.r[k].copy(), st_.v[k].copy(), st_.R[k].copy(), st_.p[k].copy(), st_.P[k].copy())


def _close(a, b, rtol):
    a, b = np.asarray(a), np.asarray(b)
    np.testing.assert_allclose(a, b, rtol=0, atol=rtol * max(np.abs(b).max(), 1e-300))


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.booleans())
def test_propagate_is_the_reference(seed, oc):
    rng, s = _runs(seed, 4)
    dR = Rotation.from_rotvec(rng.normal(scale=0.01, size=(4, 3))).as_matrix()
    dv = rng.normal(size=(4, 3)) * 3
    dp = rng.normal(size=(4, 3)) * 1.5
    Q = np.diag(rng.uniform(1e-8, 1e-6, 12))
    C_p = Rotation.from_rotvec(rng.normal(scale=0.01, size=(4, 3))).as_matrix() @ s.R
    N_i = ekf.nullspace(s.r + 3, s.v - 0.2, C_p, s.p + 1)           # at a prior that differs
    got = ekf.propagate(s, dR, dv, dp, 1.0, G, Q, (N_i, C_p) if oc else None)
    for k in range(4):
        want = REF.propagate(_one(s, k), dR[k], dv[k], dp[k], 1.0, G, Q, (N_i[k], C_p[k]) if oc else None)
        for a in "rvRp":
            _close(getattr(got, a)[k], getattr(want, a), 1e-13)
        _close(got.P[k], want.P, 1e-11)
        assert np.array_equal(got.P[k], got.P[k].T)
        Phi = ekf.transition_matrix(s.r[k], s.v[k], s.R[k], got.r[k], got.v[k], got.R[k], 1.0, G)
        _close(Phi, REF.transition_matrix(s.r[k], s.v[k], s.R[k], want.r, want.v, want.R, 1.0, G), 1e-13)
        if oc:
            N_j = ekf.nullspace(got.r[k], got.v[k], got.R[k], s.p[k])
            Phi = ekf.oc_transition(Phi, N_i[k], N_j, C_p[k], got.R[k], 1.0)
            _close(Phi @ N_i[k], N_j, 1e-10)                             # Phi N_i = N_j
    # a run's numbers do not depend on its batch
    alone = ekf.propagate(ekf.NavState(s.r[2], s.v[2], s.R[2], s.p[2], s.P[2]), dR[2], dv[2], dp[2],
                          1.0, G, Q, (N_i[2], C_p[2]) if oc else None)
    for a in "rvRpP":
        assert np.array_equal(getattr(alone, a), getattr(got, a)[2])


def _bearings(rng, s: ekf.NavState, which: str):
    """Measured bearings (site and/or the state's landmark) of a truth near ``s``."""
    n = len(s.r)
    r_t = s.r + rng.normal(size=(n, 3)) * 20
    R_t = Rotation.from_rotvec(rng.normal(scale=2e-3, size=(n, 3))).as_matrix() @ s.R
    p_t = s.p + rng.normal(size=(n, 3)) * 30

    def b(p):
        d = np.einsum("nij,nj->ni", R_t, p - r_t) + rng.normal(size=(n, 3)) * SIG_B * 50
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    meas = []
    if "s" in which:
        meas.append(ekf.Bearing(b(np.zeros((n, 3))), np.zeros(3)))
    if "l" in which:
        meas.append(ekf.Bearing(b(p_t)))
    return meas


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["sl", "s", "l"]), st.sampled_from([1, 3]), st.booleans())
def test_update_is_the_reference(seed, which, iterations, oc):
    rng, s = _runs(seed, 3)
    meas = _bearings(rng, s, which)
    N = ekf.nullspace(s.r, s.v, s.R, s.p) if oc else None
    got, nis = ekf.update(s, meas, SIG_B, N, iterations)
    for k in range(3):
        ref_meas = [(m.b[k], m.p_known) for m in meas]
        want, nis_w = REF.update(_one(s, k), ref_meas, SIG_B, None if N is None else N[k], iterations)
        for a in "rvpR":       # the corrections agree to round-off (amplified by S's condition)
            _close(getattr(got, a)[k] - getattr(s, a)[k], getattr(want, a) - getattr(s, a)[k], 1e-6)
        _close(got.P[k], want.P, 1e-7)
        np.testing.assert_allclose(nis[k], nis_w, rtol=1e-6)
    alone, _ = ekf.update(ekf.NavState(s.r[1], s.v[1], s.R[1], s.p[1], s.P[1]),
                          [ekf.Bearing(m.b[1], m.p_known) for m in meas], SIG_B,
                          None if N is None else N[1], iterations)
    for a in "rvRpP":
        assert np.array_equal(getattr(alone, a), getattr(got, a)[1])


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["sl", "s", "l"]))
def test_stacked_bearing_jacobian_matches_central_differences(seed, which):
    """H of eq. 15-18 as the update kernel stacks it (eq. 16's [b x] written out
    in the kernel): the residual moves by -H dx under a correction dx."""
    rng, s = _runs(seed, 2)
    meas = _bearings(rng, s, which)
    H, res = ekf.linearise(s, meas)
    h = np.array([1e-2] * 6 + [1e-6] * 3 + [1e-2] * 3)
    for c in range(12):
        e = np.zeros((2, 12))
        e[:, c] = h[c]
        plus, minus = s.copy(), s.copy()
        ekf.inject(plus, e)
        ekf.inject(minus, -e)
        fd = -(ekf.linearise(plus, meas)[1] - ekf.linearise(minus, meas)[1]) / (2 * h[c])
        np.testing.assert_allclose(H[..., c], fd, rtol=1e-5, atol=1e-10)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31))
def test_projected_jacobian_annihilates_the_nullspace(seed):
    """OC-EKF: with N the Jacobian at any iterate satisfies H N = 0 (and equals
    the reference's projection); without it, it does not."""
    rng, s = _runs(seed, 3)
    meas = _bearings(rng, s, "sl")
    N = ekf.nullspace(s.r + 10, s.v, s.R, s.p - 5)
    H, _ = ekf.linearise(s, meas, N)
    n = N / np.linalg.norm(N, axis=1, keepdims=True)
    assert np.abs(np.einsum("kij,kj->ki", H, n)).max() < 1e-12 * np.abs(H).max()
    H0, _ = ekf.linearise(s, meas)
    assert np.abs(np.einsum("kij,kj->ki", H0, n)).max() > 1e-6 * np.abs(H0).max()
    for k in range(3):
        want, _ = REF._linearise(_one(s, k), [(m.b[k], m.p_known) for m in meas], N[k])
        _close(H[k], want, 1e-12)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31))
def test_init_landmark_is_the_reference_and_its_jacobian_the_derivative(seed):
    rng, s = _runs(seed, 3)
    d = np.c_[rng.uniform(-3000, 3000, (3, 2)), np.zeros(3)] - s.r       # towards the ground
    b = np.einsum("nij,nj->ni", s.R, d)
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    b[2] = -b[2] if (s.R[2].T @ b[2])[2] < 0 else b[2]                     # run 2: up, misses
    new, ok = ekf.init_landmark(s, b, 0.1, SIG_B)
    assert list(ok) == [True, True, False]
    for k in range(2):
        want = REF.init_landmark(_one(s, k), b[k], 0.1, SIG_B)
        _close(new.p[k], want.p, 1e-12)
        _close(new.P[k], want.P, 1e-10)
    for a in "rvRpP":                                                      # the miss: unchanged
        assert np.array_equal(getattr(new, a)[2], getattr(s, a)[2])
    p, J, dep, _ = ekf.init_jacobian(s, b)
    _close(dep[:2], np.linalg.norm(p[:2] - s.r[:2], axis=1), 1e-12)
    h = np.array([1e-2] * 6 + [1e-7] * 3)
    for c in range(9):
        e = np.zeros((3, 12))
        e[:, c] = h[c]
        plus, minus = s.copy(), s.copy()
        ekf.inject(plus, e)
        ekf.inject(minus, -e)
        fd = (ekf.init_jacobian(plus, b)[0] - ekf.init_jacobian(minus, b)[0]) / (2 * h[c])
        np.testing.assert_allclose(J[:2, :, c], fd[:2], rtol=1e-5, atol=1e-8 * np.abs(J).max())


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 12))
def test_preintegration_kernel_is_the_sample_scheme(seed, n_sub):
    """imu.preintegrate (kernel) against the sample-by-sample scheme of the imu
    module docstring written with scipy rotations: R_mid = R Exp(w dt/2),
    v += R_mid f dt, r += v dt + R_mid f dt^2/2, R = R Exp(w dt)."""
    from opnav.landing import imu

    rng = np.random.default_rng(seed)
    m, dt = 3, 0.1
    f = rng.normal(size=(m * n_sub, 3)) * 5
    w = rng.normal(size=(m * n_sub, 3)) * 0.2
    pre = imu.preintegrate(f, w, dt, n_sub)
    for j in range(m):
        R, v, r = np.eye(3), np.zeros(3), np.zeros(3)
        for k in range(j * n_sub, (j + 1) * n_sub):
            R_mid = R @ Rotation.from_rotvec(w[k] * dt / 2).as_matrix()
            a = R_mid @ f[k]
            r = r + v * dt + 0.5 * a * dt * dt
            v = v + a * dt
            R = R @ Rotation.from_rotvec(w[k] * dt).as_matrix()
        np.testing.assert_allclose(pre.dR[j], R, atol=1e-13)
        np.testing.assert_allclose(pre.dv[j], v, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(pre.dp[j], r, rtol=1e-12, atol=1e-13)
