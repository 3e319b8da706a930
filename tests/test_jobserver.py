"""The build's job server (opnav.core.jobserver): a delegated job runs the same script, with the
job's directory, environment, command line and streams, and leaves with its exit status; without
a server (or with a job of several threads) the script runs in its own process; a job stopped
by Snakemake (its client killed) ends."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from opnav.core import jobserver

# the tests that start a server are slow: its imports (about 2 CPU-s) and ten job processes; the
# quick build (tests/test_workflow.py, slow too) runs every job of the quick profile through it
slow = pytest.mark.slow

SRC = Path(jobserver.__file__).resolve().parents[2]

# A stand-in for a Snakemake script job: a `snakemake` object of a Snakemake type (what
# delegate() looks for), then the job's own work, which reports where it ran.
JOB = textwrap.dedent("""
    from snakemake.iocontainers import Snakemake
    snakemake = Snakemake.__new__(Snakemake)
    from opnav.core.jobserver import delegate

    delegate()
    import json, os, sys
    from opnav.core.snakeio import resource_line
    what = sys.argv[1]
    print(json.dumps({"pid": os.getpid(), "ppid": os.getppid(), "cwd": os.getcwd(), "argv": sys.argv[1:],
                      "env": os.environ.get("JOB_VAR"), "stdin": sys.stdin.read(),
                      "numpy_preloaded": "numpy" in sys.modules,
                      "client_cpu_env": os.environ.get("OPNAV_JOB_CLIENT_CPU_S")}), flush=True)
    print(resource_line(), flush=True)
    if what == "fail":
        raise SystemExit("the job failed: one line")
    if what == "exit3":
        sys.exit(3)
    if what == "raise":
        raise ValueError("boom")
    if what == "sleep":
        import time
        open(sys.argv[2], "w").write(str(os.getpid()))
        time.sleep(60)
