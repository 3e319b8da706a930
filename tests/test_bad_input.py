"""Bad input is refused before any job runs, with one line naming the key.

Each case is an overlay on config/config.yaml + config/quick.yaml, checked with
:func:`opnav.core.config.validate_config`, which is what the Snakefile runs before it
builds the DAG (one `snakemake -n` case below proves that path) and what the
CLI runs before it computes anything.
"""

import copy

import pytest
import yaml

from conftest import REPO, run_snakemake
from opnav.core.config import ConfigError, _merge, validate_config


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
    # round two (issue 33): where outputs go
    ("results_dir: docs/out", "tracked folder docs/"),
    ("results_dir: .ci", "tracked folder .ci/"),
    ("results_dir: .snakemake/x", "tracked folder .snakemake/"),
    ("results_dir: README.md", "'results_dir': 'README.md' is an existing file"),
    ("results_dir: '" + "a" * 5000 + "'", "'results_dir': 5000 characters"),
    ('results_dir: "res\\0ults"', "'results_dir': contains a NUL byte"),
    ("results_dir: '~nosuchuser33/out'", "'results_dir': '~nosuchuser33/out': '~' names no home"),
    ("results_dir: ..", "'results_dir': '..' holds the checkout"),
    ("results_dir: 7", "'results_dir': 7 is not of type 'string'"),
    # camera scenarios get the landing physics checks of landing.camera
    ("landing: {scenarios: {interior: {fov_deg: 10, tilt_deg: 0}}}", "'landing.scenarios.interior': the landing site"),
    ("landing: {scenarios: {interior: {tilt_azimuth_deg: 73}}}", "'landing.scenarios.interior': the landing site"),
    ("landing: {scenarios: {interior: {pixels: 16}}, planner: {margin_px: 40}}",
     "'landing.scenarios.interior': landing.planner.margin_px = 40 px"),
    ("landing: {scenarios: {wide: {fov_deg: 170, tilt_deg: 0, pixels: 8}}, planner: {margin_px: 4}}",
     "'landing.scenarios.wide.pixels'"),
    ("landing: {scenarios: {interior: {sigma_px: 1.0e-300}}}", "landing.scenarios.interior.sigma_px"),
    ("landing: {scenarios: {interior: {zoom: 2}}}", "landing.scenarios.interior"),
    ("landing: {scenarios: {Wide_1: {}}}", "landing.scenarios"),
    ("landing: {headline_scenario: nadir}", "'landing.headline_scenario': 'nadir' is not one of"),
    ("approach: {growing: {N: 7}}", "'approach.growing.N': 7 does not divide"),
    ("approach: {camera: {sigma3_px: [1.0e-300, 1.0e-300, 2.0e-300]}}", "approach.camera.sigma3_px[0]"),
    # the studies planner: one line per problem, naming studies.<name> and the key
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: 45.0}}}", "'studies.s.vary.landing.camera.fov_deg'"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, colour: red}}", "'studies.s'"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0, 60.0], landing.imu.rate_hz: [10.0]}}}",
     "'studies.s.vary' (study 's'): the vary lists have different lengths"),
    ("studies: {s: {paper: landing, vary: {approach.camera.ifov_arcsec: [10.0]}}}",
     "'studies.s.vary.approach.camera.ifov_arcsec' (study 's')"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, fixed: {landing.camera.fov_deg: 50.0}}}",
     "'studies.s.fixed' (study 's'): key(s) ['landing.camera.fov_deg'] are both swept"),
    ("studies: {s: {paper: landing, vary: {landing.mc.n_runs: [5, 6]}}}",
     "'studies.s.vary.landing.mc.n_runs' (study 's'): key 'landing.mc.n_runs' is not read"),
    ("studies: {s: {paper: landing, vary: {landing.camera.pixels: [512.0]}}}",
     "'studies.s.vary' (study 's'): value landing.camera.pixels = 512.0 refused"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, methods: [depth, oracle]}}",
     "'studies.s.methods' (study 's'): unknown method(s) ['oracle']"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, metrics: [happiness]}}",
     "'studies.s.metrics' (study 's'): unknown metric(s) ['happiness']"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}", "'studies.s.vary' (study 's'): values"),
    ("studies: {s: {paper: landing, vary: {landing.camera.tilt_azimuth_deg: [73.0]}}}",
     "'studies.s.vary' (study 's'): value landing.camera.tilt_azimuth_deg = 73.0 refused: invalid config key "
     "'landing.camera': the landing site"),
    ("studies: {s: {paper: approach, vary: {approach.camera.ifov_arcsec: [10.0, 0.1]}}}",
     "'studies.s.vary' (study 's'): value approach.camera.ifov_arcsec = 0.1 refused: invalid config key 'approach.camera'"),
    ("studies: {s: {paper: landing, variants: [roll], vary: {landing.camera.fov_deg: [45.0]}}}", "'studies.s.variants'"),
    # bounds on the job graph, before it is built
    ("studies: {s: {paper: landing, grid: true, vary: {landing.camera.fov_deg: [" + ", ".join(
        f"{40 + 0.1 * i:.1f}" for i in range(100)) + "], landing.filter.obs_per_landmark: ["
     + ", ".join(str(i) for i in range(1, 101)) + "]}}}",
     "'studies.s.vary' (study 's'): 100 x 100 = 10000 value sets exceed limits.max_study_values"),
    ("landing: {mc: {n_runs: 25000, runs_per_job: 1}}", "'limits.max_jobs': the config makes about"),
    ("limits: {max_jobs: 10}", "'limits.max_jobs'"),
    ("limits: {max_jobs: 0}", "limits.max_jobs"),
]


