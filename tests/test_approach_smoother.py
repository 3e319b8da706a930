"""RTS smoother: dense joint-Gaussian posterior, covariance invariants, lag-one forms."""

import numpy as np
import pytest

import approach_reference as ref
from opnav.approach import crlb, ekf, smoother
from opnav.approach.camera import misalignment_small

from approach_helpers import random_filter_problem, small_window


def _dense_posterior(z, theta, x0, P0, win):
    """Mean and covariance of X_0..X_n given z, from the joint information matrix."""
    A = misalignment_small(theta)
    Hx = np.stack([-A @ C for C in win.C])
    J, h = crlb.dense_information(win, P0, Hx, y=z - win.u_ref @ A.T, x0=x0)
    cov = np.linalg.inv(J)
    return (cov @ h).reshape(win.n + 1, 6), cov


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rts_equals_dense_joint_gaussian_posterior(seed):
    win, rng = small_window(n=7, seed=seed)
    S = 2
    z = rng.standard_normal((S, win.n + 1, 3)) * 3 + win.u_ref
    theta = rng.normal(size=(S, 3)) * 0.05
    x0 = rng.normal(size=(S, 6))
    P0 = np.diag(rng.random(6) + 0.5)
    f = ekf.run_filter(z, theta, x0, P0, win)
    s = ref.rts(f, win)
    sb = smoother.bryson_frazier(f, win)
    for i in range(S):
        mean, cov = _dense_posterior(z[i], theta[i], x0[i], P0, win)
        np.testing.assert_allclose(s.xs[i], mean, atol=1e-9)
        np.testing.assert_allclose(sb.xs[i], mean, atol=1e-9)
        for k in range(win.n + 1):
            blk = cov[6 * k:6 * k + 6, 6 * k:6 * k + 6]
            np.testing.assert_allclose(s.Ps[i, k], blk, atol=1e-9)
            np.testing.assert_allclose(sb.Ps[i, k], blk, atol=1e-9)
            if k >= 1:  # lag-one smoothed cross-covariance, eq. 18
                lag = cov[6 * k:6 * k + 6, 6 * (k - 1):6 * k]
                np.testing.assert_allclose(s.Plag[i, k], lag, atol=1e-9)
        # the filtered estimate at the last sample is the smoothed one
        np.testing.assert_allclose(f.xf[i, -1], mean[-1], atol=1e-9)


def test_lag_one_gain_form_equals_recursion():
    win, rng = small_window(n=10, seed=5)
    z = rng.standard_normal((3, win.n + 1, 3)) + win.u_ref
    f = ekf.run_filter(z, np.zeros((3, 3)), np.zeros((3, 6)), np.eye(6), win)
    s = ref.rts(f, win)
    rec = ref.lag_one_recursive(f, s, win)
    np.testing.assert_allclose(rec[:, 1:], s.Plag[:, 1:], atol=1e-10)


def test_filter_log_likelihood_equals_dense_gaussian_density():
    win, rng = small_window(n=4, seed=7)
    z = rng.standard_normal((1, win.n + 1, 3)) + win.u_ref
    theta = np.array([[0.01, -0.02, 0.03]])
    x0, P0 = rng.normal(size=(1, 6)), np.eye(6)
    f = ekf.run_filter(z, theta, x0, P0, win)
    # dense: z stacked = M X + A u_ref + v, X ~ N(m, Sigma)
    n = win.n
    A = misalignment_small(theta[0])
    Phi_cum = [np.eye(6)]
    for k in range(1, n + 1):
        Phi_cum.append(win.Phi[k] @ Phi_cum[-1])
    # covariance of X_k from the linear model
    covX = np.zeros((6 * (n + 1), 6 * (n + 1)))
    G = np.zeros((6 * (n + 1), 6 * (n + 1)))  # X = G [x0; w1..wn]
    for k in range(n + 1):
        G[6 * k:6 * k + 6, :6] = Phi_cum[k]
        for j in range(1, k + 1):
            T = np.eye(6)
            for m in range(j + 1, k + 1):
                T = win.Phi[m] @ T
            G[6 * k:6 * k + 6, 6 * j:6 * j + 6] = T
    Sw = np.zeros_like(covX)
    Sw[:6, :6] = P0
    for j in range(1, n + 1):
        Sw[6 * j:6 * j + 6, 6 * j:6 * j + 6] = win.Q
    covX = G @ Sw @ G.T
    meanX = G[:, :6] @ x0[0]
    M = np.zeros((3 * n, 6 * (n + 1)))
    for k in range(1, n + 1):
        M[3 * (k - 1):3 * k, 6 * k:6 * k + 3] = -A @ win.C[k]
    mz = M @ meanX + np.concatenate([A @ win.u_ref[k] for k in range(1, n + 1)])
    Sz = M @ covX @ M.T + np.diag(win.Rvar[1:].ravel())
    from scipy.stats import multivariate_normal
    ll = multivariate_normal(mz, Sz).logpdf(z[0, 1:].ravel())
    assert f.loglik[0] == pytest.approx(ll, rel=1e-9)


