"""Parameter studies (opnav.studies): planning and validation of the `studies` section,
paired runs, chunk-independent results, and the summary statistics."""

import copy

import numpy as np
import pandas as pd
import pytest
from conftest import REPO
from scipy import stats

from opnav.core.config import ConfigError, load_config
from opnav.landing.montecarlo import run_chunk
from landing_helpers import landing_setup
from opnav.landing.planner import available_methods
from opnav.preflight import check_config
from opnav.studies import captions, planning, tables, values

QUICK = [REPO / "config" / "quick.yaml"]
# the simulations' views of the config (as the rules pass them: studies.smk)
SIM_LANDING = ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "imu", "camera", "landmarks",
               "filter", "planner")


def _shapes(cfg):
    land = {k: cfg["landing"][k] for k in SIM_LANDING}
    land["mc"] = {k: cfg["landing"]["mc"][k] for k in ("base_seed", "bounds")}
    land["timing"] = {"max_calls": cfg["landing"]["timing"]["max_calls"]}
    appr = {k: cfg["approach"][k] for k in cfg["approach"] if k not in ("variants", "methods", "scatter")}
    return {"landing": land, "approach": appr}


def _plan(cfg):
    return planning.plan(cfg, _shapes(cfg), lambda c: check_config(c), available_methods())


def _with_study(cfg, name, **spec):
    cfg = copy.deepcopy(cfg)
    cfg["studies"] = {name: spec}
    return cfg


@pytest.fixture(scope="module")
def quick():
    return load_config(overlays=QUICK)


def test_configured_studies_plan_and_share_identical_simulations(quick):
    plan = _plan(quick)
    assert {"fov", "obs", "ifov"} <= set(plan)
    fov, obs = plan["fov"], plan["obs"]
    assert [i.label for i in fov.instances] == ["fov_deg~45", "fov_deg~60"]
    # fov = 60 deg and obs = 3 are both the configured (main Monte Carlo) simulation: one digest
    default = values.config_digest({"paper": "landing",
                                     "sim": values.project(quick["landing"], _shapes(quick)["landing"])})
    assert fov.instances[1].digest == obs.instances[1].digest == default
    assert fov.instances[0].digest != default


@pytest.mark.parametrize("spec, fragments", [
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [60.0, -5.0]}},
     ["study 'bad'", "landing.camera.fov_deg = -5.0", "invalid config key 'landing.camera.fov_deg'"]),
    ({"paper": "landing", "vary": {"landing.filter.obs_per_landmark": [2, "many"]}},
     ["study 'bad'", "landing.filter.obs_per_landmark = 'many'", "not of type"]),
    ({"paper": "approach", "vary": {"approach.camera.ifov_arcsec": [10.0, 0.0]}},
     ["study 'bad'", "approach.camera.ifov_arcsec = 0.0"]),
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [60.0, 10.0]}},     # physics check
     ["study 'bad'", "landing.camera.fov_deg = 10.0", "invalid config key 'landing.camera'", "view"]),
    ({"paper": "landing", "vary": {"landing.camera.colour": [1]}},
     ["study 'bad'", "'landing.camera.colour' is not a config key"]),
    ({"paper": "landing", "vary": {"approach.camera.ifov_arcsec": [1.0]}},
     ["study 'bad'", "not under 'landing.'"]),
    ({"paper": "landing", "vary": {"landing.mc.n_runs": [5, 6]}},
     ["study 'bad'", "'landing.mc.n_runs' is not read by the landing simulation"]),
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [45.0, 60.0], "landing.imu.rate_hz": [10.0]}},
     ["study 'bad'", "different lengths"]),
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [45.0]}, "methods": ["depth", "oracle"]},
     ["study 'bad'", "unknown method(s) ['oracle']"]),
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [45.0]}, "metrics": ["happiness"]},
     ["study 'bad'", "unknown metric(s) ['happiness']"]),
    ({"paper": "landing", "vary": {"landing.camera.fov_deg": [45, 45.0]}},
     ["study 'bad'", "coincide"]),
    ({"paper": "approach", "vary": {"approach.camera.ifov_arcsec": [10.0]}, "runs": 10000, "runs_per_job": 10000},
     ["study 'bad'", "runs_per_job = 10000", "memory"]),
    ({"paper": "approach", "vary": {"approach.camera.ifov_arcsec": [10.0]},
      "fixed": {"approach.camera.ifov_arcsec": 20.0}},
     ["study 'bad'", "both swept (vary) and fixed"]),
    ({"paper": "approach", "vary": {"approach.camera.ifov_arcsec": [10.0]},
      "fixed": {"approach.initial_error.mode": "guessed"}},
     ["study 'bad'", "approach.initial_error.mode"]),
])
def test_bad_study_is_refused_naming_study_and_key(quick, spec, fragments):
    with pytest.raises(ConfigError) as exc:
        _plan(_with_study(quick, "bad", **spec))
    for f in fragments:
        assert f in str(exc.value), str(exc.value)


