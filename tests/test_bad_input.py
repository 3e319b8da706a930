"""Bad input is refused before any job runs, with one line naming the key.

Each case is an overlay on config/config.yaml + config/quick.yaml, checked with
:func:`opnav.config.validate_config`, which is what the Snakefile runs before it
builds the DAG (one `snakemake -n` case below proves that path) and what the
CLI runs before it computes anything.
"""

import copy

import pytest
import yaml

from conftest import REPO, run_snakemake
from opnav.config import ConfigError, _merge, validate_config


def _raw_quick() -> dict:
    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    _merge(cfg, yaml.safe_load((REPO / "config" / "quick.yaml").read_text()))
    return cfg


_BASE = _raw_quick()

# (overlay YAML, text the error must contain: the key)
BAD_CONFIGS = [
    # non-finite numbers, anywhere
    ("approach: {dt_s: .nan}", "approach.dt_s"),
    ("approach: {dt_s: .inf}", "approach.dt_s"),
    ("approach: {geometry: {range_km: .inf}}", "approach.geometry.range_km"),
    ("approach: {em: {tz_tol: .nan}}", "approach.em.tz_tol"),
    ("approach: {process_noise_diag: [1.0e-4, 1.0e-4, -.inf, 0, 0, 0]}", "approach.process_noise_diag[2]"),
    ("approach: {roll: {rate_deg_s: .nan}}", "approach.roll.rate_deg_s"),
    ("landing: {imu: {sigma_a_mps2: .inf}}", "landing.imu.sigma_a_mps2"),
    ("landing: {gravity_mps2: [0, 0, .nan]}", "landing.gravity_mps2[2]"),
    ("landing: {mc: {runs_per_job: .nan}}", "landing.mc.runs_per_job"),
    ("landing: {planner: {tol_rad: .nan}}", "landing.planner.tol_rad"),
    # integer keys refuse 3.0
    ("approach: {n_seeds: 3.0}", "approach.n_seeds"),
    ("approach: {segments: {N: 50.0}}", "approach.segments.N"),
    ("approach: {alternatives: {batch_ml: {checkpoint_stride: 2.0}}}",
     "approach.alternatives.batch_ml.checkpoint_stride"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, runs: 2.0}}", "studies.s.runs"),
    ("landing: {mc: {n_runs: 3.0}}", "landing.mc.n_runs"),
    ("landing: {mc: {runs_per_job: 3.0}}", "landing.mc.runs_per_job"),
    ("landing: {camera: {pixels: 1024.0}}", "landing.camera.pixels"),
    ("landing: {landmarks: {count: 5.5}}", "landing.landmarks.count"),
    # ranges, types, unknown keys
    ("approach: {segments: {L: 100000}}", "approach.segments.L"),
    ("approach: {mars_elements: {e: 1.0}}", "approach.mars_elements.e"),
    ("approach: {camera: {sigma3_px: [0.1, -0.1, 0.2]}}", "approach.camera.sigma3_px[1]"),
    ("approach: {camera: {sigma3_px: [0, 0.1, 0.2]}}", "approach.camera.sigma3_px[0]"),
    ("approach: {truth_bias_arcsec: [1.0e+9, 0, 0]}", "approach.truth_bias_arcsec[0]"),
    ("approach: {convergence_study: {data_samples: 1000000}}", "approach.convergence_study.data_samples"),
    ("approach: {foo: 1}", "'foo'"),
    ("landing: {camera: {sigma_px: 0}}", "landing.camera.sigma_px"),
    ("landing: {mc: {bounds: {att_deg: 500}}}", "landing.mc.bounds.att_deg"),
    ("profile: fast", "profile"),
    ("paper: {build_pdf: 'yes'}", "paper.build_pdf"),
    # duplicates and lists
    ("approach: {variants: [literal, literal]}", "approach.variants"),
    ("approach: {methods: [plain, plain]}", "approach.methods"),
    ("approach: {variants: [literal, roll], table1_variants: [prior]}", "approach.table1_variants"),
    ("landing: {extra: {methods: [logdet, logdet]}}", "landing.extra.methods"),
    # physics of paper A
    ("approach: {geometry: {range_km: 3000}}", "approach.geometry.range_km"),
    ("approach: {geometry: {v_inf_dir: [0, 0, 0]}}", "approach.geometry.v_inf_dir"),
    ("approach: {geometry: {v_inf_dir: [0, 0, -2]}}", "approach.geometry.v_inf_dir"),
    ("approach: {dt_s: 60, geometry: {range_km: 20000, aim_offset_km: 0}}", "approach.geometry"),
    ("approach: {camera: {ifov_arcsec: 0.1}}", "approach.camera"),
    ("approach: {geometry: {range_km: 20000}}", "approach.camera"),
    ("approach: {truth_bias_arcsec: [6000, 0, 0]}", "approach.truth_bias_arcsec"),
    ("approach: {segments: {N: 100000, L: 10000}}", "approach.segments"),
    ("approach: {n_seeds: 1000, segments: {N0: 10000}}", "approach.n_seeds"),
    ("approach: {roll: {steps_deg: [0, 90], step_interval_s: 100.3}}", "approach.roll.step_interval_s"),
    ("approach: {prior_sigma: {r_km: 1.0e-300}}", "approach.prior_sigma.r_km"),
    ("approach: {initial_error: {r_km: [1.0e+9, 0, 0]}}", "approach.initial_error.r_km[0]"),
    # physics of paper B
    ("landing: {duration_s: 197.5}", "landing.duration_s"),
    ("landing: {filter: {dt_s: 0.7}}", "landing.duration_s"),
    ("landing: {imu: {rate_hz: 2.5}}", "landing.imu.rate_hz"),
    ("landing: {initial_state: {r_m: [3300, 5870, -10]}}", "landing.initial_state.r_m"),
    ("landing: {initial_state: {r_m: [3300, 5870, 2]}}", "landing.initial_state.r_m"),
    ("landing: {initial_state: {v_mps: [0, 0, -200]}}", "landing.initial_state"),
    ("landing: {camera: {tilt_deg: 0}}", "landing.camera"),
    ("landing: {camera: {tilt_azimuth_deg: 73}}", "landing.camera"),
    ("studies: {s: {paper: landing, vary: {camera.fov_deg: [45.0]}}}", "studies.s.vary"),
    ("landing: {figures: {f5_time_s: 500}}", "landing.figures.f5_time_s"),
    ("landing: {figures: {f5_time_s: 1.5}}", "landing.figures.f5_time_s"),
    ("landing: {mc: {n_runs: 100000}}", "landing.mc.n_runs"),
    ("landing: {mc: {bounds: {r_m: 100000}}}", "landing.mc.bounds.r_m"),
    ("landing: {planner: {margin_px: 10000}}", "landing.planner.margin_px"),
    # method names: the planner's registry
    ("landing: {mc: {methods: [depth, nosuch]}}", "landing.mc.methods"),
    ("landing: {extra: {reference: gdopp}}", "landing.extra.reference"),
    ("landing: {single: {method: foo}}", "landing.single.method"),
    ("studies: {s: {paper: moon, vary: {landing.camera.fov_deg: [45.0]}}}", "studies.s.paper"),
    ("landing: {extra: {methods: [], reference: logdet}}", "landing.extra.reference"),
    ("landing: {extra: {n_boot: 1}}", "landing.extra.n_boot"),
    ("approach: {mars_elements: {a_au: 1.0e-9}}", "approach.mars_elements.a_au"),
    ("landing: {gravity_mps2: [0, 0, 0]}", "landing.initial_state"),
    ("landing: {filter: {min_update_altitude_m: 100000}}", "landing.initial_state.r_m"),
    ("approach: {base_seed: true}", "approach.base_seed"),
    # where outputs go
    ("results_dir: ''", "results_dir"),
    ("results_dir: '.'", "results_dir"),
    ("results_dir: paper", "results_dir"),
    ("results_dir: paper/out", "results_dir"),
    ("results_dir: results/../config", "results_dir"),
]