def _overlaid(overlay: str) -> dict:
    cfg = copy.deepcopy(_BASE)
    _merge(cfg, yaml.safe_load(overlay))
    return cfg


@pytest.mark.parametrize("overlay,key", BAD_CONFIGS, ids=[c[0] for c in BAD_CONFIGS])
def test_bad_config_refused_naming_key(overlay, key):
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO, workflow=True)
    text = str(err.value)
    assert key in text, text
    assert all(line.startswith("invalid config key") or line.startswith("invalid config (top")
               for line in text.splitlines()), text


def test_quick_and_full_profiles_pass():
    validate_config(_overlaid("{}"), root=REPO, workflow=True)
    # a slow, nearly parabolic approach that does not reach Mars is legal
    validate_config(_overlaid("approach: {geometry: {v_inf_kms: 1.0e-9}}"), root=REPO, workflow=True)
    validate_config(yaml.safe_load((REPO / "config" / "config.yaml").read_text()), root=REPO, workflow=True)


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


def test_all_problems_in_one_pass():
    """Schema and physics problems of different sections, and of studies, in one error."""
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(
            "approach: {dt_s: .nan}\nlanding: {headline_scenario: nadir, duration_s: 197.5}\n"
            "results_dir: docs/out\nstudies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}"),
            root=REPO, workflow=True)
    text = str(err.value)
    for key in ("approach.dt_s", "landing.headline_scenario", "landing.duration_s", "results_dir"):
        assert f"'{key}'" in text, text
    with pytest.raises(ConfigError) as err:          # the studies once the papers' sections are sound
        validate_config(_overlaid("results_dir: docs/out\nstudies: {s: {paper: landing, vary: "
                                  "{landing.camera.fov_deg: [45, 45.0]}}, t: {paper: landing, vary: "
                                  "{landing.mc.n_runs: [3]}}}"), root=REPO, workflow=True)
    text = str(err.value)
    assert all(k in text for k in ("'results_dir'", "'studies.s.vary'", "'studies.t.vary.landing.mc.n_runs'")), text


def test_results_dir_tilde_is_expanded():
    import os

    cfg = validate_config(_overlaid("results_dir: ~/opnav-out"), root=REPO)
    assert cfg["results_dir"] == os.path.expanduser("~/opnav-out") and "~" not in cfg["results_dir"]


