"""What a config edit reruns, read from the dry-run job list of a completed quick run.

Rules get only the config keys they use (editing one study's values lists that
study's jobs for the new values and the manuscript that shows it, no other Monte
Carlo), and Monte-Carlo chunks are kept and named by their run indices (raising
n_runs or a study's runs lists only the chunks of the new runs).
"""

import pandas as pd
import pytest
import yaml

from conftest import REPO, dry_run_jobs, dry_run_jobs_many, run_snakemake

# rules that only gather finished outputs into the manuscript; any new output reruns them
AGGREGATORS = {"paper_claims", "paper_floats", "paper_macros", "paper_page_one", "paper_pdf", "paper_scorecard", "all"}

_NEW_STUDY = {"studies": {"accel": {"paper": "landing", "vary": {"landing.imu.sigma_a_mps2": [5.0e-4, 1.0e-3]},
                                    "methods": ["depth", "svd"], "runs": 2, "runs_per_job": 2}}}
#: Every config edit the tests below dry-run on the completed quick run, by name.
EDITS = {
    "nothing": {},
    "convergence_tol": {"approach": {"convergence_study": {"tol_arcsec": 0.2}}},
    "study_fov": {"studies": {"fov": {"vary": {"landing.camera.fov_deg": [45.0, 70.0]}}}},
    "study_ifov": {"studies": {"ifov": {"vary": {"approach.camera.ifov_arcsec": [10.0, 15.0]}}}},
    "new_study": _NEW_STUDY,
    "n_runs_6": {"landing": {"mc": {"n_runs": 6}}},
}

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def edits(quick_results) -> dict[str, list[tuple[str, dict]]]:
    """{edit name: the jobs `snakemake -n` lists with that overlay on the quick profile},
    the dry runs made two at a time."""
    args = []
    for name, overlay in EDITS.items():
        path = quick_results / f"edit-{name}.yaml"
        path.write_text(yaml.safe_dump(overlay))
        args.append(("--configfile", "config/quick.yaml", str(path)))
    return dict(zip(EDITS, dry_run_jobs_many(quick_results, args)))


def test_unchanged_config_lists_nothing(edits):
    assert edits["nothing"] == []


@pytest.mark.parametrize("edit, only", [
    # (the claimed accuracy is the analysis plan's A-C1 target, no config key: the rules using it,
    # approach_crlb, approach_stars, approach_stars_outputs, approach_tables and approach_x1_figure,
    # pass it as a param and list the plan as an input)
    ("convergence_tol", {"approach_convergence", "approach_tables", "approach_x1_figure"}),
])
def test_editing_one_key_reruns_only_its_users(edits, edit, only):
    rules = {r for r, _ in edits[edit]}
    assert only <= rules, rules
    assert rules - only <= AGGREGATORS, f"also listed: {sorted(rules - only - AGGREGATORS)}"


@pytest.mark.parametrize("study", ["fov", "ifov"])
def test_editing_one_study_lists_only_its_new_value(quick_results, edits, study):
    """Only the new value's runs are flown; only that study's outputs job (table and figure) is redone."""
    jobs = edits[f"study_{study}"]
    sims = [(r, w) for r, w in jobs if r not in AGGREGATORS]
    runs = [w for r, w in sims if r == "study_runs"]
    assert runs, sims
    assert len({w["sdigest"] for w in runs}) == 1           # one new simulation config
    assert {r for r, _ in sims} == {"study_runs", f"study_{study}_outputs"}, sims
    cfg = yaml.safe_load((quick_results / "config" / "quick.yaml").read_text())["studies"][study]
    per_value = len(range(0, cfg["runs"], cfg.get("runs_per_job", 25)))
    paper = "approach" if study == "ifov" else "landing"
    # one job per chunk of the new value, flying every (variant and) method of it
    assert len(runs) == per_value and {w["spaper"] for w in runs} == {paper}


def test_a_new_study_in_an_overlay_lists_only_its_jobs(edits):
    jobs = edits["new_study"]
    rules = {r for r, _ in jobs} - AGGREGATORS
    assert rules == {"study_runs", "study_accel_outputs"}
    runs = [w for r, w in jobs if r == "study_runs"]
    # 5.0e-4 is the configured value: the main-value simulation the fov/obs studies already
    # flew (both methods): one job, the new value's
    assert len(runs) == 1 and runs[0]["spaper"] == "landing"


