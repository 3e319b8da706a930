"""The batched descent (opnav.landing.descent.run_descents) against the frozen
per-run descent of main before the refactor (tests/descent_reference.py), a
run alone against the same run inside batches of other sizes and orders, and
the batched planner's picks against the per-call planner on many planning
states (both camera scenarios, every method)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from opnav.core.config import load_config
from opnav.landing import planner as PL
from opnav.landing.descent import run_descent, run_descents, tracking_step
from opnav.landing.scenario import build_scenario
from landing_helpers import scenario_setups

sys.path.insert(0, str(Path(__file__).parent))
import descent_reference as REF  # noqa: E402

#: per-run outputs compared (timing aside)
KEYS = ("err_r", "err_v", "err_th_deg", "err_rpy_deg", "sig_r", "sig_v", "sig_th_deg", "sig_yaw_deg",
        "nees_r", "nees_v", "updated", "plan_t", "plan_beta", "plan_index", "plan_edge", "plan_ratio",
        "plan_evals", "n_landmarks", "init_error")


@pytest.fixture(scope="module")
def scenarios():
    return {name: build_scenario(c) for name, c in scenario_setups(load_config()["landing"]).items()}


def _field(run, k):
    """A field of a Descent record, or a key of the frozen reference's dict."""
    return run[k] if isinstance(run, dict) else getattr(run, k)


def assert_same_run(a, b, rtol: float = 1e-7, atol: float = 1e-9):
    for k in KEYS:
        x, y = np.asarray(_field(a, k)), np.asarray(_field(b, k))
        assert x.shape == y.shape, k
        if x.dtype.kind in "bi":
            np.testing.assert_array_equal(x, y, err_msg=k)
        else:
            np.testing.assert_allclose(x, y, rtol=rtol, atol=atol, err_msg=k)


@pytest.mark.parametrize("scenario, methods", [("interior", ("depth", "svd", "logdet", "random")),
                                                ("site-tilt", ("depth", "cond"))])
@pytest.mark.slow
def test_batched_descent_equals_the_per_run_reference(scenarios, scenario, methods):
    """Two runs flown as one batch give the numbers of the pre-refactor per-run
    descent (picks identical, states to round-off), in both camera scenarios
    (interior: the paper's in-plane optimum; site-tilt: the edge rule)."""
    scn = scenarios[scenario]
    for m in methods:
        batch = run_descents(scn, m, [3, 1])
        for run, i in zip(batch, (3, 1)):
            assert_same_run(run, REF.run_descent(scn, m, i))


def test_a_run_alone_equals_the_run_inside_batches(scenarios):
    """Batch size and order never change a run's numbers."""
    scn = scenarios["interior"]
    alone = run_descent(scn, "svd", 2)
    for runs in ([2, 0], [3, 1, 0, 2]):
        got = run_descents(scn, "svd", runs)[runs.index(2)]
        assert_same_run(got, alone, rtol=1e-9, atol=1e-10)
        # the recorded planning inputs (timing replay) too
        for k in ("plan_step", "plan_exclude", "plan_rng"):
            np.testing.assert_array_equal(getattr(got, k), getattr(alone, k), err_msg=k)
        for k in ("plan_r", "plan_v", "plan_a", "plan_R", "plan_P"):
            np.testing.assert_allclose(getattr(got, k), getattr(alone, k), rtol=1e-9, atol=1e-10, err_msg=k)
    # ...and the batch of one is run_descent itself
    assert_same_run(run_descents(scn, "svd", [2])[0], alone, rtol=0, atol=0)


def test_runs_differ_and_draws_follow_the_run_index(scenarios):
    """Mutation guard: different runs (streams) give different numbers, and a
    run's initial error is that of SeedSequence([base_seed, i]) whatever its
    position in the batch."""
    scn = scenarios["interior"]
    a, b = run_descents(scn, "depth", [5, 6])
    assert not np.allclose(a.err_r, b.err_r)
    ss = np.random.SeedSequence([scn.base_seed, 6]).spawn(4)[0]
    np.testing.assert_array_equal(b.init_error, REF.initial_error(np.random.default_rng(ss), scn.bounds))


def _planning_calls(scn, runs):
    """(states, visible, exclude, detected) of every batched planning call of a
    depth descent of ``runs``."""
    from opnav.landing import descent as D

    seen = []
    orig = D.plan_batch

    def spy(method, states, camera, field_, visible, cfg, exclude, rngs=None, detected=None, **k):
        seen.append((states, visible, np.array(exclude), np.array(detected)))
        return orig(method, states, camera, field_, visible, cfg, exclude, rngs, detected, **k)

    D.plan_batch = spy
    try:
        run_descents(scn, "depth", runs)
    finally:
        D.plan_batch = orig
    return seen


