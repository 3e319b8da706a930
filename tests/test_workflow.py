"""The pipeline as a user meets it: config validation, dry runs, the quick profile."""

import shutil
from pathlib import Path

import pytest
import yaml

from conftest import REPO, run_snakemake
from opnav.core.config import ConfigError, load_config, validate_config


def _write_bad(workdir: Path, mutations, name: str) -> Path:
    cfg = load_config(overlays=[REPO / "config" / "quick.yaml"])
    for mutate in mutations:
        mutate(cfg)
    path = workdir / name
    path.write_text(yaml.safe_dump(cfg))
    return path


BAD_CONFIGS = [  # (mutation, key the refusal names, text of that key's line)
    (lambda c: c["landing"]["mc"].__setitem__("n_runs", "many"), "landing.mc.n_runs", "not of type"),
    (lambda c: c["landing"]["mc"].__setitem__("n_runs", 0), "landing.mc.n_runs", "minimum"),
    (lambda c: c["landing"]["mc"]["bounds"].__setitem__("att_deg", 400), "landing.mc.bounds.att_deg", "maximum"),
    (lambda c: c["landing"].__setitem__("colour", "red"), "landing", "'colour' was unexpected"),
    (lambda c: c.__setitem__("profile", "fast"), "profile", "is not one of"),
]


def _refusal_lines_name(lines: list[str], cases, out: str) -> None:
    for _, key, fragment in cases:
        named = [line for line in lines if f"invalid config key '{key}'" in line]
        assert named, out[-2000:]
        assert any(fragment in line for line in named), (key, fragment, named)


@pytest.mark.parametrize("case", BAD_CONFIGS, ids=lambda c: f"{c[1]}:{c[2]}")
def test_bad_config_is_refused_naming_the_key(case):
    """Each case, in process: the function the Snakefile calls before any job
    (common.smk) refuses it with a line naming the key."""
    cfg = load_config(overlays=[REPO / "config" / "quick.yaml"])
    case[0](cfg)
    with pytest.raises(ConfigError) as err:
        validate_config(cfg, root=REPO)
    _refusal_lines_name(str(err.value).splitlines(), [case], str(err.value))


def test_snakemake_refuses_a_bad_config_listing_every_problem(workdir):
    """End to end: `snakemake -n` with a config holding one bad value per key
    fails, one line per problem, each naming its key."""
    cases = [c for i, c in enumerate(BAD_CONFIGS) if c[1] not in {d[1] for d in BAD_CONFIGS[:i]}]
    assert len(cases) >= 4
    bad = _write_bad(workdir, [m for m, _, _ in cases], "bad.yaml")
    proc = run_snakemake(workdir, "-n", "--cores", "1", "--configfile", str(bad))
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0
    _refusal_lines_name(out.splitlines(), cases, out)


@pytest.mark.parametrize("configfile", [pytest.param("config/config.yaml", marks=pytest.mark.slow),  # ~2 CPU-s
                                        "config/quick.yaml"])
def test_dry_run_succeeds(workdir, configfile):
    proc = run_snakemake(workdir, "-n", "--cores", "2", "--configfile", configfile)
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_quick_profile_is_a_valid_overlay_of_only_changed_keys():
    """quick.yaml holds only keys of config.yaml whose values it changes, and the
    merged result validates (so the overlay cannot drift from the schema)."""
    full = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    quick = yaml.safe_load((REPO / "config" / "quick.yaml").read_text())

    def check(f, q, prefix=""):
        for k, v in q.items():
            assert k in f, f"quick.yaml key {prefix + k} is not in config.yaml"
            if isinstance(v, dict):
                check(f[k], v, prefix + k + ".")
            else:
                assert v != f[k], f"quick.yaml key {prefix + k} repeats the full value"

    check(full, quick)
    merged = load_config(overlays=[REPO / "config" / "quick.yaml"])
    assert merged["profile"] == "quick"
    assert merged["landing"]["mc"]["bounds"] == load_config()["landing"]["mc"]["bounds"]


@pytest.mark.slow
def test_quick_profile_end_to_end(quick_results):
    workdir = quick_results  # the complete quick run (conftest), shared with the dry-run tests
    before = sorted(p.relative_to(REPO) for p in (REPO / "results").rglob("*")) if (REPO / "results").exists() else []
    out = workdir / "results" / "quick"           # the quick profile's own results folder
    assert not (workdir / "results" / "landing").exists()
    t1 = (out / "landing" / "B-T1_initial_state.csv").read_text()
    assert "3300" in t1 and "published" in t1
    assert (out / "paper" / "scorecard.csv").is_file()
    if shutil.which("latexmk"):
        # the manuscript rebuilds byte-identically (SOURCE_DATE_EPOCH, no paths or IDs)
        pdf = out / "paper" / "main.pdf"
        first = pdf.read_bytes()
        assert len(first) > 10_000
        pdf.unlink()
        again = run_snakemake(workdir, "results/quick/paper/main.pdf", "--cores", "1",
                              "--configfile", "config/quick.yaml")
        assert again.returncode == 0, again.stderr[-3000:]
        assert pdf.read_bytes() == first
        # every number the text quotes was written by a rule
        log = (out / "paper" / "logs" / "paper_pdf.log").read_text()
        assert "opnav-missing-macro" not in log, log[-2000:]
    # the Snakemake report, with a caption for every figure and table
    rep = run_snakemake(workdir, "--cores", "1", "--configfile", "config/quick.yaml",
                        "--report", "results/quick/report.html")
    assert rep.returncode == 0, rep.stderr[-3000:]
    html = (out / "report.html").read_text(errors="replace")
    assert len(html) > 10_000
    assert "made by the quick profile" in html          # the report names its profile
    after = sorted(p.relative_to(REPO) for p in (REPO / "results").rglob("*")) if (REPO / "results").exists() else []
    assert before == after, "the quick run must not touch the repository's results/"


