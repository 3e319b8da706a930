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

PACKAGE = ('from opnav.core.compiled import register_kernel_modules\n'
           'register_kernel_modules(__name__, ("kp.ka", "kp.kb"))\n')
CALLEE = "from opnav.core.compiled import kernel\n\n\n@kernel\ndef f(x):\n    return x + {}\n"
CALLER = textwrap.dedent("""\
    from opnav.core.compiled import kernel, warms
    from kp.ka import f


    @kernel
    def g(x):
        return f(x) * 2.0


    @warms
    def _warm():
        g(1.0)
""")
RUN = textwrap.dedent("""\
    import json, opnav.core.compiled as c
    import kp.ka, kp.kb
    seconds = c.warm(("kp.ka", "kp.kb"))
    print(json.dumps({"g": kp.kb.g(1.0), "modules": sorted(seconds), **c.cache_stats()}))
""")


def _run(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO / "src"), str(tmp_path)]))
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", RUN], cwd=tmp_path, env=env, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


@pytest.mark.slow  # four processes that import numba and compile: 5-6 CPU-s
def test_cache_loaded_by_the_next_process_and_invalidated_by_a_callee_change(tmp_path):
    kp = tmp_path / "kp"
    kp.mkdir()
    (kp / "__init__.py").write_text(PACKAGE)
    (kp / "ka.py").write_text(CALLEE.format("1.0"))
    (kp / "kb.py").write_text(CALLER)
    first = _run(tmp_path)
    # g and, as its callee, f
    assert first == {"g": 4.0, "modules": ["kp.kb"], "loaded": 0, "compiled": 2}
    assert _run(tmp_path) == {"g": 4.0, "modules": ["kp.kb"], "loaded": 1, "compiled": 0}
    assert list((kp / "__pycache__").glob("kb.g-*.nbi")), "cache written beside the source"
    # the callee's module changes, the caller's file does not: g must see the new f
    (kp / "ka.py").write_text(CALLEE.format("10.0"))
    assert _run(tmp_path) == {"g": 22.0, "modules": ["kp.kb"], "loaded": 0, "compiled": 2}
    assert _run(tmp_path) == {"g": 22.0, "modules": ["kp.kb"], "loaded": 1, "compiled": 0}


def test_kernel_sources_are_the_registered_modules_files():
    """Each paper package registers its own kernel modules; a paper's set is the core's and its
    own, found as files without importing them."""
    import opnav.approach  # noqa: F401  (registers its kernel modules)
    import opnav.landing  # noqa: F401  (registers its kernel modules)

    for package in ("opnav.approach", "opnav.landing"):
        names = compiled.kernel_modules(package)
        files = compiled.kernel_sources(package)
        assert files[:2] == [REPO / "src" / "opnav" / "core" / "compiled.py",
                             REPO / "src" / "opnav" / "core" / "numba_adapter.py"]
        assert len(files) == 2 + len(names) and names[0] == "opnav.core.rotations"
        assert all(n.startswith((package + ".", "opnav.core.")) for n in names), names
        for name, path in zip(names, files[2:]):
            assert path.is_file(), name
            assert path.relative_to(REPO / "src").with_suffix("").parts == tuple(name.split("."))
    assert set(compiled.kernel_modules("opnav.approach")) & set(compiled.kernel_modules("opnav.landing")) \
        == {"opnav.core.rotations"}


def test_a_registration_outside_the_package_is_refused():
    with pytest.raises(ValueError, match="not modules of the package"):
        compiled.register_kernel_modules("opnav.approach", ("opnav.landing.ekf",))
    with pytest.raises(KeyError, match="registered no kernel modules"):
        compiled.kernel_modules("opnav.nothing")


DIGEST = "import opnav.landing, opnav.core.compiled as c; print(c.kernel_set_digest('opnav.landing'))"


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
    import opnav.landing  # noqa: F401  (registers its kernel modules)

    assert compiled.COMPILE_ESTIMATES not in compiled.kernel_sources("opnav.landing") and estimates.is_file()
    first = _digest(src)
    data = json.loads(estimates.read_text())
    data["cpu_s"]["opnav.landing.linalg"] = 99.0
    estimates.write_text(json.dumps(data))
    assert _digest(src) == first
    linalg = src / "opnav" / "landing" / "linalg.py"
    linalg.write_text(linalg.read_text() + "\n# edited\n")
    assert _digest(src) != first


def test_compile_estimates_name_registered_modules():
    import opnav.approach  # noqa: F401  (registers its kernel modules)
    import opnav.landing  # noqa: F401  (registers its kernel modules)

    estimate = compiled.compile_cpu_s()
    assert set(estimate) <= set(compiled.kernel_modules()) and all(v > 0 for v in estimate.values())


ONE_SIGNATURE = textwrap.dedent("""\
    import json, opnav.core.compiled as c
    import opnav.landing.linalg, opnav.landing.descent
    c.warm(("opnav.landing.linalg", "opnav.landing.descent"))
    print(json.dumps({f"{k.py_func.__module__}.{k.__name__}": [str(s) for s in k._dispatcher.signatures]
                      for k in c._KERNELS if k._dispatcher is not None}))
""")


@pytest.mark.slow  # a process that compiles linalg and descent: 5-6 CPU-s
def test_one_signature_per_kernel_when_kernels_pass_constants(tmp_path):
    """descent calls ``cholesky_in_place(L, 3)`` and ``cho_solve(L, 3, x)``, linalg's warm-up
    calls them with an int64: one compiled signature each, not a second one for the literal 3
    (each a full compile; numba_adapter._unliteral_calls)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", ONE_SIGNATURE], env=env, capture_output=True, text=True,
                         check=True)
    sigs = json.loads(out.stdout.splitlines()[-1])
    assert "opnav.landing.linalg.cholesky_in_place" in sigs
    assert {k: v for k, v in sigs.items() if len(v) != 1} == {}


def test_every_module_with_kernels_is_registered_by_its_package():
    """A module of the package that defines a ``@kernel`` or a ``@warms`` function is in its
    package's registered kernel modules (read from the sources: no import, no numba), so its
    kernels' cache is keyed by its package's kernel set and the compile job warms it. The
    warm-up coverage itself (a warmed cache compiles nothing) is test_kernel_references' (slow)."""
    import ast

    import opnav.approach  # noqa: F401  (registers its kernel modules)
    import opnav.landing  # noqa: F401  (registers its kernel modules)

    registered = set(compiled.kernel_modules())
    src = REPO / "src"
    holding = set()
    for f in (src / "opnav").rglob("*.py"):
        tree = ast.parse(f.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef) and any(
                    (d.id if isinstance(d, ast.Name) else getattr(getattr(d, "func", None), "id", "")) in ("kernel", "warms")
                    for d in node.decorator_list):
                holding.add(".".join(f.relative_to(src).with_suffix("").parts))
                break
    holding.discard("opnav.core.compiled")  # the decorators' own home
    assert holding, "no kernel found: the scan is broken"
    assert sorted(holding - registered) == []
