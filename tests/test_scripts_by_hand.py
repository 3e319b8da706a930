"""Every workflow script runs by hand as the real job (opnav.core.snakeio.mock_snakemake builds
the rule's inputs, outputs, params and log from the Snakefile and the overlays given)."""

import subprocess
import sys

import pandas as pd
import pytest
import yaml

from conftest import REPO, copy_workflow

SCRIPTS = sorted((REPO / "workflow" / "scripts").glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_every_script_has_the_one_by_hand_entry(script):
    text = script.read_text()
    assert 'if "snakemake" not in globals():' in text
    assert "mock_snakemake(" in text and "argv=sys.argv[1:]" in text
    assert "snakemake.config" not in text  # params only: a rule gets the keys it uses


@pytest.mark.slow  # parses the workflow thrice: ~2.2 CPU-s (issue 56: the default run <= 90 s)
def test_a_script_run_by_hand_gets_the_rule_params_of_its_overlays(tmp_path):
    """landing_tables.py by hand with the quick profile plus an overlay that moves the
    initial position: B-T1 lands where the rule writes it (results/quick/...) and shows
    the overlay's value, so params come from the parsed workflow, not from the script."""
    wd = copy_workflow(tmp_path)
    overlay = wd / "moved.yaml"
    overlay.write_text(yaml.safe_dump({"landing": {"initial_state": {"r_m": [3333.0, 5870.0, 6570.0]}}}))
    proc = subprocess.run(
        [sys.executable, "workflow/scripts/landing_tables.py", "--configfile", "config/quick.yaml",
         str(overlay)], cwd=wd, capture_output=True, text=True,
        env={"PYTHONPATH": str(wd / "src"), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path / "home")})
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    t1 = pd.read_csv(wd / "results" / "quick" / "landing" / "B-T1_initial_state.csv")
    assert t1.astype(str).apply(lambda c: c.str.contains("3333")).to_numpy().any(), t1
    assert (wd / "results" / "quick" / "landing" / "logs" / "landing_tables.log").is_file()


@pytest.mark.slow  # parses the workflow: ~1.1 CPU-s (issue 56: the default run <= 90 s)
def test_a_missing_wildcard_is_named(tmp_path):
    from opnav.core.snakeio import mock_snakemake

    with pytest.raises(SystemExit, match="needs the wildcard.*variant"):
        mock_snakemake("approach_mc", root=REPO)


def test_the_landing_chunk_job_gets_the_configured_batch_size(tmp_path):
    """landing.mc.batch_size reaches the Monte-Carlo job (it was read from the
    simulation config, which does not carry it, so any value flew the whole chunk
    as one batch); it is a param of its own, outside the runs' reuse key."""
    from opnav.core.snakeio import mock_snakemake

    overlay = tmp_path / "batch.yaml"
    overlay.write_text(yaml.safe_dump({"landing": {"mc": {"batch_size": 3}}}))
    sm = mock_snakemake("landing_mc_chunk", root=REPO, argv=["--configfile", str(overlay)],
                        bscn="site-tilt", bmethod="depth", bchunk="r0000-0001")
    assert sm.params.batch_size == 3
    assert "batch_size" not in sm.params.landing.get("mc", {})
