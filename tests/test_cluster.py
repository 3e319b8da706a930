"""The quick profile through a real single-node SLURM (``.ci/slurm-cluster``) and the
executor plugin (``--workflow-profile profiles/slurm``), compared with the local build.

Runs where the cluster can be started: Linux, as root, with slurm-wlm installed, or
apt-get to install it and ``OPNAV_ALLOW_APT=1`` (CI sets it; the test never installs
system packages without it). Elsewhere it is skipped with one line saying why. Deselect
with ``-m "not cluster"``. The cluster is started by the test and stopped at its end
(if it was not already running), by the daemons' pid files; one cluster test at a time
per machine (a lock file), so two sessions never share or stop each other's daemons.
"""

import fcntl
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import REPO, _snakemake_cmd, copy_workflow
from opnav.core.snakeio import CSV_STAMP, load_csv

pytestmark = pytest.mark.cluster  # run with `pytest -m cluster`

SCRIPT = REPO / ".ci" / "slurm-cluster"
# What a cluster without accounting (no slurmdbd) needs: job status from squeue (the
# plugin would ask sacct, which answers nothing, and wait forever), and the logs of
# successful jobs kept, to see that the jobs went through sbatch. A private one-node
# cluster can be polled every 10 s instead of the plugin's 40 s (docs/cluster.md).
CLUSTER_ARGS = ("--workflow-profile", "profiles/slurm", "--configfile", "config/quick.yaml",
                "--slurm-status-command", "squeue", "--slurm-keep-successful-logs",
                "--slurm-init-seconds-before-status-checks", "10")
RUN_TIMEOUT_S = 1800
# Measured times differ between any two runs (on a shared node more so): columns named
# for a time or CPU time ("timed_calls" is a count), rows of long tables whose text
# names one (metric "median_plan_time_us", the scorecard's planning-time rows), the
# evidence read from the timing replays (sample "replay<k>" or "between_replays") and
# the rows of the claims whose plan test reads them (opnav.report.readme.timing_claims:
# B-C4, B-C9, B-C11), and the build's date stamp. Every other cell must be equal.
TIMING = re.compile(r"time(?!d)|cpu", re.IGNORECASE)
STAMPS = re.compile(r"^built_utc$")


def _why_not() -> str | None:
    if not sys.platform.startswith("linux"):
        return "SLURM cluster test: Linux only"
    if os.geteuid() != 0:
        return "SLURM cluster test: needs root to start munged/slurmctld/slurmd (.ci/slurm-cluster)"
    def found(b):
        return any(os.access(os.path.join(d, b), os.X_OK) for d in os.environ.get("PATH", "").split(os.pathsep))

    if found("slurmctld"):
        return None
    if not found("apt-get"):
        return "SLURM cluster test: neither slurm-wlm nor apt-get to install it"
    if os.environ.get("OPNAV_ALLOW_APT") != "1":
        return ("SLURM cluster test: slurm-wlm is not installed; set OPNAV_ALLOW_APT=1 to let the test "
                "install slurm-wlm and munge with apt-get (it changes the system)")
    return None