def test_raising_n_runs_flies_only_the_new_runs(quick_results, edits):
    """Quick profile: 4 runs in one chunk of 4; 6 runs adds chunk r0004-0005 per camera
    scenario and method and nothing else is flown again (each run's stream depends
    on its index only)."""
    cfg = yaml.safe_load((quick_results / "config" / "quick.yaml").read_text())
    assert cfg["landing"]["mc"] == {"n_runs": 4, "runs_per_job": 4, "methods_per_job": 10}
    jobs = edits["n_runs_6"]
    # the quick profile flies every method of a chunk in one job (landing_mc_pack1)
    packs = [w for r, w in jobs if r.startswith("landing_mc_pack")]
    assert packs and {w["bchunk"] for w in packs} == {"r0004-0005"}, packs
    assert not [w for r, w in jobs if r == "landing_mc_chunk"]
    # one new chunk per camera scenario (every method), every scenario
    assert sorted(w["bscn"] for w in packs) == ["interior", "site-tilt"]
    methods = {w["bmethod"] for r, w in jobs if r == "landing_mc_gather"}
    assert len(methods) >= 4
    # (paper A's Monte Carlo in any form: approach_mc or, quick profile, approach_mc_pack*)
    assert not {r for r, _ in jobs if r.startswith("approach_mc")} | ({r for r, _ in jobs} & {"study_runs", "landing_single"})


def _readme_study_block() -> dict:
    # the README's study example (moved from README.md to docs/studies.md)
    text = next(t for t in ((REPO / f).read_text() for f in ("README.md", "docs/studies.md"))
                if "<!-- study-example" in t)
    tail = text.split("<!-- study-example", 1)[1]
    return yaml.safe_load(tail.split("```yaml\n", 1)[1].split("```", 1)[0])


def test_readme_study_example_runs_only_its_jobs(quick_results, edits):
    """The README's study block, at quick-profile sizes, from one command: only its own
    runs are flown (its configured value is shared with the fov/obs studies), and it
    gives its table and figure. (It adds outputs to the shared run: after the dry runs.)"""
    block = _readme_study_block()
    (name, spec), = block["studies"].items()
    (quick_results / "my-study.yaml").write_text(yaml.safe_dump(block))
    (quick_results / "sizes.yaml").write_text(yaml.safe_dump({"studies": {name: {"runs": 2, "runs_per_job": 2}}}))
    proc = run_snakemake(quick_results, "--cores", "2", f"study_{name}", "--configfile", "config/quick.yaml",
                         "my-study.yaml", "sizes.yaml")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    log = proc.stdout + proc.stderr
    n_values = len(next(iter(spec["vary"].values())))
    flown = log.count("rule study_runs:")
    assert flown == n_values - 1, log[-3000:]           # one job per new value, every method
    out = quick_results / "results" / "quick" / "studies" / name
    table = pd.read_csv(out / f"B-S_{name}.csv")
    assert len(table) == n_values * len(spec["methods"]) * len(spec["metrics"])
    assert set(table["metric"]) == set(spec["metrics"]) and (table["n_runs"] == 2).all()
    assert (out / f"B-S_{name}.png").stat().st_size > 10_000


def test_editing_a_kernel_module_reruns_its_users_in_the_same_run(quick_results):
    """An edit of a compiled-kernel module lists compile_kernels AND the jobs that call
    those kernels (their src inputs hold the module) in one invocation. With the kernel
    cache's marker as an ancient() input, Snakemake 9.27 listed compile_kernels alone and
    kept the stale Monte Carlo (this test fails on that design). The file's content and
    times are restored after the dry run (the scratch run is shared)."""
    import os

    path = quick_results / "src" / "opnav" / "landing" / "planning" / "search.py"
    text, st = path.read_bytes(), path.stat()
    try:
        path.write_bytes(text + b"\n# an edit\n")
        rules = {r for r, _ in dry_run_jobs(quick_results, "--configfile", "config/quick.yaml")}
    finally:
        path.write_bytes(text)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert {"compile_kernels", "landing_mc_pack1", "landing_timing"} <= rules, sorted(rules)
    assert not {r for r in rules if r.startswith("approach_")}, sorted(rules)
