"""The planned-information metric logdet_nav (opnav.landing.planning.reference): the
candidate's own initialisation, the filter's noise model, obs_per_landmark
observations, marginalised on the navigation states; against a direct
information-form computation and with invariants that a mis-specification breaks."""

import dataclasses
import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from opnav.landing import ekf
from opnav.landing.measurement import selection_jacobian
from opnav.landing.planning.layout import Estimate
from opnav.landing.planning.reference import (PLANNED_METRICS, FilterModel, planned_metric, planned_nav_logdet,
                                              planned_posterior, planned_rows, whitened_site_bound)
from opnav.core.rotations import exp_so3


G = np.array([0.0, 0.0, -3.711])


def _state(seed=0):
    rng = np.random.default_rng(seed)
    r = np.array([800.0, -400.0, 1500.0]) + rng.normal(0, 20, 3)
    v = np.array([-20.0, 10.0, -40.0])
    a = np.array([0.3, -0.2, 1.0])
    # camera looking down: body z along -{L} z roughly (boresight body -z)
    R = exp_so3(rng.normal(0, 0.05, 3)) @ np.diag([1.0, -1.0, -1.0])
    A = rng.normal(size=(12, 12))
    P = np.diag(np.r_[np.full(3, 50.0**2), np.full(3, 2.0**2), np.full(3, 0.01**2), np.full(3, 1e4)])
    P = P + 1e-3 * np.sqrt(np.outer(np.diag(P), np.diag(P))) * (A @ A.T) / 12
    cand = np.column_stack([r[0] + rng.uniform(-600, 600, 6), r[1] + rng.uniform(-600, 600, 6), np.zeros(6)])
    return r, v, a, R, P, cand


def test_posterior_is_the_information_form_of_the_planned_updates():
    from opnav.landing.ekf import transition_matrix

    r, v, a, R, P, cand = _state()
    sf, frac, n_obs, dt = 2.5e-3, 0.1, 3, 1.0
    Sig, ok = planned_posterior(Estimate(r, v, a, R, P), np.zeros(3), cand,
                                FilterModel(sf, frac, n_obs, dt, G, oc=False))
    assert ok.all()
    for c, S in zip(cand, Sig):
        # its own initialisation: the filter's init_landmark for the candidate's bearing
        st = ekf.NavState(r=r.copy(), v=v.copy(), R=R.copy(), p=np.zeros(3), P=P.copy())
        b = R @ (c - r)
        new, ok1 = ekf.init_landmark(st, b / np.linalg.norm(b), frac, sf)
        assert ok1 and np.allclose(new.p, c, atol=1e-6)
        # the full 6 x 12 bearing Jacobians (noise sf^2 I: the radial rows carry nothing)
        # at the predicted poses, mapped back by the filter's transition
        Lam = np.linalg.inv(new.P)
        for k in range(n_obs):
            t = k * dt
            rk = r + v * t + 0.5 * a * t * t
            H = selection_jacobian(rk, R, np.zeros(3), c)
            if k == 0:
                H[3:6] = 0.0                     # the initialising bearing is in P0
            Phi = transition_matrix(r, v, R, rk, v + a * t, R, t, G) if k else np.eye(12)
            H = H @ Phi
            Lam = Lam + H.T @ H / sf**2
        np.testing.assert_allclose(S, np.linalg.inv(Lam), rtol=1e-5, atol=1e-9 * np.abs(S).max())


def test_score_is_the_navigation_marginal_and_moves_with_the_model():
    r, v, a, R, P, cand = _state(1)
    est = Estimate(r, v, a, R, P)
    nav = lambda sf=2.5e-3, n_obs=3, dt=1.0: planned_nav_logdet(est, np.zeros(3), cand,
                                                                FilterModel(sf, 0.1, n_obs, dt, G, True))
    s3 = nav()
    Sig, _ = planned_posterior(est, np.zeros(3), cand, FilterModel(2.5e-3, 0.1, 3, 1.0, G, True))
    np.testing.assert_allclose(s3, [-np.linalg.slogdet(S[:9, :9])[1] for S in Sig], rtol=1e-9)
    # one observation (the initialising one): no landmark update, so the candidate
    # cannot matter to the navigation states: every candidate scores the same
    s1 = nav(n_obs=1)
    np.testing.assert_allclose(s1, s1[0], rtol=1e-9)
    # ... nor without motion: seen again from the same point it adds nothing
    still = nav(dt=0.0)
    np.testing.assert_allclose(still, still[0], rtol=1e-9)
    assert np.ptp(s3) > 1e-3                                # with parallax it does matter
    assert np.all(nav(n_obs=5) > s3)
    # the filter's (larger) noise model gives less information than the true noise
    assert np.all(nav(sf=5 * 2.5e-3) < s3)


