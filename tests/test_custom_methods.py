"""A user's own landmark-selection metric (opnav.landing.methods, issue 58): the registry, the
refusals before any work (one line naming the method), the example metric flown in the Monte
Carlo with its picks checked against direct calls of the function, and a method failing during
the Monte Carlo named with its run and call."""

from __future__ import annotations

import copy
import math
import textwrap

import numpy as np
import pytest

from opnav.core.config import load_config
from opnav.landing import methods as M
from opnav.landing import planner as PL
from opnav.landing.montecarlo import run_chunk
from opnav.landing.planning import geometry, layout
from opnav.landing.planning.screens import TIE_RTOL
from opnav.landing.scenario import build_scenario
from opnav.landing.setup import scenario_sections as camera_scenarios
from landing_helpers import landing_setup

EXAMPLE = "examples/parallax.py:parallax_score"


@pytest.fixture(scope="module")
def landing():
    """The quick profile's landing section with a smaller landmark field (the edge rule of
    site-tilt scores every detected landmark: ~600 here instead of ~12,000)."""
    c = copy.deepcopy(load_config(overlays=["config/quick.yaml"])["landing"])
    c["landmarks"] = {**c["landmarks"], "count": 2000, "near_site": {**c["landmarks"]["near_site"], "count": 500}}
    return c


