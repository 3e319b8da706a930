"""Paper B's config parsed once (issue 56 item 2): ``opnav.landing.setup.Setup``, the typed
``landing`` section every paper-B function takes; the raw mapping only at the edges (the
workflow's scripts, the CLI, the preflight)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from opnav.core.config import load_config
from opnav.core.sections import Missing
from opnav.landing.setup import Setup, scenario_sections

#: keys only the ``landing`` config mapping holds (a constant-string subscript or .get of one of
#: these inside src/opnav/landing is the raw config read again; ``scenarios``, ``equivalence``,
#: ``tuning``, ``timing``, ``n_runs`` also name parts of the summaries and are left out)
SECTION_KEYS = {"landing", "gravity_mps2", "duration_s", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu",
                "camera", "landmarks", "filter", "planner", "single", "figures", "mc", "custom_methods",
                "headline_scenario", "near_site", "bounds", "batch_size", "base_seed"}


def test_the_config_parses_into_a_frozen_hashable_setup():
    c = load_config()["landing"]
    s = Setup.from_config(c)
    assert s.filter.meas_noise_scale == c["filter"]["meas_noise_scale"] and s.mc.bounds.r_m == c["mc"]["bounds"]["r_m"]
    assert s.tuning.candidates == tuple((float(a), int(b)) for a, b in c["tuning"]["candidates"])
    assert hash(s) == hash(Setup.from_config(c)) and s == Setup.from_config(c)     # a cache key
    assert s.with_filter(iterations=1) != s and s.with_filter(iterations=1).filter.iterations == 1
    with pytest.raises(TypeError, match="landing Setup"):
        from opnav.landing.scenario import build_scenario

        build_scenario(c)          # the raw mapping is refused below the edge


def test_a_key_the_rule_did_not_pass_fails_on_use_naming_it():
    """A rule's part of the section (B_SIMS: mc holds base_seed and bounds only): the absent keys
    are Missing and fail on first use with one line naming the dotted key; a key with a default
    (mc.batch_size, yaw_deg, custom_methods) takes it."""
    part = {"mc": {"base_seed": 3, "bounds": {"r_m": 1.0, "v_mps": 2.0, "att_deg": 3.0}}}
    s = Setup.from_config(part)
    assert s.mc.base_seed == 3 and s.mc.batch_size == 0 and s.yaw_deg == 0.0 and s.custom_methods == ()
    assert isinstance(s.mc.n_runs, Missing) and isinstance(s.filter, Missing)
    for use in (lambda: int(s.mc.n_runs), lambda: s.mc.n_runs + 1, lambda: s.filter.dt_s, lambda: list(s.mc.methods)):
        with pytest.raises(KeyError, match=r"landing\.(mc\.n_runs|filter|mc\.methods): not among this rule's params"):
            use()


def test_camera_scenarios_parsed_equal_the_workflows_mappings_parsed():
    """Setup.scenarios_by_name (the package's) and scenario_sections (the workflow's mappings, the
    rules' params) give the same camera per scenario, in config order; an unknown headline is
    refused by both, naming the key."""
    c = load_config()["landing"]
    s = Setup.from_config(c)
    ours, theirs = s.scenarios_by_name(), scenario_sections(c)
    assert list(ours) == list(theirs) == list(c["scenarios"])
    for n in ours:
        assert ours[n].camera == Setup.from_config(theirs[n]).camera
    assert ours["interior"].camera.fov_deg == c["scenarios"]["interior"]["fov_deg"] != s.camera.fov_deg
    assert s.headline() == c["headline_scenario"]
    bad = {**c, "headline_scenario": "nadir"}
    for f in (lambda: scenario_sections(bad), lambda: Setup.from_config(bad).scenarios_by_name()):
        with pytest.raises(ValueError, match="landing.headline_scenario: 'nadir'"):
            f()


def _raw_reads(tree: ast.AST) -> list[tuple[int, str]]:
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Load) \
                and isinstance(node.slice, ast.Constant) and node.slice.value in SECTION_KEYS:
            out.append((node.lineno, f'[{node.slice.value!r}]'))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "get" \
                and node.args and isinstance(node.args[0], ast.Constant) and node.args[0].value in SECTION_KEYS:
            out.append((node.lineno, f'.get({node.args[0].value!r})'))
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for a in node.args.args + node.args.kwonlyargs:
                ann = ast.unparse(a.annotation) if a.annotation is not None else ""
                if "Setup" in ann and ("|" in ann or "Union" in ann or "Optional" in ann):
                    out.append((node.lineno, f"{node.name}({a.arg}: {ann})"))
                if a.arg.endswith("_cfg") or a.arg in ("landing", "config"):
                    out.append((node.lineno, f"{node.name}({a.arg})"))
    return out


def test_the_landing_package_reads_no_raw_config():
    """Inside src/opnav/landing only setup.py (the parse) reads the ``landing`` mapping: no
    constant-string subscript or .get of a section key, no ``Setup | dict`` parameter, no
    ``*_cfg`` / ``landing`` / ``config`` parameter (read from the sources with ast). The CLI is the
    edge: it reads the checked config's ``landing`` section once, to parse it. Mutation: a
    ``landing_cfg["mc"]["batch_size"]`` back in montecarlo.run_chunk fails it."""
    import opnav.landing as pkg

    root = Path(pkg.__file__).parent
    edge = {"setup.py": (), "cli.py": ("['landing']",), "bsummary.py": (".get('headline_scenario')",),
            # tuning.json read back (TuningReport.from_json): the document's key, not the config's
            "tuning.py": ("['base_seed']",)}
    bad = []
    for p in sorted(root.rglob("*.py")):
        rel = str(p.relative_to(root))
        for line, what in _raw_reads(ast.parse(p.read_text())):
            if rel == "setup.py" or what in edge.get(rel, ()):
                continue
            bad.append(f"{rel}:{line} {what}")
    assert not bad, "\n".join(bad)


def test_the_checker_sees_a_raw_read():
    tree = ast.parse("def run_chunk(landing_cfg: dict):\n    return landing_cfg['mc'].get('batch_size', 0)\n")
    assert {w for _, w in _raw_reads(tree)} == {"run_chunk(landing_cfg)", "['mc']", ".get('batch_size')"}