def test_oc_keeps_yaw_unobservable():
    r, v, a, R, P, cand = _state(2)
    Sig, _ = planned_posterior(Estimate(r, v, a, R, P), np.zeros(3), cand, FilterModel(2.5e-3, 0.1, 3, 1.0, G, oc=True))
    N = ekf.nullspace(r, v, R, cand[0])
    st0 = ekf.NavState(r=r.copy(), v=v.copy(), R=R.copy(), p=np.zeros(3), P=P.copy())
    b = R @ (cand[0] - r)
    P0 = ekf.init_landmark(st0, b / np.linalg.norm(b), 0.1, 2.5e-3)[0].P
    # the planned updates add no information along the unobservable direction
    dLam = np.linalg.inv(Sig[0]) - np.linalg.inv(P0)
    assert np.linalg.norm(dLam @ N) < 1e-6 * np.linalg.norm(dLam) * np.linalg.norm(N)


def test_planner_objective_uses_the_filter_noise_model_and_strategy():
    from opnav.core.config import load_config
    from opnav.landing.planner import PlanState, candidate_scores, plan_one
    from landing_helpers import scenario_setups
    from opnav.landing.scenario import build_scenario

    scn = build_scenario(scenario_setups(load_config()["landing"])["interior"])
    cfg = scn.planner
    assert (cfg.noise_scale, cfg.obs_per_landmark) == (scn.noise_scale, scn.obs_per_landmark) != (1.0, 1)
    r, v, a, R, P, cand = _state(3)
    st = PlanState(r, v, a, R, P)
    field = scn.field.__class__(np.ascontiguousarray(cand))
    _, q = plan_one("logdet_nav", st, scn.camera, field, cfg, -1, np.arange(len(cand)))
    got = candidate_scores("logdet_nav", st, scn.camera, field, cfg, q, np.arange(len(cand)))
    model = FilterModel(scn.camera.sigma_b * scn.noise_scale, scn.depth_sigma_frac, scn.obs_per_landmark, scn.Dt,
                        scn.g, scn.oc)
    want = planned_nav_logdet(st, np.zeros(3), cand, model, scn.camera.boresight_B)
    np.testing.assert_allclose(-got, want, rtol=1e-12)


@functools.lru_cache(maxsize=None)
def _scenario(name):
    from opnav.core.config import load_config
    from landing_helpers import scenario_setups
    from opnav.landing.scenario import build_scenario

    return build_scenario(scenario_setups(load_config()["landing"])[name])


@pytest.mark.slow   # 3-6 s a kind (30 drawn cases, both paths)
@pytest.mark.parametrize("name", PLANNED_METRICS)
@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["interior", "site-tilt"]), st.sampled_from([1, 2, 3, 5]),
       st.booleans(), st.sampled_from([0.02, 0.1, 0.5]), st.sampled_from([0.5, 1.0, 2.0]),
       st.sampled_from([1.0, 5.0]))
def test_compiled_baseline_is_its_numpy_definition_and_plans_as_it(name, seed, camera, n_obs, oc, frac, dt,
                                                                    scale):
    """Each B-X1 information baseline compiled (``information.planned`` through ``plan_one``, the
    Monte Carlo's path) equals its numpy definition (``reference.planned_metric``: the
    information form P0^-1 + A^T A of the candidate's own initialisation, the filter's noise
    sigma_b x scale, n_obs planned observations; the paper path's objective) to round-off for
    hypothesis-drawn states, strategies, noise scales and OC flags, +inf exactly where the
    candidate cannot be initialised or is behind the camera; off a plateau the two paths'
    planning calls (search, edge rule, pick) agree. Mutations tried: the kernel given the true
    noise (nav_constants' sigma_f := sigma_b) fails every kind at scale 5; the site's rows
    without Phi_k (nav_constants) fails every kind at n_obs >= 2."""
    from opnav.landing.planner import PlanState, alternative_path, candidate_scores, plan_one

    scn = _scenario(camera)
    cfg = dataclasses.replace(scn.planner, obs_per_landmark=n_obs, oc=oc, depth_sigma_frac=frac, t_s=dt,
                              noise_scale=scale)
    r, v, a, _, P, _ = _state(seed)
    rng = np.random.default_rng(seed)
    R = exp_so3(rng.normal(0, 0.05, 3))                         # boresight (body -z, tilted) downwards
    cand = np.column_stack([r[0] + rng.uniform(-1500, 1500, 40), r[1] + rng.uniform(-1500, 1500, 40),
                            np.zeros(40)])
    cand = np.vstack([cand, r + [0.0, 0.0, 50.0]])              # above the lander: behind the camera
    st_ = PlanState(r, v, a, R, P)
    field = scn.field.__class__(np.ascontiguousarray(cand))
    det = np.arange(len(cand))
    res, q = plan_one(name, st_, scn.camera, field, cfg, -1, det)
    got = candidate_scores(name, st_, scn.camera, field, cfg, q, det)
    want = -planned_metric(name, st_, np.asarray(cfg.p_known), cand,
                           FilterModel(scn.camera.sigma_b * scale, frac, n_obs, dt, cfg.g, oc), scn.camera.boresight_B)
    fin = np.isfinite(want)
    assert not fin[-1] and np.array_equal(np.isfinite(got), fin) and np.array_equal(got[~fin], want[~fin])
    np.testing.assert_allclose(got[fin], want[fin], rtol=1e-9, atol=1e-9 * np.abs(want[fin]).max())
    if np.ptp(want[fin]) <= 1e-6 * np.abs(want[fin]).max():
        return    # a plateau (n_obs = 1: one bearing adds nothing to its own initialisation): round-off decides
    ref, _ = plan_one(name, st_, scn.camera, field, alternative_path(cfg), -1, det)
    assert (res.index, res.edge, res.n_evals, res.note) == (ref.index, ref.edge, ref.n_evals, ref.note)
    assert res.beta == pytest.approx(ref.beta, abs=1e-9, nan_ok=True)