@pytest.mark.slow
@pytest.mark.parametrize("scenario", ["interior", "site-tilt"])
def test_batched_planner_picks_equal_the_per_call_planner(scenarios, scenario):
    """Every method of planner.available_methods(): on the planning states of a
    batched descent (every 7th call, all runs of it), plan_batch gives the
    landmark, optimum, edge flag, evaluation count and pick ratio of one plan()
    call per run (site-tilt: the edge rule decides the picks; interior: the
    depth optimum lies inside the image, the H baselines' may not)."""
    scn = scenarios[scenario]
    calls = _planning_calls(scn, [0, 1, 2])[::9]
    assert len(calls) >= 4
    n_edge = dict.fromkeys(PL.available_methods(), 0)
    for method in PL.available_methods():
        for states, visible, exclude, detected in calls:
            m = len(exclude)
            rngs = [np.random.default_rng(j) for j in range(m)]
            got = PL.plan_batch(method, states, scn.camera, scn.field, visible, scn.planner, exclude,
                                rngs, detected)
            for j in range(m):
                one = PL.PlanState(states.r[j], states.v[j], states.a[j], states.R_LtoB[j], states.P[j])
                want = PL.plan(method, one, scn.camera, scn.field, visible, scn.planner,
                               exclude={int(exclude[j])} if exclude[j] >= 0 else set(),
                               rng=np.random.default_rng(j), detected=detected)
                g = got[j]
                assert g.index == want.index, (method, j)
                assert g.edge == want.edge and g.n_evals == want.n_evals, (method, j)
                np.testing.assert_allclose(g.beta, want.beta, rtol=1e-9, atol=1e-12)
                np.testing.assert_allclose(g.pick_ratio, want.pick_ratio, rtol=1e-7)
                n_edge[method] += want.edge
    n_calls = sum(len(c[2]) for c in calls)
    if scenario == "site-tilt":        # the edge rule is exercised by every search method
        assert n_edge["depth"] >= 0.8 * n_calls
        assert all(n_edge[m] > 0 for m in PL.OBJECTIVE_METHODS)
    else:
        assert n_edge["depth"] == 0


def test_tracking_step_is_the_fig3_strategy():
    """Known answers: plan when none / observed enough / left the image, unless
    the image holds no other landmark (keep it while seen, else drop it)."""
    cur = np.array([-1, 5, 5, 5, 5, 5])
    n_obs = np.array([0, 1, 3, 1, 3, 1])
    still = np.array([False, True, True, False, True, False])
    other = np.array([True, True, True, True, False, False])
    plan_, observe, cur2, n2 = tracking_step(cur, n_obs, still, other, 3)
    np.testing.assert_array_equal(plan_, [True, False, True, True, False, False])
    np.testing.assert_array_equal(observe, [False, True, False, False, True, False])
    np.testing.assert_array_equal(cur2, [-1, 5, 5, 5, 5, -1])
    np.testing.assert_array_equal(n2, [0, 2, 3, 1, 4, 0])


@pytest.mark.slow  # ~2 CPU-s a method (issue 56: the default run <= 90 s)
@pytest.mark.parametrize("method", ["depth", "logdet"])
def test_skipping_the_pick_ratio_changes_nothing_else(scenarios, method):
    """``pick_ratio=False`` (B-X1-only methods: no table shows it) leaves every pick, state and
    error of the descent as it is and only blanks the diagnostic; with it on, ratios are >= 1."""
    scn = scenarios["interior"]
    on = run_descents(scn, method, [0, 1])
    off = run_descents(scn, method, [0, 1], pick_ratio=False)
    import dataclasses

    for a, b in zip(on, off):
        for k in (f.name for f in dataclasses.fields(a)):
            if k == "plan_ratio":
                continue
            x, y = np.asarray(getattr(a, k)), np.asarray(getattr(b, k))
            assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), k
        r = np.asarray(a.plan_ratio, float)
        assert np.isfinite(r).any() and (r[np.isfinite(r)] >= 1 - 1e-12).all()
        assert np.isnan(np.asarray(b.plan_ratio, float)).all()


def test_a_chunk_is_already_in_gathered_order():
    """A method's single chunk file stands for its gathered Monte Carlo (workflow
    ``b_mc``): ``run_chunk`` holds runs and planning calls in run order, as ``gather``."""
    from opnav.landing.montecarlo import gather, run_chunk

    cfg = scenario_setups(load_config(overlays=[Path(__file__).parents[1] / "config" / "quick.yaml"])
                           ["landing"])["site-tilt"]
    d = run_chunk(cfg, "depth", [0, 1, 2])
    g = gather([d])
    da, ga = d.arrays(), g.arrays()
    assert set(ga) == set(da)
    for k in da:
        x = np.asarray(da[k])
        assert np.array_equal(x, np.asarray(ga[k]), equal_nan=x.dtype.kind == "f"), k
    assert (np.diff(d.plan_run) >= 0).all() and len(set(d.plan_run)) == 3