def test_smoothed_covariances_no_larger_and_spd_on_the_approach():
    from opnav.approach import scenario as sc
    from approach_helpers import approach_setup

    cfg = approach_setup()
    geo = sc.build_geometry(cfg, "roll", n=300)
    Rvar = sc.measurement_variance(geo, cfg, cfg.camera.sigma3_px)
    win = geo.window(Rvar)
    z, _ = sc.simulate(geo, Rvar, sc.rad([10, 20, 10]), sc.seed_streams(1, 1, range(3)))
    f = ekf.run_filter(z, np.full((3, 3), 1e-5), np.zeros((3, 6)), geo.P0, win)
    for s in (ref.rts(f, win), smoother.bryson_frazier(f, win)):
        for P in (f.Pf, f.Pp[:, 1:], s.Ps):
            np.testing.assert_allclose(P, np.swapaxes(P, -1, -2), rtol=0, atol=1e-9 * np.abs(P).max())
            # SPD: Cholesky of the Jacobi-scaled matrix succeeds
            d = 1 / np.sqrt(np.diagonal(P, axis1=-2, axis2=-1))
            np.linalg.cholesky(P * d[..., :, None] * d[..., None, :])
        diff = f.Pf - s.Ps  # filtered minus smoothed must be PSD (scaled)
        d = 1 / np.sqrt(np.diagonal(f.Pf, axis1=-2, axis2=-1))
        eig = np.linalg.eigvalsh(diff * d[..., :, None] * d[..., None, :])
        assert eig.min() > -1e-7


def _approach_filter(S=4, n=120, seed=3):
    from opnav.approach import scenario as sc
    from approach_helpers import approach_setup

    cfg = approach_setup()
    geo = sc.build_geometry(cfg, "roll", n=n)
    Rvar = sc.measurement_variance(geo, cfg, cfg.camera.sigma3_px)
    win = geo.window(Rvar)
    z, _ = sc.simulate(geo, Rvar, sc.rad([10, 20, 10]), sc.seed_streams(seed, 1, range(S)))
    theta = np.random.default_rng(seed).normal(size=(S, 3)) * 1e-4
    return geo, win, z, theta


def test_position_only_smoother_is_the_full_one_bit_for_bit():
    """The E-step's fast path (position block only, no predicted moments kept) gives exactly
    the entries of the full Bryson-Frazier moments, and those match the RTS smoother."""
    geo, win, z, theta = _approach_filter()
    x0 = np.random.default_rng(0).normal(size=(z.shape[0], 6))
    f = ekf.run_filter(z, theta, x0, geo.P0, win)
    lean = ekf.run_filter(z, theta, x0, geo.P0, win, predicted=False)
    assert lean.xp is None and lean.Pp is None
    for name in ("xf", "Pf", "loglik", "KH_last", "K", "Sinv", "nu", "Hr"):
        assert np.array_equal(getattr(f, name), getattr(lean, name)), name
    full = smoother.bryson_frazier(f, win)
    pos = smoother.bryson_frazier(lean, win, ekf.POS)
    assert pos.xs.shape == z.shape and pos.Ps.shape == z.shape + (3,)
    assert np.array_equal(pos.xs, full.xs[..., :3])
    assert np.array_equal(pos.Ps, full.Ps[..., :3, :3])
    r = ref.rts(f, win)
    np.testing.assert_allclose(pos.Ps, r.Ps[..., :3, :3], rtol=1e-7, atol=1e-9 * np.abs(r.Ps[..., :3, :3]).max())
    np.testing.assert_allclose(pos.xs, r.xs[..., :3], rtol=1e-7, atol=1e-7 * np.abs(r.xs[..., :3]).max())


def test_prior_propagated_to_several_samples_in_one_pass_equals_separate_passes():
    geo, win, z, _ = _approach_filter(n=60)
    x0 = np.random.default_rng(1).normal(size=(z.shape[0], 6))
    at = [0, 7, 7, 30, 60]
    xs, Ps = ekf.predict_only(x0, geo.P0, win, at=at)
    for a, x, P in zip(at, xs, Ps):
        xa, Pa = ekf.predict_only(x0, geo.P0, win.slice(0, a))
        assert np.array_equal(x, xa) and np.array_equal(P, Pa)
    with pytest.raises(ValueError, match="must increase"):
        ekf.predict_only(x0, geo.P0, win, at=[30, 7])
    with pytest.raises(ValueError, match="must increase"):
        ekf.predict_only(x0, geo.P0, win, at=[5, 61])


def test_filter_measurement_jacobian_is_minus_A_C_at_every_sample():
    geo, win, z, theta = _approach_filter(S=3, n=40)
    f = ekf.run_filter(z, theta, np.zeros((3, 6)), geo.P0, win)
    for s in range(3):
        for k in (1, 17, 40):
            H = ekf.measurement_jacobian(theta[s:s + 1], win.C[k])[0]
            np.testing.assert_allclose(f.Hr[s, k], H[:, :3], rtol=1e-15, atol=0)
            assert not H[:, 3:].any()


from hypothesis import given, settings, strategies as st  # noqa: E402


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), S=st.integers(1, 3), n=st.integers(1, 12),
       cols=st.sampled_from([slice(None), slice(0, 3), slice(3, 6), slice(1, 4)]))
def test_compiled_bryson_frazier_equals_rts_over_random_windows(seed, S, n, cols):
    """The compiled Bryson-Frazier moments (any contiguous block of states) equal the numpy
    RTS smoother's (eq. 7-9) on random linear models."""
    win, _, z, theta, x0, P0 = random_filter_problem(seed, S, n)
    f = ekf.run_filter(z, theta, x0, P0, win)
    r = ref.rts(f, win)
    b = smoother.bryson_frazier(f, win, cols)
    np.testing.assert_allclose(b.xs, r.xs[..., cols], rtol=1e-8, atol=1e-9 * np.abs(r.xs).max())
    np.testing.assert_allclose(b.Ps, r.Ps[..., cols, cols], rtol=1e-7, atol=1e-9 * np.abs(r.Ps).max())
    assert np.array_equal(b.Ps, np.swapaxes(b.Ps, -1, -2))
    with pytest.raises(ValueError, match="contiguous"):
        smoother.bryson_frazier(f, win, slice(0, 6, 2))