def test_tracked_folders_come_from_git(tmp_path):
    """A folder that holds tracked files is refused whatever its name; a folder of
    placeholders only (results/README.md) or of untracked files is not."""
    import subprocess

    from opnav.core.checks import results_dir_problems, tracked_dirs

    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    for f in ("notes/a.txt", "results/README.md", "scratch/x.txt"):
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f).write_text("x")
    subprocess.run(["git", "-C", str(tmp_path), "add", "notes/a.txt", "results/README.md"], check=True)
    assert {d.as_posix() for d in tracked_dirs(tmp_path)} == {".git", ".snakemake", "notes"}
    assert results_dir_problems("notes/out", tmp_path) and not results_dir_problems("results", tmp_path)
    assert not results_dir_problems("scratch/out", tmp_path)


def test_yaml_anchors_and_merge_keys_still_work(tmp_path):
    from opnav.core.config import read_config_file

    f = tmp_path / "ok.yaml"
    f.write_text("x: &c {fov_deg: 45.0}\nlanding: {camera: {<<: *c, tilt_deg: 40.0}}\n")
    assert read_config_file(f)["landing"]["camera"] == {"fov_deg": 45.0, "tilt_deg": 40.0}


def _bomb(levels=9):
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]")
    return "\n".join(lines) + "\n"


# (file content (str or bytes, None: absent), text the one-line error must contain)
BAD_FILES = [
    ("landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n",
     "{f}, line 3, column 1: not valid YAML: duplicate key 'landing' (first given on line 1)"),
    ("landing:\n  mc: {n_runs: 8, n_runs: 9}\n", "{f}, line 2"),
    ("landing:\n\tmc: {n_runs: 8}\n", "{f}, line 2, column 1: not valid YAML"),
    ("- landing\n- approach\n", "{f}, line 1: the top level must be a mapping of config keys (approach, landing, ...), not a list"),
    ("", "{f}: empty (no config keys)"),
    ("# nothing but a comment\n", "{f}: empty (no config keys)"),
    ("42\n", "{f}, line 1: the top level must be a mapping"),
    ("landing: !!python/object/apply:os.system ['true']\n", "{f}, line 1, column 10: not valid YAML"),
    ("landing: !custom {a: 1}\n", "{f}, line 1"),
    (b"\x7fELF\x02\x01\x01\x00\x00\x00\xff\xfe", "{f}, line 1: not UTF-8 text"),
    (b"landing: {}\x00\n", "{f}, line 1: a NUL byte"),
    (None, "{f}: not found"),
    (_bomb(), "{f}: its aliases expand to more than 100000 nodes"),
    ("a: &a [*a]\n", "{f}, line 1: a recursive alias"),
    ("a: 1\n---\nb: 2\n", "{f}, line 2, column 1: not valid YAML"),
    ("landing: {mc: {n_runs: [1, 2}\n", "{f}, line 1"),
    ("1: {a: 2}\n", "{f}: top-level key 1 is not a name"),
]


@pytest.mark.parametrize("content,expected", BAD_FILES, ids=[str(c)[:40] for c, _ in BAD_FILES])
def test_bad_config_file_refused_naming_file_and_line(content, expected, tmp_path, capsys, no_work):
    """Through the CLI (`opnav --config FILE`): one line naming the file (and the line)."""
    from opnav.cli import EXIT_USER, main

    f = tmp_path / "over.yaml"
    if isinstance(content, bytes):
        f.write_bytes(content)
    elif content is not None:
        f.write_text(content)
    assert main(["landing", "--config", str(f)]) == EXIT_USER
    cap = capsys.readouterr()
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and expected.format(f=f) in lines[0], cap.err
    assert cap.out == ""


def test_a_directory_is_not_a_config_file(tmp_path):
    from opnav.core.config import read_config_file

    with pytest.raises(ConfigError, match="not a regular file"):
        read_config_file(tmp_path)


