"""SIGINT in the middle of a Monte Carlo loses nothing but the job in flight: the
rerun completes and its output equals a clean computation exactly (the descent
records no clock: planning time is measured by replay, opnav.landing.timing)."""

import os
import signal
import time

from pathlib import Path

import numpy as np
import pytest

from conftest import REPO, copy_workflow, run_snakemake, start_snakemake


def _job_in_flight(pgid: int, script: str) -> bool:
    """A process of group ``pgid`` other than its leader runs ``script`` (a job of
    Snakemake's): read from /proc (Linux); True where there is no /proc to read."""
    proc = Path("/proc")
    if not proc.is_dir():
        return True
    for d in proc.iterdir():
        if not d.name.isdigit() or int(d.name) == pgid:
            continue
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()   # state ppid pgrp ...
            if int(fields[2]) == pgid and script in (d / "cmdline").read_bytes().decode(errors="replace"):
                return True
        except (OSError, ValueError, IndexError):
            continue
    return False


@pytest.mark.slow
def test_sigint_mid_monte_carlo_then_rerun_is_identical(tmp_path):
    from opnav.core.config import load_config
    from opnav.landing.montecarlo import gather, load, run_chunk

    wd = tmp_path / "wf"
    wd.mkdir()
    copy_workflow(wd)
    # four runs per job: with the compiled descent a run takes a fraction of a second, so a
    # job of one run could end between seeing it in flight and the signal (CI, 08:13 UTC)
    (wd / "small.yaml").write_text("landing: {mc: {n_runs: 12, runs_per_job: 4, methods_per_job: 1}}\n")
    target = "results/quick/landing/mc/site-tilt/depth.npz"  # the quick profile's results_dir
    args = [target, "--cores", "1", "--configfile", "config/quick.yaml", "small.yaml"]
    chunks = wd / "results" / "quick" / "landing" / "mc" / "site-tilt" / "chunks" / "depth"

    # its own process group (as Popen(start_new_session=True)): SIGINT reaches it and its jobs.
    # The signal is sent while a chunk job runs: Snakemake's log handler swallows a
    # KeyboardInterrupt that lands while it writes a line (snakemake/logging.py, emit), as it
    # does between jobs, so only a job in flight, killed by the signal, surely stops the run.
    proc = start_snakemake(wd, *args, new_session=True)
    deadline = time.time() + 240
    while time.time() < deadline and proc.poll() is None:
        done = list(chunks.glob("r*.npz")) if chunks.is_dir() else []
        if done and _job_in_flight(proc.pid, "landing_mc_chunk"):   # one chunk written, a job running
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the workflow ended before it could be interrupted:\n" + proc.wait().stderr
    os.killpg(proc.pid, signal.SIGINT)
    stopped = proc.wait(timeout=120)
    assert not (wd / target).exists(), stopped.stdout + stopped.stderr
    for f in chunks.iterdir():                     # nothing half-written is left as an output
        if f.name.startswith("r"):
            load(f)

    rerun = run_snakemake(wd, *args, timeout=600)
    assert rerun.returncode == 0, rerun.stdout + rerun.stderr

    from opnav.landing.scenario import camera_scenarios

    cfg = camera_scenarios(load_config(REPO / "config" / "config.yaml",
                                       overlays=[REPO / "config" / "quick.yaml", wd / "small.yaml"])["landing"])["site-tilt"]
    # each job flies its chunk of four runs as one batch: the clean run does the same
    # (batch size changes numbers only at round-off, tests/test_landing_batch.py)
    clean = gather([run_chunk(cfg, "depth", list(range(a, a + 4)), batch_size=4) for a in (0, 4, 8)])
    got = load(wd / target)
    assert set(got) - {"method", "reuse_key"} == set(clean)
    differ = {k for k in clean if not np.array_equal(np.asarray(got[k]), np.asarray(clean[k]),
                                                     equal_nan=np.asarray(clean[k]).dtype.kind == "f")}
    assert not differ, differ

    # a truncated intermediate found downstream: the job fails with the file's name and
    # the rebuild command, the traceback is in the rule's log, and Snakemake names the log
    chunk = sorted(chunks.glob("r*.npz"))[1]
    chunk.write_bytes(chunk.read_bytes()[:100])
    again = run_snakemake(wd, *args, timeout=600)
    out = again.stdout + again.stderr
    assert again.returncode != 0
    log = wd / "results" / "quick" / "landing" / "logs" / "mc_site-tilt_depth_gather.log"
    assert str(log.relative_to(wd)) in out, out
    assert chunk.name in out and "snakemake --cores 2 --force" in out, out
    text = log.read_text()
    assert "Traceback" in text and "CorruptIntermediate" in text and chunk.name in text, text
