"""opnav.core.compiled's on-disk cache: a second process loads what the first compiled, and a
kernel that calls another module's kernel is recompiled when that module changes (numba
alone keys a cached function by its own file, and would load the old callee's code)."""

import json
import os
import subprocess
import sys
import textwrap

import pytest
from conftest import REPO

from opnav.core import compiled

CALLEE = "from opnav.core.compiled import kernel\n\n\n@kernel\ndef f(x):\n    return x + {}\n"
CALLER = textwrap.dedent("""\
    from opnav.core.compiled import kernel, warms
    from ka import f


    @kernel
    def g(x):
        return f(x) * 2.0


    @warms
    def _warm():
        g(1.0)
""")
RUN = textwrap.dedent("""\
    import json, opnav.core.compiled as c
    c.KERNEL_MODULES = ("ka", "kb")
    seconds = c.warm()
    import kb
    print(json.dumps({"g": kb.g(1.0), "modules": sorted(seconds), **c.cache_stats()}))
""")


def _run(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO / "src"), str(tmp_path)]))
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", RUN], cwd=tmp_path, env=env, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


@pytest.mark.slow  # four processes that import numba and compile: 5-6 CPU-s
def test_cache_loaded_by_the_next_process_and_invalidated_by_a_callee_change(tmp_path):
    (tmp_path / "ka.py").write_text(CALLEE.format("1.0"))
    (tmp_path / "kb.py").write_text(CALLER)
    first = _run(tmp_path)
    # g and, as its callee, f
    assert first == {"g": 4.0, "modules": ["kb"], "loaded": 0, "compiled": 2}
    assert _run(tmp_path) == {"g": 4.0, "modules": ["kb"], "loaded": 1, "compiled": 0}
    assert list((tmp_path / "__pycache__").glob("kb.g-*.nbi")), "cache written beside the source"
    # the callee's module changes, the caller's file does not: g must see the new f
    (tmp_path / "ka.py").write_text(CALLEE.format("10.0"))
    assert _run(tmp_path) == {"g": 22.0, "modules": ["kb"], "loaded": 0, "compiled": 2}
    assert _run(tmp_path) == {"g": 22.0, "modules": ["kb"], "loaded": 1, "compiled": 0}


def test_kernel_sources_are_the_registered_modules_files():
    files = compiled.kernel_sources()
    assert files[0] == REPO / "src" / "opnav" / "core" / "compiled.py"
    assert len(files) == 1 + len(compiled.KERNEL_MODULES)
    for name, path in zip(compiled.KERNEL_MODULES, files[1:]):
        assert path.is_file(), name
        assert path.relative_to(REPO / "src").with_suffix("").parts == tuple(name.split("."))


DIGEST = "import opnav.core.compiled as c; print(c.kernel_set_digest())"


def _digest(src):
    env = dict(os.environ, PYTHONPATH=str(src))
    return subprocess.run([sys.executable, "-c", DIGEST], env=env, capture_output=True, text=True,
                          check=True).stdout.strip()


def test_compile_estimates_outside_the_kernel_set_digest(tmp_path):
    """A new compile estimate (the progress lines') recompiles nothing; a kernel edit recompiles."""
    import shutil
    src = tmp_path / "src"
    shutil.copytree(REPO / "src" / "opnav", src / "opnav",
                    ignore=shutil.ignore_patterns("__pycache__", "*.npz", "*.nbi", "*.nbc"))
    estimates = src / "opnav" / compiled.COMPILE_ESTIMATES.relative_to(REPO / "src" / "opnav")
    assert compiled.COMPILE_ESTIMATES not in compiled.kernel_sources() and estimates.is_file()
    first = _digest(src)
    data = json.loads(estimates.read_text())
    data["cpu_s"]["opnav.landing.linalg"] = 99.0
    estimates.write_text(json.dumps(data))
    assert _digest(src) == first
    linalg = src / "opnav" / "landing" / "linalg.py"
    linalg.write_text(linalg.read_text() + "\n# edited\n")
    assert _digest(src) != first


def test_compile_estimates_name_registered_modules():
    estimate = compiled.compile_cpu_s()
    assert set(estimate) <= set(compiled.KERNEL_MODULES) and all(v > 0 for v in estimate.values())


ONE_SIGNATURE = textwrap.dedent("""\
    import json, opnav.core.compiled as c
    c.warm(("opnav.landing.linalg", "opnav.landing.descent"))
    print(json.dumps({f"{k.py_func.__module__}.{k.__name__}": [str(s) for s in k._dispatcher.signatures]
                      for k in c._KERNELS if k._dispatcher is not None}))
""")


@pytest.mark.slow  # a process that compiles linalg and descent: 5-6 CPU-s
def test_one_signature_per_kernel_when_kernels_pass_constants(tmp_path):
    """descent calls ``cholesky_in_place(L, 3)`` and ``cho_solve(L, 3, x)``, linalg's warm-up
    calls them with an int64: one compiled signature each, not a second one for the literal 3
    (each a full compile; compiled._unliteral_calls)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", ONE_SIGNATURE], env=env, capture_output=True, text=True,
                         check=True)
    sigs = json.loads(out.stdout.splitlines()[-1])
    assert "opnav.landing.linalg.cholesky_in_place" in sigs
    assert {k: v for k, v in sigs.items() if len(v) != 1} == {}
