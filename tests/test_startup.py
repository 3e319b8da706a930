"""A job's start-up CPU (opnav.core.startup, issue 47 item 1): the job log says it, the
resource line carries it for benchmarks/job_costs.py, and a kernel's first call counts as
loading when the cache had it and as compiling when it did not. The imports are timed by
the benchmark with ``python -X importtime`` (job_costs --imports), not inside the job (issue
56 item 2): importing in a job leaves ``builtins.__import__`` as it was."""

import json
import os
import re
import subprocess
import sys
import textwrap

import pytest

from conftest import REPO

JOB = textwrap.dedent("""\
    import builtins, sys
    from opnav.core.snakeio import script_context, stand_in

    builtin_import = builtins.__import__
    smk = stand_in(log=[sys.argv[1]])
    with script_context(smk) as log:
        import fractions, decimal, statistics   # a lazy import inside the work
        log.info("work done; import patched: %s", builtins.__import__ is not builtin_import)
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
FIELDS = re.compile(r"startup_cpu_s=([0-9.]+) before_work_s=([0-9.]+) "
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
    assert "job start-up:" in text and "work done; import patched: False" in text, text
    m = FIELDS.search(text)
    assert m, text
    total, before, load, comp = map(float, m.groups())
    assert before > 0 and load == 0 and comp == 0
    assert abs(total - (before + load)) < 2e-3
    assert "kernels_loaded=" not in text, "a job that called no kernel counts none"


@pytest.mark.slow  # two processes that import numba, one compiles: ~2 CPU-s (in-process: test_numba_adapter) (issue 56: the default run <= 90 s)
def test_a_kernel_call_counts_as_compiling_then_as_loading(tmp_path):
    """First process: an empty cache, the call compiles (compile CPU; numba's import and the
    dispatcher are making it callable); second process: the call loads (load CPU, no compile)."""
    (tmp_path / "kmod.py").write_text(KERNEL)
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, str(tmp_path / "kmod.py")], cwd=tmp_path, env=_env(tmp_path),
                             capture_output=True, text=True, check=True, timeout=300)
        runs.append(json.loads(out.stdout.splitlines()[-1]))
    first, second = runs
    assert first["compile_s"] > 0 and first["kernels_s"] > 0, first
    assert second["kernels_s"] > 0 and second["compile_s"] == 0, second
    assert second["startup_s"] == second["before_work_s"] + second["kernels_s"]


def test_job_costs_reads_the_startup_figures(tmp_path):
    """benchmarks/job_costs.startup_lines: the mean over the jobs' logs, compile_kernels'
    logs left out (its compiling is its work), a log without the figure not counted, a log of
    a commit before issue 56 (with the jobs' own ``imports_s=``) still read."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    from job_costs import startup_lines, startups

    line = ("2026-12-04 INFO job resources: cpu_s=9.0 user_s=8.0 sys_s=1.0 max_rss_mb=100.0 "
            "startup_cpu_s={} before_work_s={} kernel_load_s={} kernel_compile_s=0.000\n")
    old = ("2026-12-04 INFO job resources: cpu_s=9.0 user_s=8.0 sys_s=1.0 max_rss_mb=100.0 "
           "startup_cpu_s={} before_work_s={} imports_s=0.1 kernel_load_s={} kernel_compile_s=0.000\n")
    for rel, form, vals in (("landing/logs/mc_a.log", line, (1.0, 0.75, 0.25)),
                            ("approach/logs/mc_b.log", old, (0.6, 0.6, 0.0)),
                            ("kernels/logs/compile_landing.log", line, (9.0, 1.0, 8.0))):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(form.format(*vals))
    (tmp_path / "landing" / "logs" / "old.log").write_text("job resources: cpu_s=1.0 user_s=1.0 sys_s=0.0 "
                                                           "max_rss_mb=1.0\n")
    assert sorted(p for p, *_ in startups(tmp_path)) == ["approach/logs/mc_b.log", "landing/logs/mc_a.log"]
    text = "\n".join(startup_lines(tmp_path))
    assert "mean 0.80 s over 2 jobs (before the work 0.68, making kernels callable 0.12)" in text, text


def test_job_costs_times_a_scripts_imports_with_importtime(tmp_path):
    """benchmarks/job_costs --imports: a script's top-level imports run under ``python -X
    importtime``; the figure is the top-level imports' cumulative time, each module's self
    time summed (a made-up report, then a real run of a two-import script)."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    from job_costs import import_costs, parse_importtime, script_imports

    report = ("import time: self [us] | cumulative | imported package\n"
              "import time:       100 |        100 |   a.io\n"
              "import time:       300 |        400 |   a.sub\n"
              "import time:       200 |        600 | a\n"
              "import time:        50 |         50 | b\n")
    total, selfs = parse_importtime(report)
    assert abs(total - 0.65) < 1e-9 and selfs["a.sub"] == 0.3 and selfs["a"] == 0.2
    script = tmp_path / "job.py"
    script.write_text("from __future__ import annotations\nimport json\nfrom fractions import Fraction\n"
                      "def work():\n    import colorsys\n")
    assert script_imports(script) == "import json\nfrom fractions import Fraction"
    (name, ms, selfs), = import_costs([script])
    assert name == "job.py" and ms > 0 and "fractions" in selfs and "colorsys" not in selfs
