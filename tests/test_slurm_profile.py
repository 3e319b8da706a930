"""The SLURM profile never lets a job go out without a runtime and a memory, and never
waits silently on a cluster without accounting (issue 46 item 7)."""

import re

import pytest

import yaml

from conftest import REPO


def _rule_blocks():
    """(file, name or None, text) of every rule of workflow/rules/*.smk: a `rule NAME:` (or a
    `rule:` named in its `name:`, made in a loop) block up to the next rule."""
    for f in (REPO / "workflow" / "rules").glob("*.smk"):
        for block in filter(str.strip, re.split(r"(?m)^\s*(?=rule\b)", f.read_text())[1:]):
            m = re.match(r"rule\s+(\w+)\s*:", block)
            yield f.name, m.group(1) if m else None, block


def _cluster_rules() -> set[str]:
    """The named rules that are not `localrule: True` (those go to SLURM)."""
    return {name for _, name, block in _rule_blocks()
            if name and not re.search(r"localrule:\s*True", block)}


def test_a_rule_made_in_a_loop_carries_its_own_resources():
    """A rule named in `name:` (one per study, per method pack) cannot have a profile entry:
    if it goes to SLURM, it declares runtime and mem_mb itself."""
    bad = [f"{f}: {block.splitlines()[0:4]}" for f, name, block in _rule_blocks()
           if name is None and not re.search(r"localrule:\s*True", block)
           and not re.search(r"resources:.*?runtime=.*?mem_mb=", block, re.S)]
    assert not bad, bad


def test_every_cluster_rule_has_runtime_and_memory():
    """Mutation: deleting compile_kernels' line from the profile fails it (it went out with
    no runtime or memory in the SLURM run of issue 46)."""
    profile = yaml.safe_load((REPO / "profiles" / "slurm" / "config.yaml").read_text())
    res = profile["set-resources"]
    rules = _cluster_rules()
    assert {"compile_kernels", "landing_tuning", "landing_mc_chunk", "study_runs"} <= rules
    missing = sorted(r for r in rules if not {"runtime", "mem_mb"} <= set(res.get(r, {})))
    assert not missing, missing
    assert all(res[r]["runtime"] >= 1 and res[r]["mem_mb"] >= 100 for r in rules)


def test_status_comes_from_squeue_by_default():
    """sacct answers nothing on a cluster without accounting, and Snakemake then waits for
    ever after the jobs end: the profile asks squeue."""
    profile = yaml.safe_load((REPO / "profiles" / "slurm" / "config.yaml").read_text())
    assert profile["slurm-status-command"] == "squeue"


# ------------------------------------------------------------------ a cluster it cannot see

def _fake_slurm(tmp_path, *, squeue: bool):
    """A PATH of its own: fake sbatch/scancel (and squeue when asked) that record their calls,
    and only the system tools the workflow calls (no real SLURM command, whatever is installed)."""
    import shutil
    import stat

    fake = tmp_path / "bin"
    fake.mkdir()
    for tool in ("bash", "sh", "env", "cat", "uname", "hostname", "git", "which", "ls", "mkdir", "rm",
                 "latexmk", "pdflatex", "nproc"):
        found = shutil.which(tool)
        if found:
            (fake / tool).symlink_to(found)
    calls = tmp_path / "calls.log"
    # sacct answers nothing (a cluster without accounting; the plugin's account guess runs it)
    scripts = {"sbatch": 'echo "sbatch $*" >> "$FAKE_SLURM_LOG"\necho 4242\n',
               "scancel": 'echo "scancel $*" >> "$FAKE_SLURM_LOG"\n', "sacct": "exit 0\n",
               "sinfo": 'echo PARTITION; echo "main*"\n'}
    if squeue:                                   # answers nothing: the jobs never seem to end
        scripts["squeue"] = 'echo "squeue $*" >> "$FAKE_SLURM_LOG"\n'
    for name, body in scripts.items():
        (fake / name).write_text("#!/bin/sh\n" + body)
        (fake / name).chmod((fake / name).stat().st_mode | stat.S_IEXEC)
    return fake, calls


def _start_slurm_run(wd, fake, calls):
    import os
    import subprocess
    import sys

    env = dict(os.environ, PATH=str(fake), FAKE_SLURM_LOG=str(calls), PYTHONPATH=str(wd / "src"))
    return subprocess.Popen([sys.executable, "-m", "snakemake", "--workflow-profile", "profiles/slurm",
                             "--configfile", "config/quick.yaml"], cwd=wd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)


@pytest.mark.slow
@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_slurm_without_squeue_fails_fast_and_a_signal_stops_it(tmp_path, sig):
    """Issue 57 item 4, with a fake sbatch: (1) no squeue on PATH: one line naming it, exit 1,
    nothing submitted (it used to submit and wait silently for ever); (2) a squeue that
    answers nothing, so the run waits on jobs it cannot see: SIGTERM or SIGINT ends it
    within 10 s, saying it was interrupted, and scancel is called. Mutations (tried): the
    onstart check removed (phase 1 submits and waits past its timeout), the deadline
    thread removed (phase 2 waits past 10 s)."""
    import signal
    import subprocess
    import time

    from conftest import copy_workflow

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    (tmp_path / "a").mkdir()
    fake, calls = _fake_slurm(tmp_path / "a", squeue=False)
    proc = _start_slurm_run(wd, fake, calls)
    try:
        out, _ = proc.communicate(timeout=180)
    except subprocess.TimeoutExpired:
        import os

        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("without squeue the SLURM run did not end in 180 s:\n" + proc.communicate()[0][-3000:])
    assert proc.returncode == 1, out[-3000:]
    line = [ln for ln in out.splitlines() if ln.startswith("opnav: the SLURM executor needs")]
    assert len(line) == 1 and "'squeue'" in line[0] and "nothing was submitted" in line[0], out[-3000:]
    assert "Traceback" not in out and not calls.exists(), out[-3000:]

    (tmp_path / "b").mkdir()
    fake, calls = _fake_slurm(tmp_path / "b", squeue=True)
    proc = _start_slurm_run(wd, fake, calls)
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None and not (calls.exists() and "sbatch" in calls.read_text()):
        time.sleep(0.5)
    assert proc.poll() is None, "the run ended before it submitted:\n" + proc.communicate()[0][-3000:]
    time.sleep(2)                                     # waiting on the cluster now
    t0 = time.monotonic()
    proc.send_signal(getattr(signal, sig))
    try:
        out, _ = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        import os

        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail(f"{sig} did not stop the SLURM run in 10 s:\n" + proc.communicate()[0][-3000:])
    took = time.monotonic() - t0
    assert took < 10 and proc.returncode == 128 + getattr(signal, sig), (took, proc.returncode, out[-3000:])
    assert f"interrupted by {sig}" in out and "did not complete successfully" not in out, out[-3000:]
    assert "scancel" in calls.read_text(), calls.read_text()


def test_profiles_hold_each_key_once():
    """A rule given twice in set-resources keeps the last silently (two engineers adding the
    same rule in one round did it): the profiles pass the strict reader (duplicate keys,
    YAML 1.1 traps refused). Mutation: a second landing_optima line fails it."""
    from opnav.core.yamlfile import read_config_file

    for f in sorted((REPO / "profiles").glob("*/config.yaml")):
        read_config_file(f)
