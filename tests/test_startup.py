"""A job's start-up CPU (opnav.core.startup, issue 47 item 1): the job log says it, the
resource line carries it for benchmarks/job_costs.py, a lazy import inside the work still
counts as start-up, and a kernel's first call counts as loading when the cache had it and
as compiling when it did not."""

import json
import os
import re
import subprocess
import sys
import textwrap

from conftest import REPO

JOB = textwrap.dedent("""\
    import sys
    from opnav.core.snakeio import script_context, stand_in

    smk = stand_in(log=[sys.argv[1]])
    with script_context(smk) as log:
        import fractions, decimal, statistics   # a lazy import inside the work
        log.info("work done")
""")
KERNEL = textwrap.dedent("""\
    import json
    from opnav.core import startup
    startup.begin()
    from opnav.core.compiled import kernel

    @kernel
    def f(x):
        return x * 2.0 + 1.0

    f(1.0)
    print(json.dumps(startup.seconds()))
""")
FIELDS = re.compile(r"startup_cpu_s=([0-9.]+) before_work_s=([0-9.]+) imports_s=([0-9.]+) "
                    r"kernel_load_s=([0-9.]+) kernel_compile_s=([0-9.]+)")


def _env(*paths):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO / "src"), *map(str, paths)]))
    env.pop("NUMBA_CACHE_DIR", None)
    return env


def test_job_log_has_the_startup_line_and_fields(tmp_path):
    log = tmp_path / "job.log"
    subprocess.run([sys.executable, "-c", JOB, str(log)], env=_env(), check=True, timeout=120)
    text = log.read_text()
    assert re.search(r"started: [0-9.]+ CPU-s before the work", text), text
    assert "job start-up:" in text and "work done" in text, text
    m = FIELDS.search(text)
    assert m, text
    total, before, imports, load, comp = map(float, m.groups())
    assert before > 0 and load == 0 and comp == 0
    assert imports > 0, "the import inside the work was not timed"
    assert abs(total - (before + imports + load)) < 2e-3


def test_a_kernel_call_counts_as_compiling_then_as_loading(tmp_path):
    """First process: an empty cache, the call compiles (compile CPU, no load); second
    process: the call loads (load CPU, no compile)."""
    (tmp_path / "kmod.py").write_text(KERNEL)
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, str(tmp_path / "kmod.py")], cwd=tmp_path, env=_env(tmp_path),
                             capture_output=True, text=True, check=True, timeout=300)
        runs.append(json.loads(out.stdout.splitlines()[-1]))
    first, second = runs
    assert first["compile_s"] > 0 and first["kernels_s"] == 0, first
    assert second["kernels_s"] > 0 and second["compile_s"] == 0, second
    assert second["startup_s"] == second["before_work_s"] + second["imports_s"] + second["kernels_s"]


def test_job_costs_reads_the_startup_figures(tmp_path):
    """benchmarks/job_costs.startup_lines: the mean over the jobs' logs, compile_kernels'
    logs left out (its compiling is its work), a log without the figure not counted."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    from job_costs import startup_lines, startups

    line = ("2026-12-04 INFO job resources: cpu_s=9.0 user_s=8.0 sys_s=1.0 max_rss_mb=100.0 "
            "startup_cpu_s={} before_work_s={} imports_s={} kernel_load_s={} kernel_compile_s=0.000\n")
    for rel, vals in (("landing/logs/mc_a.log", (1.0, 0.5, 0.25, 0.25)),
                      ("approach/logs/mc_b.log", (0.6, 0.4, 0.2, 0.0)),
                      ("kernels/logs/compile_landing.log", (9.0, 1.0, 0.0, 8.0))):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(line.format(*vals))
    (tmp_path / "landing" / "logs" / "old.log").write_text("job resources: cpu_s=1.0 user_s=1.0 sys_s=0.0 "
                                                           "max_rss_mb=1.0\n")
    assert sorted(p for p, *_ in startups(tmp_path)) == ["approach/logs/mc_b.log", "landing/logs/mc_a.log"]
    text = "\n".join(startup_lines(tmp_path))
    assert "mean 0.80 s over 2 jobs (before the work 0.45, imports during it 0.23, making kernels callable 0.12)" in text, text
