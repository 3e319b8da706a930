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