def _overlaid(overlay: str) -> dict:
    cfg = copy.deepcopy(_BASE)
    _merge(cfg, yaml.safe_load(overlay))
    return cfg


@pytest.mark.parametrize("overlay,key", BAD_CONFIGS, ids=[c[0] for c in BAD_CONFIGS])
def test_bad_config_refused_naming_key(overlay, key):
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO)
    text = str(err.value)
    assert key in text, text
    assert all(line.startswith("invalid config key") or line.startswith("invalid config (top")
               for line in text.splitlines()), text


def test_quick_and_full_profiles_pass():
    validate_config(_overlaid("{}"), root=REPO)
    # a slow, nearly parabolic approach that does not reach Mars is legal
    validate_config(_overlaid("approach: {geometry: {v_inf_kms: 1.0e-9}}"), root=REPO)
    validate_config(yaml.safe_load((REPO / "config" / "config.yaml").read_text()), root=REPO)


def test_every_problem_gets_its_own_line():
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid("landing: {duration_s: 197.5, imu: {rate_hz: 2.5}}"), root=REPO)
    lines = str(err.value).splitlines()
    assert any("landing.duration_s" in ln for ln in lines)
    assert any("landing.imu.rate_hz" in ln for ln in lines)


def test_method_names_follow_the_planner_registry(monkeypatch):
    """A method the planner registers is accepted; the check has no copy of the list."""
    from opnav.landing import planner

    validate_config(_overlaid("landing: {single: {method: svd}}"), root=REPO)
    monkeypatch.setattr(planner, "available_methods", lambda: ("depth", "cond", "gdop", "logdet",
                                                               "mineig", "random", "center"))
    with pytest.raises(ConfigError, match="landing.mc.methods"):
        validate_config(_overlaid("{}"), root=REPO)