def example_function():
    """examples/parallax.py's function, imported here by file (not through the registry)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("parallax_example_test", M.CHECKOUT / "examples/parallax.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.parallax_score


def with_methods(landing: dict, **entries) -> dict:
    return {**landing, "custom_methods": entries}


def user_file(tmp_path, body: str, name: str = "mine.py") -> str:
    f = tmp_path / name
    f.write_text(textwrap.dedent(body))
    return str(f)


# ---------------------------------------------------------------- the registry

def test_the_builtins_are_the_planners_methods_and_the_schemas():
    """One registry: the planner's methods, the schema's method enum and methods.BUILTIN agree, and a
    custom method is listed after them."""
    import yaml

    from opnav.core.config import SCHEMA_PATH

    schema = yaml.safe_load((SCHEMA_PATH.parent / "landing.schema.yaml").read_text())
    assert M.builtin_names() == PL.available_methods()
    assert set(schema["$defs"]["method"]["enum"]) == set(M.builtin_names())
    cfg = PL.PlannerConfig(custom=(("parallax", EXAMPLE),))
    assert PL.available_methods(cfg) == M.builtin_names() + ("parallax",)
    assert M.get("parallax", cfg.custom).family == "custom"
    assert {M.get(m).family for m in M.builtin_names()} == {"compiled", "picker"}
    with pytest.raises(ValueError, match="unknown planning method 'nope'.*parallax"):
        M.get("nope", cfg.custom)


def test_the_config_forms_and_display():
    spec = {"a": "examples/parallax.py:parallax_score",
            "b": {"path": EXAMPLE, "label": "max. parallax", "color": "#117733"}}
    s = M.specs(spec)
    assert [x.name for x in s.values()] == ["a", "b"] and s["a"].path == s["b"].path == EXAMPLE
    assert M.display("b", spec) == ("max. parallax", "#117733") and M.display("a", spec) == ("a", "")
    assert M.display("depth", spec) == ("", "")
    assert M.labels(spec) == {"a": "a", "b": "max. parallax"} and M.colors(spec) == {"b": "#117733"}
    assert M.spec_items(spec) == (("a", EXAMPLE), ("b", EXAMPLE))
    assert M.source_files(spec) == [str(M.CHECKOUT / "examples/parallax.py")] * 2


def test_the_schema_takes_the_key_and_no_registration_is_the_default():
    from opnav.core.config import schema_problems, SCHEMA_PATH

    cfg = load_config(overlays=["config/quick.yaml"])
    assert cfg["landing"]["custom_methods"] == {}
    cfg["landing"]["custom_methods"] = {"parallax": {"path": EXAMPLE, "label": "x", "color": "C3"}, "p2": EXAMPLE}
    assert schema_problems(cfg, SCHEMA_PATH) == []
    for bad in ({"Parallax": EXAMPLE}, {"p": {"path": EXAMPLE, "colour": "red"}}, {"p": {"label": "x"}}, {"p": 3}):
        cfg["landing"]["custom_methods"] = bad
        assert any("custom_methods" in ln for ln in schema_problems(cfg, SCHEMA_PATH)), bad


# ---------------------------------------------------------------- refusals

def _one_line(landing, name, **entries) -> str:
    lines = M.problems(landing_setup(with_methods(landing, **entries)))
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"invalid config key 'landing.custom_methods.{name}'") and "\n" not in lines[0]
    return lines[0]


def test_the_example_passes_preflight(landing):
    assert M.problems(landing_setup(with_methods(landing, parallax=EXAMPLE))) == []
    assert M.problems(landing_setup(landing)) == []


@pytest.mark.parametrize("path, match", [
    ("no_such_module_xyz.metrics:score", "does not import.*no_such_module_xyz"),
    ("examples/no_such_file.py:score", "file examples/no_such_file.py not found"),
    ("examples/parallax.py:no_such_function", "has no attribute 'no_such_function'"),
    ("examples/parallax.py", "is not 'module:function'"),
    ("math:pi", "is not a function"),
])
def test_a_path_that_does_not_import_is_refused(landing, path, match):
    import re

    assert re.search(match, _one_line(landing, "mine", mine=path))


def test_a_module_that_raises_on_import_is_refused(landing, tmp_path):
    f = user_file(tmp_path, "raise RuntimeError('broken at import')\n")
    assert "importing" in _one_line(landing, "mine", mine=f"{f}:score") and "broken at import" in _one_line(
        landing, "mine", mine=f"{f}:score")


@pytest.mark.parametrize("sig", ["(c, d)", "()", "(*, c)", "(c, d, /)"])
def test_a_wrong_signature_is_refused(landing, tmp_path, sig):
    f = user_file(tmp_path, f"def score{sig}:\n    return 0.0\n", f"sig{abs(hash(sig))}.py")
    assert "must take exactly one argument" in _one_line(landing, "mine", mine=f"{f}:score")


def test_optional_extra_parameters_are_accepted(landing, tmp_path):
    f = user_file(tmp_path, "def score(c, scale=1.0, **kw):\n    return -scale * float(c.p_L[0] ** 2)\n")
    assert M.problems(landing_setup(with_methods(landing, mine=f"{f}:score"))) == []


@pytest.mark.parametrize("name", ["depth", "svd", "logdet_nav", "random", "closest"])
def test_a_builtin_name_is_refused(landing, name):
    assert "is a built-in method's" in _one_line(landing, name, **{name: EXAMPLE})


@pytest.mark.parametrize("body, match", [
    ("return float('nan')", "returned nan"),
    ("return math.inf", "returned inf on the probe call"),
    ("return -math.inf", "returned -inf"),
    ("raise ValueError('bad candidate')", "raised ValueError: bad candidate on the probe call"),
    ("return c.p_L", "not one real number"),
    ("return 'low'", "not one real number"),
    ("return None", "not one real number"),
    ("return True", "not one real number"),
])
def test_a_bad_probe_is_refused(landing, tmp_path, body, match):
    f = user_file(tmp_path, f"import math\n\ndef score(c):\n    {body}\n", f"p{abs(hash(body))}.py")
    assert match in _one_line(landing, "mine", mine=f"{f}:score")


def test_the_probe_sees_a_documented_candidate(landing, tmp_path):
    """The probe hands the function a Candidate whose fields have the documented shapes and units."""
    seen = []
    f = user_file(tmp_path, "SEEN = []\n\ndef score(c):\n    SEEN.append(c)\n    return 0.0\n", "seen.py")
    m = M.load(M.CustomSpec("mine", f"{f}:score"))
    M.probe(m, landing_setup(landing))
    seen = m.fn.__globals__["SEEN"]
    assert len(seen) == 2
    c = seen[0]
    assert isinstance(c, M.Candidate)
    assert [np.shape(x) for x in c[:8]] == [(3,), (3,), (3,), (3,), (3, 3), (12, 12), (3,), (3, 3)]
    np.testing.assert_allclose(c.r_L, landing["initial_state"]["r_m"])
    np.testing.assert_allclose(c.P[0, 0], landing["mc"]["bounds"]["r_m"] ** 2 / 3)
    np.testing.assert_allclose(c.R_LtoB @ c.R_LtoB.T, np.eye(3), atol=1e-12)
    assert c.t_s == landing["filter"]["dt_s"] and seen[1].p_L[2] == 0.0


def test_the_preflight_refuses_before_any_work(tmp_path):
    """opnav.preflight (the workflow's validation step and the CLI's) carries the method's line."""
    from opnav.preflight import problems

    cfg = load_config(overlays=["config/quick.yaml"])
    f = user_file(tmp_path, "def score(c):\n    return float('nan')\n")
    cfg["landing"]["custom_methods"] = {"mine": f"{f}:score"}
    lines = problems(cfg)
    assert [ln for ln in lines if "custom_methods" in ln] == [
        ln for ln in lines if ln.startswith("invalid config key 'landing.custom_methods.mine'")] and lines


