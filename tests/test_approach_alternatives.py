"""A-X2 alternatives: augmented EKF and batch ML (CasADi + IPOPT) against EM and the CRLB."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from approach_helpers import random_filter_problem, small_window
from opnav.approach import alternatives, crlb
from opnav.approach import scenario as sc
from opnav.approach.augmented import run_augmented
from opnav.approach.batch_ml import BatchML
from opnav.approach.em import em_window
from opnav.approach.setup import Setup
from opnav.core.config import load_config

N_SAMPLES = 600
TRUTH = np.array([10.0, 20.0, 10.0])


def _cfg():
    cfg = load_config()["approach"]
    cfg["initial_error"]["mode"] = "sampled"  # prior mean drawn about the truth: a proper Bayesian setup
    return cfg


@pytest.fixture(scope="module")
def roll_case():
    """Roll variant from the prior at t0, 600 samples (5 min, 30 deg of roll): theta is observable."""
    cfg = Setup.from_config(_cfg())
    geo = sc.build_geometry(cfg, "roll", n=N_SAMPLES)
    Rvar = sc.measurement_variance(geo, cfg, [0.1, 0.1, 0.2])
    win = geo.window(Rvar)
    bound = sc.arcsec(crlb.crlb_curve(win, geo.u_true, geo.P0, sc.rad(TRUTH), 0.01)[-1])
    return cfg, geo, win, bound


def _data(geo, win, truth, seeds, base=11):
    z, e0 = sc.simulate(geo, win.Rvar, sc.rad(truth), sc.seed_streams(base, 1, seeds))
    return z, sc.prior_mean_deviation(geo, e0, "sampled")


def test_roll_bound_is_below_3_arcsec_and_tz_stays_at_its_prior(roll_case):
    _, _, _, bound = roll_case
    assert bound[:2].max() < 3.0  # arcsec: a case where theta is well observable
    assert bound[2] > 1000.0  # tz: unobservable, stays at the diffuse prior


@pytest.mark.slow
def test_augmented_batch_ml_and_em_within_4_bound_sigma_and_ml_equals_em(roll_case):
    """All three estimators are within a few CRLB sigma of the truth; batch ML and converged EM
    maximise the same observed-data likelihood, so they agree far more closely."""
    _, geo, win, bound = roll_case
    S = 3
    z, dx0 = _data(geo, win, TRUTH, range(S))
    th0 = np.zeros((S, 3))
    aug = run_augmented(z, dx0, geo.P0, th0, sc.rad(100.0), win)
    bm = BatchML(win, [win.n], sc.rad(3600.0), jit=False)
    ml = bm.solve(z, dx0, geo.P0, th0, geo.u_ref)
    em = em_window(z, th0, dx0, geo.P0, win, 30, "squarem")
    est = {"augmented": sc.arcsec(aug.theta[:, -1]), "batch_ml": sc.arcsec(ml.theta[:, -1]),
           "em": sc.arcsec(em.theta[-1])}
    for name, th in est.items():
        assert np.all(np.abs(th[:, :2] - TRUTH[:2]) < 4.0 * bound[:2]), name
    assert ml.success.all()
    np.testing.assert_allclose(est["batch_ml"][:, :2], est["em"][:, :2], atol=0.05 * bound[:2].max())
    np.testing.assert_allclose(est["augmented"][:, :2], est["batch_ml"][:, :2], atol=1.0 * bound[:2].max())


@pytest.mark.slow  # ~1.6 CPU-s (issue 56: the default run <= 90 s)
def test_batch_ml_solution_is_stationary_and_gradient_exact(roll_case):
    _, geo, win, bound = roll_case
    z, dx0 = _data(geo, win, TRUTH, [5])
    bm = BatchML(win, [win.n // 2, win.n], sc.rad(3600.0), jit=False)
    res = bm.solve(z, dx0, geo.P0, np.zeros(3), geo.u_ref)
    for j in range(2):
        p = bm.params(z[0, 1:] - geo.u_ref[1:], dx0[0], geo.P0, np.zeros(3))
        f, g = bm.objective[j](sc.arcsec(res.theta[0, j]), p)
        g = np.asarray(g).ravel()
        # score in units of its own standard deviation (Fisher information ~ 1/CRLB^2): ~0
        assert np.all(np.abs(g[:2]) * bound[:2] < 1e-5)
        assert res.grad_norm[0, j] == pytest.approx(np.linalg.norm(g))
    # the CasADi gradient matches central differences of the objective
    th = np.array([3.0, -4.0, 2.0])
    f0, g0 = bm.objective[-1](th, p)
    h = 1e-3
    fd = [(float(bm.objective[-1](th + h * e, p)[0]) - float(bm.objective[-1](th - h * e, p)[0])) / (2 * h)
          for e in np.eye(3)]
    np.testing.assert_allclose(np.asarray(g0).ravel()[:2], fd[:2], rtol=1e-5)


def test_score_at_truth_has_zero_mean(roll_case):
    """E[d log p(z|theta)/d theta] = 0 at the true theta (data and prior mean drawn from the model)."""
    _, geo, win, bound = roll_case
    S = 8
    z, dx0 = _data(geo, win, TRUTH, range(S), base=23)
    bm = BatchML(win, [win.n], sc.rad(1.0e6), jit=False)  # prior gradient negligible
    scores = []
    for s in range(S):
        p = bm.params(z[s, 1:] - geo.u_ref[1:], dx0[s], geo.P0, np.zeros(3))
        scores.append(np.asarray(bm.objective[0](TRUTH, p)[1]).ravel()[:2])
    scores = np.array(scores)
    fisher_sd = 1.0 / bound[:2]  # sd of the score = sqrt(Fisher information)
    zstat = scores.mean(0) / (fisher_sd / np.sqrt(S))
    assert np.all(np.abs(zstat) < 4.0)
    assert np.all(scores.std(0) < 3.0 * fisher_sd)  # and its spread is the Fisher information's


def test_batch_ml_zero_bias_truth(roll_case):
    _, geo, win, bound = roll_case
    S = 2
    z, dx0 = _data(geo, win, np.zeros(3), range(S), base=31)
    bm = BatchML(win, [win.n], sc.rad(3600.0), jit=False)
    res = bm.solve(z, dx0, geo.P0, sc.rad([5.0, -5.0, 0.0]), geo.u_ref)
    assert np.all(np.abs(sc.arcsec(res.theta[:, -1, :2])) < 4.0 * bound[:2])


@pytest.mark.slow  # ~2.3 CPU-s (issue 56: the default run <= 90 s)
def test_jit_gives_the_same_objective(roll_case):
    _, geo, win, _ = roll_case
    z, dx0 = _data(geo, win, TRUTH, [0])
    vals = []
    for jit in (False, True):
        bm = BatchML(win.slice(0, 100), [100], sc.rad(3600.0), jit=jit)
        p = bm.params(z[0, 1:101] - geo.u_ref[1:101], dx0[0], geo.P0, np.zeros(3))
        f, g = bm.objective[0](TRUTH, p)
        vals.append(np.r_[float(f), np.asarray(g).ravel()])
    np.testing.assert_allclose(vals[0], vals[1], rtol=1e-10)


@pytest.mark.slow  # ~1.9 CPU-s (issue 56: the default run <= 90 s)
def test_compiled_fold_gives_the_virtual_machines_numbers_bit_for_bit(roll_case):
    """The JIT-compiled fold of the step (and its reverse derivative, IPOPT's gradient) must
    give exactly the numbers of CasADi's virtual machine calling the compiled step, so that
    compiling it never moves an IPOPT iterate."""
    import casadi as ca

    from opnav.approach import batch_ml

    step = batch_ml.kf_step(True)
    if step.name() != "kf_step_jit":
        pytest.skip("no working C compiler: nothing is compiled")
    _, geo, win, _ = roll_case
    z, dx0 = _data(geo, win, TRUTH, [0])
    d = 40
    sl = slice(1, d + 1)
    th = ca.MX.sym("th", 3)
    args = (dx0[0], geo.P0, 0.0, th, np.hstack(list(win.Phi[sl])), np.hstack(list(win.C[sl])),
            win.u_ref[sl].T, win.Rvar[sl].T, (z[0, sl] - win.u_ref[sl]).T, win.Q)
    vals = []
    for fold in (step.mapaccum("kf_vm", d, [0, 1, 2], [0, 1, 2]), batch_ml.kf_accum(d, True)):
        out = fold(*args)
        nll = out[2][-1]
        f = ca.Function("f", [th], [nll, ca.gradient(nll, th), out[0][:, -1], out[1][:, -6:]])
        vals.append([np.asarray(v) for v in f(sc.rad(TRUTH))])
    assert batch_ml.kf_accum(d, True).name() == f"kf_{d}_jit"
    for a, b in zip(*vals):
        assert a.tobytes() == b.tobytes()


def test_linear_augmented_filter_attains_the_crlb():
    """On the linear-Gaussian model the augmented Kalman filter's theta covariance equals the
    Bayesian CRLB from the dense joint information of X_0..X_n and theta."""
    win, rng = small_window(n=8, seed=3)
    u_lin = win.u_ref + rng.standard_normal(win.u_ref.shape)
    P0 = np.diag([4.0, 3.0, 2.0, 1.0, 1.0, 0.5])
    sig = 0.05
    z = rng.standard_normal((1, win.n + 1, 3))  # the covariance does not depend on the data
    res = run_augmented(z, np.zeros((1, 6)), P0, np.zeros(3), sig, win, u_lin=u_lin)
    dense = crlb.batch_crlb(win, u_lin, P0, np.zeros(3), sig)
    np.testing.assert_allclose(np.sqrt(np.diag(res.P_theta[0, -1])), dense, rtol=1e-7)
    # and the recursion shared with A-X1 gives the same sequence
    rec = crlb.crlb_curve(win, u_lin, P0, np.zeros(3), sig)
    np.testing.assert_allclose(np.sqrt(np.diagonal(res.P_theta[0], axis1=1, axis2=2)), rec, rtol=1e-7)


def test_linear_augmented_filter_mean_is_the_gls_solution():
    """Linear model: the filter's final theta equals the dense posterior mean (GLS)."""
    win, rng = small_window(n=6, seed=4, q=0.05)
    u_lin = win.u_ref.copy()
    P0 = np.eye(6)
    sig = 0.1
    n = win.n
    z = np.full((1, n + 1, 3), np.nan)
    z[0, 1:] = win.u_ref[1:] + rng.standard_normal((n, 3))
    J, b = crlb.dense_information(win, P0, -win.C, crlb.theta_sensitivity(u_lin), sig, y=z[0] - win.u_ref)
    post = np.linalg.solve(J, b)
    res = run_augmented(z, np.zeros((1, 6)), P0, np.zeros(3), sig, win, u_lin=u_lin)
    np.testing.assert_allclose(res.theta[0, -1], post[-3:], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(res.xf[0, -1], post[6 * n:6 * n + 6], rtol=1e-6, atol=1e-10)


def test_ekf_theta_covariance_approaches_the_crlb(roll_case):
    """The (nonlinear) augmented EKF's theta covariance is close to the bound at the truth."""
    _, geo, win, _ = roll_case
    z, dx0 = _data(geo, win, TRUTH, [2])
    sig = sc.rad(100.0)  # the pipeline's default prior on theta
    res = run_augmented(z, dx0, geo.P0, np.zeros(3), sig, win)
    bound = crlb.crlb_curve(win, geo.u_true, geo.P0, sc.rad(TRUTH), sig)[-1]
    np.testing.assert_allclose(np.sqrt(np.diag(res.P_theta[0, -1]))[:2], bound[:2], rtol=0.05)


def test_augmented_input_errors():
    win, _ = small_window(n=3)
    with pytest.raises(ValueError, match="samples"):
        run_augmented(np.zeros((1, 2, 3)), np.zeros((1, 6)), np.eye(6), np.zeros(3), 1.0, win)
    with pytest.raises(ValueError, match="theta_prior_sigma"):
        run_augmented(np.zeros((1, 4, 3)), np.zeros((1, 6)), np.eye(6), np.zeros(3), 0.0, win)
    with pytest.raises(ValueError, match="checkpoints"):
        BatchML(win, [2, 2], 1.0, jit=False)


def test_checkpoint_samples_keep_the_last():
    seg = np.arange(1, 11) * 50
    np.testing.assert_array_equal(alternatives.checkpoint_samples(seg, 4), [100, 300, 500])
    np.testing.assert_array_equal(alternatives.checkpoint_samples(seg, 1), seg)
    assert alternatives.checkpoint_samples(seg, 100)[-1] == 500


def test_ablation_studies_change_one_value():
    """The A-X3 ablations are studies (config.yaml): the segment sweep keeps the data
    length L N, the pixel sweep keeps the radius / centroid ratio, and every value of
    both changes only its own keys (and draws the initial error from the prior)."""
    from opnav.studies import planning

    full = load_config()
    cfg = full["approach"]
    shape = {k: cfg[k] for k in cfg}
    plan = planning.plan(full, {"approach": shape, "landing": full["landing"]}, lambda c: None)
    base = cfg["segments"]["L"] * cfg["segments"]["N"]
    seg = plan["segment"]
    assert seg.keys == ("approach.segments.N", "approach.segments.L") and len(seg.instances) >= 2
    for inst in seg.instances:
        N, L = inst.values["approach.segments.N"], inst.values["approach.segments.L"]
        assert abs(L * N - base) <= N / 2
        assert inst.sim["camera"] == cfg["camera"] and inst.sim["segments"]["N0"] == cfg["segments"]["N0"]
    r = cfg["camera"]["radius_to_centroid_ratio"]
    for inst in plan["pixel"].instances:
        px = inst.values["approach.camera.sigma3_px"]
        assert px[0] == px[1] and px[2] == pytest.approx(r * px[0])
        assert inst.sim["segments"] == cfg["segments"]
    for name in ("pixel", "segment", "prior", "range", "roll_rate"):
        assert all(i.sim["initial_error"]["mode"] == "sampled" for i in plan[name].instances), name


def _augmented_reference(z, x0, P0, theta0, sig, win, q_theta=0.0, u_lin=None):
    """The augmented EKF step by step with the batched kalman API and numpy (the module's
    loop before it was compiled): theta (S, n+1, 3) rad, P_theta, xf, trace P_rr, loglik."""
    from opnav.approach import kalman
    from opnav.approach.augmented import augmented_jacobian, augmented_noise
    from opnav.approach.dynamics import ARCSEC
    from opnav.approach.stars import theta_information_update
    from opnav.core.rotations import skew

    S, n = z.shape[0], win.n
    y = np.zeros((S, 9))
    y[:, :6] = x0
    y[:, 6:] = np.broadcast_to(theta0, (S, 3)) / ARCSEC
    P = np.zeros((S, 9, 9))
    P[:, :6, :6] = P0
    P[:, 6:, 6:] = np.eye(3) * (sig / ARCSEC) ** 2
    Qa = augmented_noise(win.Q, q_theta / ARCSEC**2)
    F = np.eye(9)
    out = [[y[:, 6:]], [P[:, 6:, 6:]], [y[:, :6]], [np.trace(P[:, :3, :3], axis1=1, axis2=2)]]
    ll = np.zeros(S)
    A_lin = np.eye(3) - skew(y[0, 6:] * ARCSEC)
    star_at = {} if win.stars is None else {int(k): i for i, k in enumerate(win.stars.idx)}
    for k in range(1, n + 1):
        F[:6, :6] = win.Phi[k]
        y, P = kalman.predict(y, P, F, Qa)
        C = win.C[k]
        if u_lin is None:
            A = np.eye(3) - skew(y[:, 6:] * ARCSEC)
            u = win.u_ref[k] - y[:, :3] @ C.T
            zhat = np.einsum("sij,sj->si", A, u)
            H = augmented_jacobian(A, C, skew(u) * ARCSEC)
        else:
            H = np.broadcast_to(augmented_jacobian(A_lin, C, skew(u_lin[k]) * ARCSEC), (S, 3, 9))
            zhat = win.u_ref[k] + np.einsum("sij,sj->si", H, y)
        nu = z[:, k] - zhat
        R = win.Rvar[k] if win.Rvar.ndim == 2 else win.Rvar[k]
        y, P, _, Sinv, det = kalman.condition_on(y, P, H, R, nu, joseph=True)
        ll += kalman.innovation_loglik(nu, Sinv, det)
        if k in star_at:
            i = star_at[k]
            G = win.stars.G[i] * ARCSEC
            Wd = win.stars.w[i]
            P = theta_information_update(P, np.broadcast_to(np.einsum("ak,a,al->kl", G, Wd, G), (S, 3, 3)))
            y = y + np.einsum("sij,sj->si", P[:, :, 6:], np.einsum("ak,a,sa->sk", G, Wd, win.star_yw[:, i] - y[:, 6:] @ G.T))
        for o, v in zip(out, (y[:, 6:], P[:, 6:, 6:], y[:, :6], np.trace(P[:, :3, :3], axis1=1, axis2=2))):
            o.append(v)
    th, Pth, xf, ptr = (np.stack(o, 1) for o in out)
    return th * ARCSEC, Pth * ARCSEC**2, xf, ptr, ll


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), S=st.integers(1, 3), n=st.integers(1, 9), linear=st.booleans(),
       per_seed=st.booleans())