def test_snakefile_reports_every_problem_in_one_line_each(tmp_path):
    """Problems found by the studies planner, the scenario checks, the growing windows,
    the headline scenario and the job bound all leave through the Snakefile's one wrapper:
    a line each, no Snakemake frames; a duplicated key in a --configfile names file and line."""
    from conftest import copy_workflow

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    (wd / "bad.yaml").write_text(
        "approach: {growing: {N: 7}}\n"
        "landing: {headline_scenario: nadir, scenarios: {interior: {fov_deg: 10, tilt_deg: 0}, site-tilt: {}}}\n"
        "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "bad.yaml")
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0
    assert "'approach.growing.N'" in out and "'landing.headline_scenario'" in out, out
    assert "Traceback" not in out and ".smk\", line" not in out, out
    (wd / "good-scenario.yaml").write_text(
        "landing: {scenarios: {interior: {fov_deg: 10, tilt_deg: 0}, site-tilt: {}}}\n"
        "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "good-scenario.yaml")
    out = proc.stdout + proc.stderr
    problems = [ln for ln in out.splitlines() if ln.startswith("invalid config key")]
    assert [ln.split("'")[1] for ln in problems] == ["landing.scenarios.interior", "studies.s.vary"], out
    (wd / "dup.yaml").write_text("landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "dup.yaml")
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "dup.yaml, line 3, column 1: not valid YAML: duplicate key 'landing'" in out, out
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
    # round two (issue 33)
    (["approach", "--pixel-sigma", "1e-300"], "--pixel-sigma: invalid config key 'approach.camera.sigma3_px[0]'"),
    (["approach", "--set", "approach.variants=[literal]"],
     "--set approach.variants: invalid config key 'approach.table1_variants'"),
    (["approach", "--set", "approach.nosuch=1"], "--set approach.nosuch: no config key"),
    (["approach", "--set", "approach.dt_s"], "expected KEY.PATH=VALUE"),
    (["approach", "--set", "approach.dt_s=[1"], "--set approach.dt_s: the value '[1' is not valid YAML"),
    (["landing", "--set", "landing.camera={fov_deg: 45, fov_deg: 50}"], "duplicate key 'fov_deg'"),
    (["landing", "--set", "landing.headline_scenario=nadir"], "--set landing.headline_scenario"),
    (["landing", "--set", "landing.scenarios.interior.fov_deg=10"], "landing.scenarios.interior"),
    (["landing", "--set", "results_dir=docs/out"], "--set results_dir: invalid config key 'results_dir'"),
    (["study", "fov", "--set", "landing.mc.runs_per_job=1", "--set", "landing.mc.n_runs=25000"], "limits.max_jobs"),
    (["study", "fov", "--set", "approach.growing.N=7"], "--set approach.growing.N: invalid config key"),
    (["landing", "--config", "{tmp}/dup.yaml"], "dup.yaml, line 3"),
    (["study", "nope", "--config", "{tmp}/nan.yaml"], "approach.dt_s"),
    (["study", "s", "--config", "{tmp}/study.yaml"], "'studies.s.vary' (study 's'): values"),
    (["study", "s", "--config", "{tmp}/study.yaml", "--cores", "0"], "--cores"),
    (["study", "s", "--config", "{tmp}/study.yaml", "--cores", "x"], "--cores"),
    (["study"], "NAME"),
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
    _write(tmp_path, "dup.yaml", "landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n")
    _write(tmp_path, "study.yaml", "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
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

    from opnav.core.tables import json_ready

    obj = {"a": float("nan"), "b": [float("inf"), 1.5], "c": np.float64("nan"), "d": np.array([1.0, np.nan]),
           "e": "nan", "f": 3}
    text = json.dumps(json_ready(obj), allow_nan=False)

    def refuse(c):
        raise ValueError(c)

    back = json.loads(text, parse_constant=refuse)
    assert back == {"a": None, "b": [None, 1.5], "c": None, "d": [1.0, None], "e": "nan", "f": 3}