# ---------------------------------------------------------------- flying it

def _candidate(d, i, p, scn) -> M.Candidate:
    """The documented record of recorded call ``i`` at point ``p``, built here from the records."""
    cam, cfg = scn.camera, scn.planner
    P = d.plan_P[i]
    return M.Candidate(np.asarray(p, float), d.plan_r[i], d.plan_v[i], d.plan_a[i], d.plan_R[i],
                       0.5 * (P + P.T), np.zeros(3), cam.R_BtoC, cam.sigma_b, cfg.noise_scale, cfg.t_s,
                       cfg.obs_per_landmark)


def check_picks(d, scn, fn) -> dict:
    """Every recorded call's pick against direct calls of ``fn``: an edge call's pick is the tie
    rule's best of the detected landmarks; an in-plane call's optimum beta* scores within the
    search's tolerance of the best of a dense grid over its visible interval, and its pick is the
    detected landmark nearest (horizontally) to beta*'s ground point."""
    counts = {"edge": 0, "plane": 0}
    tr, cam, xyz = scn.truth, scn.camera, scn.field.xyz
    for i in range(len(d.plan_index)):
        k = int(d.plan_step[i])
        det = np.flatnonzero(cam.in_view((xyz - tr.r[k]) @ tr.R_LtoB[k].T, scn.planner.margin_px))
        cand = det[det != d.plan_exclude[i]]
        pick = int(d.plan_index[i])
        if d.plan_edge[i]:
            s = np.array([fn(_candidate(d, i, xyz[j], scn)) for j in cand])
            best = s.min()
            assert pick == cand[np.flatnonzero(s <= best + TIE_RTOL * abs(best))[0]], i
            counts["edge"] += 1
            continue
        beta = float(d.plan_beta[i])
        if not math.isfinite(beta):          # the documented fallback (no visible interval)
            continue
        geom = geometry.plane_geometry(d.plan_r[i], d.plan_v[i])
        ivals = PL.visible_intervals(geom, d.plan_R[i], cam, scn.planner.margin_px)
        grid = np.concatenate([np.linspace(a + 1e-9, b - 1e-9, 200) for a, b in ivals])
        f = lambda b: fn(_candidate(d, i, geometry.ground_points(b, geom)[0], scn))  # noqa: E731
        f_grid = np.array([f(b) for b in grid])
        h = max(1e-6, scn.planner.tol_rad)
        slope = max(abs(f(beta + h) - f(beta)), abs(f(beta - h) - f(beta))) / h
        assert f(beta) <= f_grid.min() + slope * scn.planner.tol_rad + 1e-12, i
        g = geometry.ground_points(beta, geom)[0]
        dist = np.hypot(xyz[cand, 0] - g[0], xyz[cand, 1] - g[1])
        assert pick == cand[np.argmin(dist)], i
        counts["plane"] += 1
    return counts


