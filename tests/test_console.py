"""The console a newcomer reads (issue 55 item 8): a job's header lists no source files (their
count instead) and no reason runs to thousands of characters; everything else prints as
Snakemake prints it."""

import logging

import pytest
from conftest import REPO, run_snakemake

from opnav.core import console


def test_source_inputs_print_as_their_count():
    src = REPO / "src"
    inputs = ["results/quick/landing/tuning.json", str(src / "opnav" / "landing" / "filter.py"),
              str(src / "opnav" / "core" / "compiled.py"), "config/x.yaml (ancient)"]
    assert console.short_inputs(inputs, [src]) == ["results/quick/landing/tuning.json", "config/x.yaml (ancient)",
                                                   "2 source files of the repository"]
    assert console.short_inputs(inputs[:1], [src]) == inputs[:1]
    assert console.short_inputs([str(src / "opnav" / "a.py")], [src]) == ["1 source file of the repository"]
    assert console.short_inputs([str(REPO / "srcx" / "a.py")], [src]) == [str(REPO / "srcx" / "a.py")]
    many = [f"results/r{i}.pdf" for i in range(20)]
    assert console.short_inputs(many, [src]) == many[:6] + ["14 more files"]


def test_long_reasons_keep_three_names_and_a_count():
    files = ", ".join(f"results/f{i}.csv" for i in range(12))
    r = console.short_reason(f"Missing output files: {files}; Input files updated by another job: a, b")
    assert r == ("Missing output files: results/f0.csv, results/f1.csv, results/f2.csv and 9 more; "
                 "Input files updated by another job: a, b")
    assert console.short_reason("Forced execution") == "Forced execution"
    assert console.short_reason("Missing output files: a, b, c, d") == "Missing output files: a, b, c, d"


def test_the_filter_rewrites_job_headers_only():
    from snakemake.logging import LogEvent, logger

    console.quiet_job_headers([REPO / "src"])
    console.quiet_job_headers([REPO / "src"])          # installed once, whatever the calls
    mine = [f for f in logger.filters if getattr(f, "name", "") == "opnav-quiet-job-headers"]
    assert len(mine) == 1
    rec = logging.LogRecord("snakemake.logging", logging.INFO, __file__, 1, "x", None, None)
    rec.event, rec.input = LogEvent.JOB_INFO, [str(REPO / "src" / "opnav" / "x.py"), "results/a.csv"]
    rec.reason = "Missing output files: " + ", ".join("abcdefgh")
    assert mine[0].filter(rec) and rec.input == ["results/a.csv", "1 source file of the repository"]
    assert rec.reason == "Missing output files: a, b, c and 5 more"
    other = logging.LogRecord("snakemake.logging", logging.INFO, __file__, 1, "x", None, None)
    other.event, other.input = LogEvent.JOB_ERROR, [str(REPO / "src" / "opnav" / "x.py")]
    assert mine[0].filter(other) and other.input == [str(REPO / "src" / "opnav" / "x.py")]  # errors in full
    logger.removeFilter(mine[0])


@pytest.mark.slow
def test_a_dry_run_prints_short_job_headers(workdir):
    proc = run_snakemake(workdir, "-n", "--configfile", "config/quick.yaml")
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout + proc.stderr
    inputs = [ln for ln in out.splitlines() if ln.startswith("    input: ")]
    assert inputs and not [ln for ln in inputs if "/src/opnav/" in ln]
    assert any("source files of the repository" in ln for ln in inputs)
    assert max(len(ln) for ln in inputs) < 600
    assert max(len(ln) for ln in out.splitlines() if ln.startswith("    reason: ")) < 600