""")


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    folder = tmp_path_factory.mktemp("jobserver")
    path = str(folder / "s")
    env = dict(os.environ, **dict.fromkeys(jobserver.THREAD_VARS, "1"))
    env.pop(jobserver.ENV, None)
    proc = subprocess.Popen([sys.executable, jobserver.__file__, path], env=env, stdin=subprocess.DEVNULL)
    for _ in range(1200):                     # its imports: about 2 CPU-s (a minute at most when loaded)
        if os.path.exists(path):
            break
        time.sleep(0.05)
    assert os.path.exists(path), "the job server did not start"
    yield path
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=10)


def _job(tmp_path, server, *args, env_extra=None, stdin="", timeout=60):
    script = tmp_path / "job.py"
    script.write_text(JOB)
    env = dict(os.environ, PYTHONPATH=str(SRC), JOB_VAR="from the job", **dict.fromkeys(jobserver.THREAD_VARS, "1"))
    if server is not None:
        env[jobserver.ENV] = server
    else:
        env.pop(jobserver.ENV, None)
    env.update(env_extra or {})
    return subprocess.run([sys.executable, str(script), *args], cwd=tmp_path, env=env, input=stdin,
                          capture_output=True, text=True, timeout=timeout)


def _report(proc):
    import json

    return json.loads(proc.stdout.splitlines()[0]), proc.stdout.splitlines()[1]


@slow
def test_a_delegated_job_runs_in_a_fork_with_the_jobs_context(tmp_path, server):
    proc = _job(tmp_path, server, "ok", "x y", stdin="from stdin")
    assert proc.returncode == 0, proc.stderr
    out, line = _report(proc)
    assert out["numpy_preloaded"]              # ran in the server's fork: its libraries already there
    assert out["cwd"] == str(tmp_path) and out["argv"] == ["ok", "x y"]
    assert out["env"] == "from the job" and out["stdin"] == "from stdin"
    assert " job_server=1" in line             # the job's resource line says so, with the client's CPU
    assert out["client_cpu_env"] is None       # which the job's own subprocesses do not inherit
    cpu = float(line.split("cpu_s=")[1].split()[0])
    assert cpu > 0.02                           # the client's interpreter start alone is more


@slow
def test_without_a_server_the_job_runs_in_its_own_process(tmp_path):
    proc = _job(tmp_path, None, "ok")
    out, line = _report(proc)
    assert proc.returncode == 0 and not out["numpy_preloaded"] and "job_server" not in line


@slow
def test_a_server_that_is_gone_leaves_the_job_in_its_own_process(tmp_path):
    proc = _job(tmp_path, str(tmp_path / "no-such-socket"), "ok")
    out, _ = _report(proc)
    assert proc.returncode == 0 and not out["numpy_preloaded"]


@slow
def test_a_job_of_several_threads_is_not_delegated(tmp_path, server):
    proc = _job(tmp_path, server, "ok", env_extra={"OPENBLAS_NUM_THREADS": "2"})
    out, _ = _report(proc)
    assert proc.returncode == 0 and not out["numpy_preloaded"]


@slow
@pytest.mark.parametrize("what, code, err", [("fail", 1, "the job failed: one line"), ("exit3", 3, ""),
                                             ("raise", 1, "ValueError: boom")])
def test_exit_status_and_message_come_back(tmp_path, server, what, code, err):
    proc = _job(tmp_path, server, what)
    out, _ = _report(proc)
    assert out["numpy_preloaded"]
    assert proc.returncode == code
    assert err in proc.stderr


@slow
def test_a_stopped_job_ends_in_the_server_too(tmp_path, server):
    """Snakemake stops a job by killing its process: the server's child running it ends."""
    script = tmp_path / "job.py"
    script.write_text(JOB)
    pidfile = tmp_path / "pid"
    env = dict(os.environ, PYTHONPATH=str(SRC), **dict.fromkeys(jobserver.THREAD_VARS, "1"))
    env[jobserver.ENV] = server
    client = subprocess.Popen([sys.executable, str(script), "sleep", str(pidfile)], cwd=tmp_path, env=env,
                              stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    for _ in range(400):
        if pidfile.exists() and pidfile.read_text():
            break
        time.sleep(0.05)
    child = int(pidfile.read_text())
    assert child != client.pid
    client.kill()
    client.wait()
    for _ in range(100):
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    else:
        pytest.fail("the server's child outlived its killed client by 5 s")


@slow
def test_a_job_waits_for_a_server_still_starting(tmp_path):
    """The build's first jobs start while the server imports: they wait for it while it lives."""
    path = str(tmp_path / "late")
    env = dict(os.environ, **dict.fromkeys(jobserver.THREAD_VARS, "1"))
    env.pop(jobserver.ENV, None)
    srv = subprocess.Popen([sys.executable, jobserver.__file__, path], env=env, stdin=subprocess.DEVNULL)
    try:
        proc = _job(tmp_path, path, "ok", env_extra={jobserver.PID_ENV: str(srv.pid)})
        out, _ = _report(proc)
        assert proc.returncode == 0 and out["numpy_preloaded"]
    finally:
        srv.send_signal(signal.SIGTERM)
        srv.wait(timeout=30)
    gone = _job(tmp_path, path, "ok", env_extra={jobserver.PID_ENV: str(srv.pid)})   # ended: run here
    assert gone.returncode == 0 and not _report(gone)[0]["numpy_preloaded"]


def test_every_workflow_script_delegates_first():
    """A script's first statement after its docstring is the delegate() call (and its import):
    anything before it would run in the job's process, then again in the server's fork."""
    import ast

    scripts = sorted((SRC.parent / "workflow" / "scripts").glob("*.py"))
    assert scripts
    bad = []
    for f in scripts:
        body = ast.parse(f.read_text()).body
        if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
            body = body[1:]                      # the docstring
        ok = (len(body) >= 2 and isinstance(body[0], ast.ImportFrom) and body[0].module == "opnav.core.jobserver"
              and isinstance(body[1], ast.Expr) and ast.unparse(body[1].value).startswith("delegate("))
        if not ok:
            bad.append(f.name)
    assert not bad, f"workflow scripts without delegate() first: {bad}"


def test_a_benchmark_of_a_job_the_server_ran_reads_its_logs_cpu_and_memory(tmp_path):
    """Snakemake's benchmark file measures the job's own process tree, which holds only the
    client when the work ran in the server's fork: the manuscript's run information and the
    SLURM resources read the job's log instead (opnav.core.snakeio.benchmark_table)."""
    from opnav.core.snakeio import benchmark_table

    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "logs").mkdir()
    head = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    for name, line in (("served", "cpu_s=12.500 user_s=12.000 sys_s=0.500 max_rss_mb=321.0 job_server=1"),
                       ("own", "cpu_s=12.500 user_s=12.000 sys_s=0.500 max_rss_mb=321.0")):
        (tmp_path / "benchmarks" / f"{name}.tsv").write_text(head + "14.0\t0:00:14\t25.1\t30\t20\t21\t0\t0\t5\t0.08\n")
        (tmp_path / "logs" / f"{name}.log").write_text(f"2026-12-07 INFO started\n2026-12-07 INFO job resources: {line}\n")
    served = benchmark_table(tmp_path / "benchmarks" / "served.tsv")
    own = benchmark_table(tmp_path / "benchmarks" / "own.tsv")
    assert served["cpu_time"].iloc[0] == 12.5 and served["max_rss"].iloc[0] == 321.0 and served["s"].iloc[0] == 14.0
    assert own["cpu_time"].iloc[0] == 0.08 and own["max_rss"].iloc[0] == 25.1      # its own process: as measured