def _script(cmd: str, timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", str(SCRIPT), cmd], capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def slurm_cluster():
    """A running single-node SLURM; stopped afterwards if this fixture started it."""
    why = _why_not()
    if why:
        pytest.skip(why)
    with open("/run/opnav-slurm-test.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)           # another session's cluster test first
        was_up = _script("status").returncode == 0
        started = False
        try:
            if not was_up:
                p = _script("start")
                if p.returncode == 3:              # cannot run here: one line says why
                    pytest.skip("SLURM cluster test: " + p.stderr.strip().splitlines()[-1])
                assert p.returncode == 0, p.stdout + p.stderr
                started = True
            yield
        finally:
            if started:
                p = _script("stop", timeout=120)
                assert p.returncode == 0, p.stdout + p.stderr


def _run_through_slurm(wd: Path) -> subprocess.CompletedProcess:
    cmd, env = _snakemake_cmd(wd, *CLUSTER_ARGS)
    proc = subprocess.Popen(cmd, cwd=wd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        subprocess.run(["scancel", "--user", "root"], check=False)
        pytest.fail(f"the run through SLURM did not end in {RUN_TIMEOUT_S} s:\n{out[-4000:]}")
    return subprocess.CompletedProcess(cmd, proc.returncode, out, "")


def _sbatch_ids(log: str) -> list[int]:
    """The SLURM job ids of the plugin's submissions (single, group and array jobs)."""
    return [int(m.group(1) or m.group(2)) for m in re.finditer(
        r"has been submitted with SLURM jobid (\d+)|Submitted array job with .* SLURM job ID (\d+)", log)]


def _job_outputs(log: str, kinds: tuple[str, ...]) -> dict[str, str]:
    """{output file: rule} of the job blocks of a Snakemake log ("rule X:" blocks are
    jobs for the executor, "localrule X:" jobs run in that process; a group job's
    blocks are indented); ``kinds`` picks "rule" and/or "localrule"."""
    outs = {}
    for m in re.finditer(r"^( *)(rule|localrule) (\w+):\n((?:\1 {4}.*\n)+)", log, re.MULTILINE):
        o = re.search(r"^ *output: (.*)$", m.group(4), re.MULTILINE)
        if m.group(2) in kinds and o:
            outs.update(dict.fromkeys(o.group(1).split(", "), m.group(3)))
    return outs


def _read(path: Path) -> pd.DataFrame:
    """A table; an intermediate stamped with its row count and checksum is checked."""
    with open(path) as f:
        stamped = f.readline().startswith(CSV_STAMP)
    return load_csv(path) if stamped else pd.read_csv(path)


def _tables(root: Path) -> dict[str, pd.DataFrame]:
    return {p.relative_to(root).as_posix(): _read(p) for p in sorted(root.rglob("*.csv"))
            if "benchmarks" not in p.parts}


def _timing_claims() -> set[str]:
    from opnav.report.plan import load_plan
    from opnav.report.readme import timing_claims

    plan = load_plan()
    return set(timing_claims(pd.DataFrame({"claim_id": list(plan.tests())}), plan))


def _untimed(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` without its timing columns and timing rows (see TIMING)."""
    text = df.select_dtypes(exclude="number").astype(str)
    timed_claims = _timing_claims()
    timed_row = text.apply(lambda col: col.str.contains(TIMING) | col.isin(timed_claims)
                           | col.str.match(r"^(replay\d+|between_replays)$") | col.str.match(STAMPS)).any(axis=1)
    return df.loc[~timed_row, [c for c in df.columns if not TIMING.search(str(c))]]


def _differing(local: pd.DataFrame, slurm: pd.DataFrame) -> list[str]:
    """The columns whose untimed cells differ (or a shape mismatch of the untimed rows: the
    scorer's derived rows of a timing claim, its band ends and sweeps, come and go with the
    measured times, so the whole tables may differ in length)."""
    if list(local.columns) != list(slurm.columns):
        return [f"columns {list(local.columns)} vs {list(slurm.columns)}"]
    a, b = _untimed(local), _untimed(slurm)
    if a.shape != b.shape:
        return [f"untimed rows {a.shape} vs {b.shape}"]
    bad = []
    for c in a.columns:
        if pd.api.types.is_numeric_dtype(a[c]) and pd.api.types.is_numeric_dtype(b[c]):
            same = np.array_equal(a[c].to_numpy(float), b[c].to_numpy(float), equal_nan=True)
        else:
            same = list(a[c].fillna("").astype(str)) == list(b[c].fillna("").astype(str))
        if not same:
            bad.append(c)
    return bad


def test_quick_profile_through_slurm_equals_the_local_build(slurm_cluster, quick_results, tmp_path):
    wd = copy_workflow(tmp_path)
    proc = _run_through_slurm(wd)
    log = proc.stdout
    assert proc.returncode == 0, log[-6000:]

    # The cluster rules went through sbatch: SLURM wrote a log for every submission, and
    # the jobs run inside the SLURM jobs (their logs) are exactly the jobs Snakemake
    # handed to the executor.
    remote = _job_outputs(log, ("rule",))
    assert remote, "no job went to the SLURM executor:\n" + log[-3000:]
    ids = _sbatch_ids(log)
    logs = list((wd / ".snakemake" / "slurm_logs").rglob("*.log"))
    assert set(ids) <= {int(re.match(r"\d+", p.name).group()) for p in logs}, (ids, logs)
    inside = {}
    for p in logs:
        inside.update(_job_outputs(p.read_text(errors="replace"), ("rule", "localrule")))
    assert inside == remote, sorted(set(inside.items()) ^ set(remote.items()))
    # ... and the profile's measured resources name rules of the workflow (the quick
    # profile runs only some of them: it packs the Monte Carlo, has no replication sample,
    # and a rule with a message: prints no header; tests/test_slurm_profile.py checks
    # that every rule sent to SLURM has its runtime and memory)
    profile = yaml.safe_load((wd / "profiles" / "slurm" / "config.yaml").read_text())
    defined = {m.group(1) for f in (wd / "workflow" / "rules").glob("*.smk")
               for m in re.finditer(r"^ *rule (\w+):", f.read_text(), re.M)}
    assert set(profile["set-resources"]) <= defined, sorted(set(profile["set-resources"]) - defined)
    print(f"through SLURM: {len(remote)} output files of {len(set(remote.values()))} rules, "
          f"{len(ids)} sbatch calls")

    # Every table equals the local build's, apart from measured times.
    results = "results/quick"
    local, slurm = _tables(quick_results / results), _tables(wd / results)
    assert local and sorted(local) == sorted(slurm), sorted(set(local) ^ set(slurm))
    differ = {name: cols for name in local if (cols := _differing(local[name], slurm[name]))}
    assert not differ, differ