def test_grid_is_the_cartesian_product(quick):
    cfg = _with_study(quick, "g", paper="landing", grid=True,
                      vary={"landing.camera.fov_deg": [45.0, 60.0, 75.0], "landing.filter.obs_per_landmark": [2, 3]})
    s = _plan(cfg)["g"]
    assert len(s.instances) == 6 and len({i.digest for i in s.instances}) == 6
    assert s.instances[1].values == {"landing.camera.fov_deg": 45.0, "landing.filter.obs_per_landmark": 3}
    assert s.instances[1].sim["camera"]["fov_deg"] == 45.0 and s.instances[1].sim["filter"]["obs_per_landmark"] == 3


def test_study_run_at_the_default_value_is_the_main_run_and_values_are_paired(quick):
    """Run i of a study is main Monte-Carlo run i at the configured value (bit for bit);
    another value draws the same initial error (paired) but flies differently."""
    plan = _plan(quick)
    main = run_chunk(landing_setup(quick["landing"]), "depth", [1])
    at_default = run_chunk(landing_setup(plan["obs"].instances[1].sim), "depth", [1])      # obs = 3, configured
    for k in ("err_r", "err_v", "nees_r", "plan_index", "plan_t", "init_error"):
        assert np.array_equal(getattr(main, k), getattr(at_default, k)), k
    other = run_chunk(landing_setup(plan["obs"].instances[0].sim), "depth", [1])            # obs = 2
    assert np.array_equal(other.init_error, main.init_error)
    assert not np.array_equal(other.err_r, main.err_r)


def test_approach_study_runs_do_not_depend_on_chunking(quick):
    from opnav.approach.study import run_runs

    from opnav.approach.setup import Setup

    cfg = Setup.from_config(_plan(quick)["ifov"].instances[1].sim)
    whole = run_runs(cfg, "roll", "em", [0, 1, 2])
    parts = pd.concat([run_runs(cfg, "roll", "em", [0, 1]), run_runs(cfg, "roll", "em", [2])],
                      ignore_index=True)
    pd.testing.assert_frame_equal(whole, parts, check_exact=False, rtol=1e-12, atol=0)
    aug = run_runs(cfg, "roll", "augmented", [0, 1, 2])
    assert not np.allclose(aug["err_x_arcsec"], whole["err_x_arcsec"])
    assert (aug["crlb_x_arcsec"] == whole["crlb_x_arcsec"]).all()           # same data, same bound


def test_summary_statistics_known_answers():
    rng = np.random.default_rng(3)
    a = rng.normal(5.0, 2.0, 12)
    d = rng.normal(0.5, 0.3, 12)
    runs = pd.DataFrame({"instance": "v~1", "run": np.r_[np.arange(12), np.arange(12)],
                         "method": ["a"] * 12 + ["b"] * 12, "m": np.r_[a, a + d]})
    runs = runs.sample(frac=1.0, random_state=0)        # order must not matter (paired by run)
    t = tables.summarize(runs, ["m"], ["a", "b"]).set_index("method")
    assert t.loc["a", "mean"] == pytest.approx(a.mean(), rel=1e-12)
    assert t.loc["a", "sd"] == pytest.approx(a.std(ddof=1), rel=1e-12)
    assert t.loc["a", "rms"] == pytest.approx(np.sqrt(np.mean(a**2)), rel=1e-12)
    ci = stats.ttest_1samp(a, 0.0).confidence_interval(0.95)
    assert (t.loc["a", "ci95_low"], t.loc["a", "ci95_high"]) == pytest.approx((ci.low, ci.high), rel=1e-10)
    paired = stats.ttest_rel(a + d, a).confidence_interval(0.95)
    assert t.loc["b", "diff_mean"] == pytest.approx(d.mean(), rel=1e-10)
    assert (t.loc["b", "diff_ci95_low"], t.loc["b", "diff_ci95_high"]) == pytest.approx(
        (paired.low, paired.high), rel=1e-10)
    assert np.isnan(t.loc["a", "diff_mean"]) and int(t.loc["b", "n_runs"]) == 12