def test_compiled_augmented_filter_equals_the_step_by_step_reference(seed, S, n, linear, per_seed):
    """The compiled augmented EKF (its EKF and linear forms, shared or per-seed variances)
    equals the same filter written step by step with the batched kalman API."""
    win, rng, z, _, x0, P0 = random_filter_problem(seed, S, n, per_seed)
    th0 = rng.normal(size=3) * 1e-4
    u_lin = win.u_ref + rng.standard_normal(win.u_ref.shape) if linear else None
    res = run_augmented(z, x0, P0, th0, 1e-3, win, q_theta=1e-12, u_lin=u_lin)
    ref = _augmented_reference(z, x0, P0, th0, 1e-3, win, 1e-12, u_lin)
    for got, want in zip((res.theta, res.P_theta, res.xf, res.P_pos_trace, res.loglik), ref):
        np.testing.assert_allclose(got, want, rtol=1e-8, atol=1e-9 * np.abs(want).max())


def test_compiled_augmented_filter_with_star_images_equals_the_reference():
    """With star images between compiled stretches (``stars`` variant), the same numbers."""
    c = _cfg()
    c["stars"]["every_K"] = 40
    cfg = Setup.from_config(c)
    geo = sc.build_geometry(cfg, "stars", n=330)  # images every 40 samples after N0 = 200
    Rvar = sc.measurement_variance(geo, cfg, [0.1, 0.1, 0.2])
    seeds = [0, 1]
    win = geo.window(Rvar, geo.simulate_stars(sc.rad(TRUTH), 7, 1, seeds))
    assert win.stars is not None and len(win.stars.idx) >= 3
    z, dx0 = _data(geo, win, TRUTH, seeds)
    res = run_augmented(z, dx0, geo.P0, np.zeros(3), sc.rad(100.0), win)
    ref = _augmented_reference(z, dx0, geo.P0, np.zeros(3), sc.rad(100.0), win)
    for got, want in zip((res.theta, res.P_theta, res.xf, res.P_pos_trace, res.loglik), ref):
        np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9 * np.abs(want).max())
