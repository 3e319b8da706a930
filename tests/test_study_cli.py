"""Running one study by name: `opnav study NAME --config FILE` runs Snakemake with
`--configfile FILE ... -- study_NAME` (without `--` the target is read as one more
config file), so only that study's jobs run; an unknown study or a bad value is
refused before any job."""

import json
import os
import re
import subprocess
import sys

import pytest
import yaml

from opnav.cli import study_command
from test_incremental import _readme_study_block


def _overlay(wd):
    block = _readme_study_block()
    (name, spec), = block["studies"].items()
    spec.update(runs=2, runs_per_job=2)
    (wd / "my-study.yaml").write_text(yaml.safe_dump(block))
    return name, spec


def _opnav(wd, *args):
    env = dict(os.environ, PYTHONPATH=str(wd / "src"))
    return subprocess.run([sys.executable, "-m", "opnav", *args], cwd=wd, capture_output=True, text=True, env=env)


@pytest.mark.slow
def test_opnav_study_runs_only_that_study(workdir):
    name, spec = _overlay(workdir)
    cmd = study_command(name, ["a.yaml", "b.yaml"])
    assert cmd[-5:] == ["--configfile", "a.yaml", "b.yaml", "--", f"study_{name}"]
    proc = _opnav(workdir, "study", name, "--config", "config/quick.yaml", "--config", "my-study.yaml", "-n")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    # Snakemake's output goes to stderr; stdout holds the JSON summary alone
    listed = {line.split()[-1].rstrip(":") for line in proc.stderr.splitlines()
              if line.startswith(("rule ", "localrule "))}
    listed |= set(re.findall(r"^Job \d+: rule (\w+)", proc.stderr, re.M))   # a rule printed by its message
    # and, in a fresh checkout, the compiling of its paper's kernels (the runs wait for it)
    assert listed == {"compile_kernels", "study_runs", f"study_{name}_outputs", f"study_{name}"}, listed
    assert proc.stderr.count("rule compile_kernels (") == 1 and f"kpaper={spec['paper']}" in proc.stderr
    n_values = len(next(iter(spec["vary"].values())))
    assert proc.stderr.count("rule study_runs:") == n_values       # one job per value, every method
    out = json.loads(proc.stdout)
    assert out["study"] == name and out["outputs"].endswith(f"results/quick/studies/{name}")
    bad = _opnav(workdir, "study", "nope", "--config", "config/quick.yaml")
    assert bad.returncode == 2 and "no study 'nope'" in bad.stderr and "fov" in bad.stderr
    val = _opnav(workdir, "study", name, "--config", "config/quick.yaml", "--config", "my-study.yaml",
                 "--set", f"studies.{name}.runs=0", "-n")
    assert val.returncode == 2 and f"studies.{name}.runs" in val.stderr


def test_opnav_study_forwards_snakemake_config_errors_as_user_errors():
    """A failed Snakemake run's config lines reach stderr as `opnav: error:` lines with
    exit 2; a failed job is a numerical failure (3)."""
    from opnav.cli import EXIT_NUMERICAL, EXIT_USER, snakemake_error

    out = ["Using workflow specific profile profiles/default", "ConfigError (no job was run):",
           "invalid config key 'studies.s.vary' (study 's'): values coincide"]
    assert snakemake_error(out) == (["invalid config key 'studies.s.vary' (study 's'): values coincide"], EXIT_USER)
    out = ["Error in rule study_runs:", "    jobid: 3", "Exiting because a job execution failed."]
    assert snakemake_error(out) == (["Error in rule study_runs"], EXIT_NUMERICAL)
