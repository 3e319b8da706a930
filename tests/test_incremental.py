"""What a config edit reruns, read from the dry-run job list of a completed quick run.

Rules get only the config keys they use (editing one ablation value lists that
ablation's jobs and the manuscript that shows it, no Monte Carlo), and Monte-Carlo
chunks are kept and named by their run indices (raising n_runs lists only the
chunks of the new runs).
"""

from pathlib import Path

import pytest
import yaml

from conftest import dry_run_jobs

# rules that only gather finished outputs into the manuscript; any new output reruns them
AGGREGATORS = {"paper_floats", "paper_macros", "paper_pdf", "paper_scorecard", "all"}


def _edit(workdir: Path, overlay: dict) -> list[tuple[str, dict]]:
    path = workdir / "edit.yaml"
    path.write_text(yaml.safe_dump(overlay))
    return dry_run_jobs(workdir, "--configfile", "config/quick.yaml", str(path))


pytestmark = pytest.mark.slow


def test_unchanged_config_lists_nothing(quick_results):
    assert _edit(quick_results, {}) == []


@pytest.mark.parametrize("overlay, only", [
    ({"approach": {"ablation": {"sigma3_px": [0.1, 0.7]}}}, {"approach_ablation_pixel"}),
    ({"approach": {"ablation": {"segment_N": [25, 40]}}}, {"approach_ablation_segment"}),
    ({"approach": {"accuracy_target_arcsec": 3.0}}, {"approach_tables", "approach_x1_figure"}),
])
def test_editing_one_key_reruns_only_its_users(quick_results, overlay, only):
    rules = {r for r, _ in _edit(quick_results, overlay)}
    assert only <= rules, rules
    assert rules - only <= AGGREGATORS, f"also listed: {sorted(rules - only - AGGREGATORS)}"


def test_landing_ablation_value_edit_lists_only_that_value(quick_results):
    jobs = _edit(quick_results, {"landing": {"ablation": {"fov_deg": [45.0, 70.0]}}})
    sims = [(r, w) for r, w in jobs if r not in AGGREGATORS]
    chunks = [w for r, w in sims if r == "landing_ablation_chunk"]
    assert chunks and all(w["bsweep"] == "fov" and w["bvalue"] == "70" for w in chunks), chunks
    assert {r for r, _ in sims} == {"landing_ablation_chunk", "landing_ablation_fov"}


def test_raising_n_runs_flies_only_the_new_runs(quick_results):
    """Quick profile: 4 runs in chunks of 2; 6 runs adds chunk r0004-0005 per camera
    scenario and method and nothing else is flown again (each run's stream depends
    on its index only)."""
    cfg = yaml.safe_load((quick_results / "config" / "quick.yaml").read_text())
    assert cfg["landing"]["mc"] == {"n_runs": 4, "runs_per_job": 2}
    jobs = _edit(quick_results, {"landing": {"mc": {"n_runs": 6}}})
    chunks = [w for r, w in jobs if r == "landing_mc_chunk"]
    assert chunks and {w["bchunk"] for w in chunks} == {"r0004-0005"}, chunks
    methods = {w["bmethod"] for w in chunks}
    # one new chunk per (camera scenario, method), every scenario
    assert len(chunks) == len({(w["bscn"], w["bmethod"]) for w in chunks}) == 2 * len(methods)
    assert {w["bscn"] for w in chunks} == {"site-tilt", "interior"} and len(methods) >= 4
    assert {w["bmethod"] for r, w in jobs if r == "landing_mc_gather"} == methods
    assert not {r for r, _ in jobs} & {"landing_ablation_chunk", "landing_single", "approach_mc"}
