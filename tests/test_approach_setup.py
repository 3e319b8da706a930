"""The approach config parsed once into a frozen Setup (approach.setup)."""

import dataclasses

import pytest

from approach_helpers import approach_cfg
from opnav.approach import scenario as sc
from opnav.approach.setup import Missing, Setup


def test_setup_holds_the_config_values_and_is_frozen():
    cfg = approach_cfg(N0=30, N=10, L=4)
    s = Setup.from_config(cfg)
    with pytest.raises(TypeError, match="approach setup"):  # parsed once: a Setup is not parsed again
        Setup.from_config(s)
    assert (s.segments.N0, s.segments.N, s.segments.L) == (30, 10, 4)
    assert s.segments.windows() == [(30 + 10 * l, 40 + 10 * l) for l in range(4)]
    assert s.camera.sigma3_px == tuple(cfg["camera"]["sigma3_px"])
    assert s.em.method == cfg["em"]["method"] and s.base_seed == cfg["base_seed"]
    assert s.alternatives.batch_ml.checkpoint_stride == cfg["alternatives"]["batch_ml"]["checkpoint_stride"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.n_seeds = 3


def test_growing_scheme_covers_the_same_data():
    cfg = approach_cfg(N0=30, N=10, L=4)
    cfg["growing"].update(N=20, M=3)
    g = Setup.from_config(cfg).scheme("growing").segments
    assert (g.mode, g.N, g.M, g.L) == ("growing", 20, 3, 2)
    assert g.windows() == [(30, 50), (30, 70)]
    cfg["growing"]["N"] = 15
    with pytest.raises(ValueError, match="growing.N"):
        Setup.from_config(cfg).scheme("growing")


def test_a_key_the_rule_did_not_pass_fails_naming_it():
    cfg = approach_cfg()
    part = Setup.from_config({k: cfg[k] for k in ("segments", "dt_s")})
    assert part.segments.N == cfg["segments"]["N"]
    assert isinstance(part.em, Missing)
    with pytest.raises(KeyError, match="approach.em"):
        part.em.method
    with pytest.raises(KeyError, match="approach.n_seeds"):
        range(part.n_seeds)


def test_measurement_variance_refuses_a_different_camera():
    cfg = Setup.from_config(approach_cfg(N0=5, N=5, L=1))
    geo = sc.build_geometry(cfg, "literal")
    other = approach_cfg(N0=5, N=5, L=1)
    other["camera"]["ifov_arcsec"] = 20.0
    other = Setup.from_config(other)
    with pytest.raises(ValueError, match="ifov_arcsec"):
        sc.measurement_variance(geo, other, (0.1, 0.1, 0.2))
    assert (sc.measurement_variance(geo, cfg, (0.1, 0.1, 0.2)) == geo.measurement_variance((0.1, 0.1, 0.2))).all()


def test_the_config_is_parsed_once_no_function_takes_the_raw_section():
    """Issue 56 item 3: every paper-A function takes the Setup; none accepts ``Setup | dict`` and
    parses it again (Setup.of is gone). Read from the sources (ast). Mutation: a ``setup: Setup |
    dict`` parameter put back in cases.run_case fails it."""
    import ast
    from pathlib import Path

    import opnav.approach as pkg

    bad = []
    for p in sorted(Path(pkg.__file__).parent.glob("*.py")):
        tree = ast.parse(p.read_text())
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for a in node.args.args + node.args.kwonlyargs:
                    ann = ast.unparse(a.annotation) if a.annotation is not None else ""
                    if "Setup" in ann and ("|" in ann or "Union" in ann or "Optional" in ann):
                        bad.append(f"{p.name}:{node.lineno} {node.name}({a.arg}: {ann})")
            if isinstance(node, ast.Attribute) and node.attr == "of" and getattr(node.value, "id", "") == "Setup":
                bad.append(f"{p.name}:{node.lineno} Setup.of")
    assert not bad, bad
    assert not hasattr(Setup, "of")


def test_the_accuracy_target_has_one_home_the_analysis_plan(tmp_path):
    """Issue 56 item 3: the claimed accuracy the approach code computes with is the analysis plan's
    A-C1 target (claims.A-C1.margins.target_arcsec), read without the report layer, and no config
    key holds a second copy. Mutation: a plan with another target gives that target (the accessor
    reads the file it is given, an edited file again), a plan without it is refused naming the key."""
    from opnav.core import planvalues
    from opnav.report.plan import load_plan

    assert planvalues.accuracy_target_arcsec() == load_plan().margin("A-C1", "target_arcsec")
    assert "accuracy_target_arcsec" not in approach_cfg()
    assert "accuracy_target_arcsec" not in {f.name for f in dataclasses.fields(Setup)}
    text = planvalues.PLAN_FILE.read_text()
    p = tmp_path / "plan.yaml"
    p.write_text(text.replace('target_arcsec: {value: 2.0, reason: "the accuracy the paper states (published.yaml',
                              'target_arcsec: {value: 3.5, reason: "the accuracy the paper states (published.yaml', 1))
    assert planvalues.accuracy_target_arcsec(p) == 3.5
    p.write_text(text.replace("  A-C1:\n    paper: A", "  A-C0:\n    paper: A", 1))
    with pytest.raises(ValueError, match=r"claims\.A-C1\.margins\.target_arcsec"):
        planvalues.accuracy_target_arcsec(p)