@pytest.fixture(scope="module")
def flown(landing):
    """The example flown for two runs in each camera scenario."""
    out = {}
    for scn_name, c in camera_scenarios(with_methods(landing, parallax=EXAMPLE)).items():
        out[scn_name] = (build_scenario(landing_setup(c)), run_chunk(landing_setup(c), "parallax", [1, 2]))
    return out


@pytest.mark.slow  # ~1.5 CPU-s (issue 56: the default run <= 90 s)
def test_the_example_flies_and_picks_what_the_function_says(flown):
    """The example metric in the Monte Carlo: its picks equal direct calls of the function (edge
    calls in site-tilt, in-plane optima in interior)."""
    parallax_score = example_function()
    seen = {"edge": 0, "plane": 0}
    for name, (scn, d) in flown.items():
        assert len(d.plan_index) > 10 and (d.method or "parallax") == "parallax"
        assert np.all(np.isnan(d.plan_ratio))          # a user's score has no scale: no ratio
        for k, v in check_picks(d, scn, parallax_score).items():
            seen[k] += v
    assert seen["edge"] >= 5 and seen["plane"] >= 5, seen


def test_a_builtin_is_unchanged_by_a_registration(landing, flown):
    """Registering a method changes no built-in method's run (the same picks and errors)."""
    c = camera_scenarios(landing)["interior"]
    plain = run_chunk(landing_setup(c), "depth", [1])
    reg = run_chunk(landing_setup({**c, "custom_methods": {"parallax": EXAMPLE}}), "depth", [1])
    for k in ("plan_index", "plan_beta", "err_r", "nees_r"):
        np.testing.assert_array_equal(getattr(plain, k), getattr(reg, k), err_msg=k)


def test_the_mutated_function_would_fail_the_pick_check(flown):
    """The pick check has teeth: a function that ranks otherwise (plus the parallax) fails it."""
    parallax_score = example_function()
    scn, d = flown["site-tilt"]
    with pytest.raises(AssertionError):
        check_picks(d, scn, lambda c: -parallax_score(c))


@pytest.mark.slow
def test_a_numba_function_flies_compiled_with_the_same_picks(landing, flown, tmp_path):
    numba = pytest.importorskip("numba")   # noqa: F841
    f = user_file(tmp_path, """
        import math
        import numba

        @numba.njit(cache=False)
        def score(c):
            d = c.p_L - c.r_L
            rho = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
            speed = math.sqrt(c.v_L[0] ** 2 + c.v_L[1] ** 2 + c.v_L[2] ** 2)
            if rho == 0.0 or speed == 0.0:
                return math.inf
            cos_t = (d[0] * c.v_L[0] + d[1] * c.v_L[1] + d[2] * c.v_L[2]) / (rho * speed)
            return -speed * c.t_s * math.sqrt(max(0.0, 1.0 - cos_t * cos_t)) / rho
        """, "jitted.py")
    c = with_methods(camera_scenarios(landing)["interior"], jitted=f"{f}:score")
    assert M.problems(landing_setup({**landing, "custom_methods": c["custom_methods"]})) == []
    scn = build_scenario(landing_setup(c))
    assert M.eval_path("jitted", scn.planner).startswith("custom (compiled search and score")
    assert PL.compiled_kind("jitted", scn.planner) == PL.OWN_COMPILED
    assert M.eval_path("depth", scn.planner) == "compiled"
    for name in ("interior", "site-tilt"):      # in-plane optima, then edge calls
        c = with_methods(camera_scenarios(landing)[name], jitted=f"{f}:score")
        d = run_chunk(landing_setup(c), "jitted", [1, 2])
        ref = flown[name][1]
        np.testing.assert_array_equal(d.plan_index, ref.plan_index)
        np.testing.assert_array_equal(d.plan_evals, ref.plan_evals)
        np.testing.assert_allclose(d.plan_beta, ref.plan_beta, rtol=1e-12, atol=1e-15)
    # the timed call is the compiled kernel itself, and it picks what plan() picks
    scn = build_scenario(landing_setup(c))
    i = 3
    state = PL.PlanState(d.plan_r[i], d.plan_v[i], d.plan_a[i], d.plan_R[i], d.plan_P[i])
    k = int(d.plan_step[i])
    det = np.flatnonzero(scn.camera.in_view((scn.field.xyz - scn.truth.r[k]) @ scn.truth.R_LtoB[k].T,
                                            scn.planner.margin_px))
    call = PL.compiled_call("jitted", state, scn.camera, scn.field, scn.planner, int(d.plan_exclude[i]), det)
    call()
    assert int(call.args[-1][-layout.NOUT + layout.O_PICK]) == int(d.plan_index[i])