def test_schema_limits_are_numbers():
    """A YAML slip such as `maximum: 1.0e9` (read as a string) would crash validation."""
    def walk(node):
        if isinstance(node, dict):
            for k, v in node.items():
                if k in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
                    assert isinstance(v, (int, float)) and not isinstance(v, bool), (k, v)
                walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)

    for f in (REPO / "src" / "opnav" / "schemas").glob("*.yaml"):
        walk(yaml.safe_load(f.read_text()))


def test_snakefile_refuses_before_any_job(tmp_path):
    """The workflow's own validation: no job runs, the key is named, nothing is written."""
    from conftest import copy_workflow

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    (wd / "bad.yaml").write_text("approach: {dt_s: .nan}\nlanding: {mc: {runs_per_job: 3.0}}\n")
    proc = run_snakemake(wd, "--cores", "1", "--configfile", "config/quick.yaml", "bad.yaml")
    assert proc.returncode != 0
    out = proc.stdout + proc.stderr
    assert "approach.dt_s" in out and "landing.mc.runs_per_job" in out, out
    assert "Traceback" not in out
    assert not (wd / "results").exists()


# ------------------------------------------------------------------ the CLI

def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


# (argv, text stderr must contain: the flag or the file/key); {tmp} is tmp_path
BAD_CLI = [
    (["approach", "--bias", "nan", "0", "0"], "--bias"),
    (["approach", "--bias", "0", "inf", "0"], "--bias"),
    (["approach", "--bias", "1e9", "0", "0"], "--bias"),
    (["approach", "--bias", "6000", "0", "0"], "--bias"),
    (["approach", "--bias", "1", "2"], "--bias"),
    (["approach", "--init", "-inf", "0", "0"], "--init"),
    (["approach", "--init", "0", "50000", "0"], "--init"),
    (["approach", "--pixel-sigma", "nan"], "--pixel-sigma"),
    (["approach", "--pixel-sigma", "0"], "--pixel-sigma"),
    (["approach", "--pixel-sigma", "1e6"], "--pixel-sigma"),
    (["approach", "--N", "3.0"], "--N"),
    (["approach", "--N", "1"], "--N"),
    (["approach", "--N0", "0"], "--N0"),
    (["approach", "--M", "5000"], "--M"),
    (["approach", "--L", "-3"], "--L"),
    (["approach", "--N", "100000", "--L", "10000"], "--N"),
    (["approach", "--seeds", "0"], "--seeds"),
    (["approach", "--seeds", "1001"], "--seeds"),
    (["approach", "--seeds", "2.5"], "--seeds"),
    (["approach", "--seed", "-1"], "--seed"),
    (["approach", "--variant", "nope"], "--variant"),
    (["approach", "--method", "fast"], "--method"),
    (["approach", "--mode", "zigzag"], "--mode"),
    (["landing", "--method", "foo"], "--method"),
    (["landing", "--method", ""], "--method"),
    (["landing", "--seed", "-1"], "--seed"),
    (["landing", "--seed", "1.5"], "--seed"),
    (["landing", "--seed", "abc"], "--seed"),
    (["landing", "--nosuch"], "--nosuch"),
    (["--config", "{tmp}/missing.yaml", "approach"], "missing.yaml"),
    (["--config", "{tmp}/broken.yaml", "landing"], "broken.yaml"),
    (["--config", "{tmp}/nan.yaml", "approach"], "approach.dt_s"),
    (["--config", "{tmp}/tilt.yaml", "landing"], "landing.camera"),
]