def test_kernels_compiled_once_then_only_loaded(quick_results):
    """Rule compile_kernels ran first, once per paper, and wrote the kernel modules it
    compiled (together every registered one); every other job that used kernels loaded
    them from numba's cache and compiled none (a job that compiles means a warm-up
    misses a signature the pipeline calls, or a kernel numba cannot cache: each such
    job pays the compilation)."""
    import json
    import re

    import opnav.approach  # noqa: F401  (registers its kernel modules)
    import opnav.landing  # noqa: F401  (registers its kernel modules)
    from opnav.core import compiled

    out = quick_results / "results" / "quick"
    made = [json.loads((out / "kernels" / f"{p}.json").read_text())["kernel_modules"]
            for p in ("approach", "landing")]
    assert set(made[0]) | set(made[1]) == set(compiled.kernel_modules())
    assert not any(m.startswith("opnav.landing.") for m in made[0]), made[0]
    assert not any(m.startswith("opnav.approach.") for m in made[1]), made[1]
    jobs = {}
    for log in out.rglob("logs/*.log"):
        m = re.search(r"kernels_loaded=(\d+) kernels_compiled=(\d+)", log.read_text(errors="replace"))
        if m:
            jobs[str(log.relative_to(out))] = (int(m.group(1)), int(m.group(2)))
    first = {f"kernels/logs/compile_{p}.log" for p in ("approach", "landing")}
    assert first <= set(jobs), sorted(jobs)
    compiling = {k: v for k, v in jobs.items() if k not in first and v[1]}
    assert not compiling, f"jobs that compiled kernels themselves (loaded, compiled): {compiling}"
    if compiled.kernel_modules():  # the Monte-Carlo jobs ran compiled code, loaded from the cache
        assert any(v[0] for k, v in jobs.items() if k not in first), jobs


@pytest.mark.slow  # a dry run of the full workflow: ~2 CPU-s (issue 56: the default run <= 90 s)
def test_slurm_profile_dry_run(workdir):
    pytest.importorskip("snakemake_executor_plugin_slurm")
    proc = run_snakemake(workdir, "-n", "--profile", "profiles/slurm", "--configfile", "config/quick.yaml")
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Job stats" in proc.stdout


@pytest.mark.slow  # a dry run of the full workflow: ~2 CPU-s (issue 56: the default run <= 90 s)
def test_slurm_workflow_profile_dry_run_account_and_measured_resources(workdir):
    """README's cluster command: account and partition from the command line
    (no tracked file edited); each cluster rule gets its measured resources."""
    import re

    import yaml

    pytest.importorskip("snakemake_executor_plugin_slurm")
    profile = yaml.safe_load((workdir / "profiles" / "slurm" / "config.yaml").read_text())
    assert "slurm_account" not in str(profile.get("default-resources", ""))
    set_res = profile["set-resources"]
    # one Monte-Carlo job per method (paper A: per variant and group), as the full profile and
    # a cluster fly them (the quick profile's landing.mc.methods_per_job and
    # jobs.approach_mc_per_job pack them into rules landing_mc_pack*, approach_mc_pack*)
    (workdir / "per-method.yaml").write_text("landing: {mc: {methods_per_job: 1}}\njobs: {approach_mc_per_job: 1}\n")
    proc = run_snakemake(workdir, "-n", "--workflow-profile", "profiles/slurm",
                         "--default-resources", "slurm_account=acct42", "slurm_partition=part7",
                         "--configfile", "config/quick.yaml", "per-method.yaml")
    assert proc.returncode == 0, proc.stderr[-3000:]
    jobs = re.split(r"\n(?= *(?:local)?rule \w+:)", proc.stdout)   # a group job's rules are indented
    seen = set()
    for block in jobs:
        m = re.match(r" *(?:local)?rule (\w+):", block)
        res = re.search(r"resources: (.*)", block)
        if not m or not res:
            continue
        rule, res = m.group(1), res.group(1)
        seen.add(rule)
        assert "slurm_account=acct42" in res and "slurm_partition=part7" in res, res
        if rule in set_res:
            assert f"runtime={set_res[rule]['runtime']}" in res, (rule, res)
            assert f"mem_mb={set_res[rule]['mem_mb']}" in res, (rule, res)
    defined = {m.group(1) for f in (workdir / "workflow" / "rules").glob("*.smk")
               for m in re.finditer(r"^ *rule (\w+):", f.read_text(), re.M)}
    # every rule given resources exists (a rule printed by its `message:`, or one the quick
    # profile does not run, e.g. the replication sample's, is not in `seen`)
    assert set(set_res) <= defined, f"set-resources for rules not in the workflow: {set(set_res) - defined}"
    assert {"landing_mc_chunk", "approach_mc"} <= seen