@pytest.mark.slow
def test_a_numba_function_scoring_nan_in_the_compiled_call_is_named(landing, tmp_path):
    f = user_file(tmp_path, """
        import math
        import numba

        @numba.njit(cache=False)
        def score(c):
            return math.nan if c.r_L[2] < 1500.0 else c.p_L[0] ** 2
        """, "jit_nan.py")
    c = with_methods(camera_scenarios(landing)["interior"], late=f"{f}:score")
    assert M.problems(landing_setup(with_methods(landing, late=f"{f}:score"))) == []
    with pytest.raises(M.MethodError, match=r"^landing\.custom_methods\.late: \S+ returned nan or -inf .* in run 2, "
                                            r"planning call \d+"):
        run_chunk(landing_setup(c), "late", [2])


# ---------------------------------------------------------------- failing in the Monte Carlo

@pytest.mark.parametrize("body, match", [
    ("raise RuntimeError('too low')", r"raised RuntimeError: too low in run 2, planning call \d+ \(t = [0-9.]+ s; method 'late'\)"),
    ("return float('nan')", r"returned nan .* in run 2, planning call \d+"),
])
def test_a_method_failing_in_the_monte_carlo_names_the_method_run_and_call(landing, tmp_path, body, match):
    """Below 1500 m the function fails (it passes the probe, at the start): the job stops with a
    MethodError naming the method, the run and the call."""
    f = user_file(tmp_path, f"import math\n\ndef score(c):\n    if c.r_L[2] < 1500.0:\n        {body}\n"
                            "    return float(c.p_L[0] ** 2)\n", f"late{abs(hash(body))}.py")
    entry = {"late": f"{f}:score"}
    assert M.problems(landing_setup(with_methods(landing, **entry))) == []
    c = with_methods(camera_scenarios(landing)["interior"], **entry)
    with pytest.raises(M.MethodError, match=r"^landing\.custom_methods\.late: \S+:score " + match):
        run_chunk(landing_setup(c), "late", [2])


def test_a_failing_job_writes_nothing(landing, tmp_path):
    """The Monte-Carlo job's script: the failure leaves no chunk file (records.save is atomic and
    runs after the runs)."""
    from opnav.landing.montecarlo import run_chunk_reusing, save

    f = user_file(tmp_path, "def score(c):\n    if c.r_L[2] < 1500.0:\n        raise RuntimeError('x')\n"
                            "    return 0.0\n", "late_write.py")
    c = with_methods(camera_scenarios(landing)["interior"], late=f"{f}:score")
    out = tmp_path / "chunks" / "late" / "r0000-0000.npz"
    out.parent.mkdir(parents=True)
    with pytest.raises(M.MethodError):
        data, _ = run_chunk_reusing(out, "key", landing_setup(c), "late", [0])
        save(out, data, "late")
    assert list(out.parent.iterdir()) == []