def test_information_form_definitions_by_hand():
    """``planned_metric`` is what each name says, on one candidate written out by hand from
    ``planned_posterior`` (the Woodbury covariance): logdet = -log det Sigma, mineig =
    1 / lambda_max(Sigma), svd_w / cond_w / gdop_w of the singular values of A P0^1/2 with
    P0^1/2 a symmetric root (rank min(4 n_obs - 2, 11)), logdet_nav = -log det Sigma[:9, :9]."""
    from scipy.linalg import sqrtm

    r, v, a, R, P, cand = _state(4)
    kw = (Estimate(r, v, a, R, P), np.zeros(3), cand, FilterModel(5 * 2.5e-3, 0.1, 3, 1.0, G, True))
    Sig, _ = planned_posterior(*kw)
    A, P0, _ = planned_rows(*kw)
    got = {n: planned_metric(n, *kw) for n in PLANNED_METRICS}
    for i in range(len(cand)):
        s = np.linalg.svd(A[i] @ np.real(sqrtm(P0[i])), compute_uv=False)[:10]
        want = {"logdet": -np.linalg.slogdet(Sig[i])[1], "mineig": 1 / np.linalg.eigvalsh(Sig[i])[-1],
                "svd_w": s[-1], "cond_w": s[-1] / s[0], "gdop_w": 1 / np.sum(s**-2.0),
                "logdet_nav": -np.linalg.slogdet(Sig[i][:9, :9])[1]}
        for n in PLANNED_METRICS:
            assert got[n][i] == pytest.approx(want[n], rel=1e-6), n


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([2, 3, 5]), st.booleans(), st.sampled_from([0.02, 0.1, 0.5]),
       st.sampled_from([1e-3, 5e-3]))
def test_whitened_baselines_are_capped_by_the_site_alone(seed, n_obs, oc, frac, sf):
    """Why svd_w / gdop_w cannot reward a candidate (planning.reference's module docstring): deleting
    the candidate's rows interlaces the singular values, so svd_w <= sigma_min of the site's
    whitened rows alone (whitened_site_bound) and gdop_w <= its square, and that bound is the
    same for every candidate (the site's rows see the navigation prior only; OC's projection
    moves it by round-off). Mutation tried: planned_metric keeping two singular values fewer
    (min(m, 11) - 2: the smallest kept is then a site-and-candidate one) fails the cap."""
    r, v, a, R, P, _ = _state(seed % 1000)
    rng = np.random.default_rng(seed)
    cand = np.column_stack([r[0] + rng.uniform(-1500, 1500, 12), r[1] + rng.uniform(-1500, 1500, 12),
                            np.zeros(12)])
    args = (Estimate(r, v, a, R, P), np.zeros(3), cand, FilterModel(sf, frac, n_obs, 1.0, G, oc))
    bound = whitened_site_bound(*args)
    ok = np.isfinite(bound)
    assert ok.sum() >= 6
    svd_w, gdop_w = planned_metric("svd_w", *args)[ok], planned_metric("gdop_w", *args)[ok]
    b = bound[ok]
    assert np.all(svd_w <= b * (1 + 1e-9)) and np.all(gdop_w <= b * b * (1 + 1e-9))
    assert np.ptp(b) <= 1e-8 * b.max()                          # candidate-independent
    assert np.ptp(svd_w) > 1e-6 * b.max()                       # (the candidates do differ below it)