@pytest.fixture()
def no_work(monkeypatch):
    """Any simulation started fails the test: refusal must come first."""
    import opnav.approach.cases as cases
    import opnav.approach.scenario as scenario
    import opnav.landing.descent as descent

    def forbidden(*a, **k):
        raise AssertionError("work started before the input was refused")

    for mod, name in ((cases, "run_case"), (scenario, "build_geometry"),
                      (descent, "build_scenario"), (descent, "run_descent")):
        monkeypatch.setattr(mod, name, forbidden)


@pytest.mark.parametrize("argv,named", BAD_CLI, ids=[" ".join(a) for a, _ in BAD_CLI])
def test_bad_cli_refused_naming_flag(argv, named, tmp_path, capsys, no_work):
    from opnav.cli import EXIT_USER, main

    _write(tmp_path, "broken.yaml", "approach: {dt_s: [1, 2\n")
    _write(tmp_path, "nan.yaml", "approach: {dt_s: .nan}\n")
    _write(tmp_path, "tilt.yaml", "landing: {camera: {tilt_deg: 0}}\n")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    try:
        rc = main(argv)
    except SystemExit as exc:          # argparse's own refusals
        rc = exc.code
    cap = capsys.readouterr()
    assert rc == EXIT_USER, (rc, cap.err)
    assert named in cap.err, cap.err
    assert cap.out == ""
    assert "Traceback" not in cap.err
    assert all(line.startswith("opnav") for line in cap.err.strip().splitlines()), cap.err


def test_numerical_failure_is_one_line(monkeypatch, capsys):
    import numpy as np

    import opnav.landing.descent as descent
    from opnav.cli import EXIT_NUMERICAL, main

    def singular(*a, **k):
        raise np.linalg.LinAlgError("Matrix is not positive definite")

    monkeypatch.setattr(descent, "run_descent", singular)
    assert main(["landing"]) == EXIT_NUMERICAL
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not positive definite" in err[0]


def test_json_output_is_strict():
    """NaN and infinities (also numpy's) are written as null: valid JSON."""
    import json

    import numpy as np

    from opnav.tables import json_ready

    obj = {"a": float("nan"), "b": [float("inf"), 1.5], "c": np.float64("nan"), "d": np.array([1.0, np.nan]),
           "e": "nan", "f": 3}
    text = json.dumps(json_ready(obj), allow_nan=False)

    def refuse(c):
        raise ValueError(c)

    back = json.loads(text, parse_constant=refuse)
    assert back == {"a": None, "b": [None, 1.5], "c": None, "d": [1.0, None], "e": "nan", "f": 3}