def test_instance_labels():
    assert values.instance_label({"landing.camera.fov_deg": 45.0}) == "fov_deg~45"
    assert values.instance_label({"landing.imu.sigma_a_mps2": 2.5e-4}) == "sigma_a_mps2~0.00025"
    assert values.instance_label({"approach.camera.sigma3_px": [0.1, 0.1, 0.2]}) == "sigma3_px~0.1,0.1,0.2"
    # same leaf under two sections: one more component
    assert values.instance_label({"landing.camera.pixels": 512, "approach.camera.pixels": 256}) == \
        "landing.camera.pixels~512_approach.camera.pixels~256"


def test_gather_runs_keeps_the_study_units_and_refuses_missing_runs():
    """A study job's chunk holds every unit of the studies sharing that value: a study
    keeps its own (variant, method) rows; a chunk missing one of its runs is refused."""
    spec = {"name": "s", "paper": "approach", "runs": 2, "methods": ["em"], "variants": ["roll"],
            "keys": ["approach.camera.ifov_arcsec"], "instances": {"a": {"approach.camera.ifov_arcsec": 10.0}}}
    rows = [{"run": r, "variant": v, "method": m, "err_x_arcsec": float(10 * r + len(v) + len(m))}
            for r in (0, 1, 2) for v in ("literal", "roll") for m in ("em", "augmented")]
    runs = tables.gather_runs([("a", pd.DataFrame(rows))], spec)
    assert sorted(zip(runs["run"], runs["variant"], runs["method"])) == [(0, "roll", "em"), (1, "roll", "em")]
    assert list(runs["err_x_arcsec"]) == [6.0, 16.0]
    short = pd.DataFrame([r for r in rows if not (r["run"] == 1 and r["variant"] == "roll" and r["method"] == "em")])
    with pytest.raises(ValueError, match="1 runs of roll/em, expected 2"):
        tables.gather_runs([("a", short)], spec)


def test_gathered_runs_do_not_depend_on_the_chunking():
    """The same runs in one chunk or in one chunk per run (runs_per_job 1) gather to the
    same table, row order included."""
    spec = {"name": "s", "paper": "landing", "runs": 3, "methods": ["svd", "depth"], "variants": [],
            "keys": ["landing.camera.fov_deg"], "instances": {"a": {"landing.camera.fov_deg": 45.0},
                                                              "b": {"landing.camera.fov_deg": 60.0}}}
    rows = {(i, r, m): {"run": r, "method": m, "final_pos_err_m": 100 * len(i) + 10 * r + len(m) / 7}
            for i in ("a", "b") for r in range(3) for m in ("depth", "svd")}

    def chunk(i, runs):  # a job flies every method of its chunk, methods in job order
        return pd.DataFrame([rows[(i, r, m)] for m in ("depth", "svd") for r in runs])

    one = tables.gather_runs([("a", chunk("a", [0, 1, 2])), ("b", chunk("b", [0, 1, 2]))], spec)
    per_run = tables.gather_runs([(i, chunk(i, [r])) for i in ("a", "b") for r in range(3)], spec)
    pd.testing.assert_frame_equal(one, per_run)
    assert list(one["method"][:3]) == ["svd"] * 3 and list(one["run"][:3]) == [0, 1, 2]


def test_caption_states_the_replay_budget_of_the_planning_times(quick):
    """Paper-B studies time planning calls by replay of at most landing.timing.max_calls
    calls per job: the caption gives the budget and the calls a run's median rests on;
    a study without a timing metric says nothing of it."""
    cfg = _with_study(quick, "t", paper="landing", vary={"landing.camera.fov_deg": [45.0, 60.0]},
                      metrics=["median_plan_time_us"], runs=6, runs_per_job=3)
    cfg["landing"]["timing"]["max_calls"] = n = 30   # the budget the test reads (not the profile's)
    spec = _plan(cfg)["t"].spec()
    assert spec["timing_calls"] == n
    cap = captions.caption(spec)
    assert f"at most {n} of a job's recorded planning calls" in cap
    assert "jobs of 3 runs" in cap and "about 10 calls" in cap, cap
    quiet = _with_study(quick, "q", paper="landing", vary={"landing.camera.fov_deg": [45.0, 60.0]},
                        metrics=["final_pos_err_m"], runs=2, runs_per_job=2)
    assert "replay" not in captions.caption(_plan(quiet)["q"].spec())
    assert _plan(quick)["ifov"].timing_calls is None          # paper A: no planning calls
