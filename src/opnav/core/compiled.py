"""Compiled kernels: the project's one way to compile a hot equation, and the cache warm-up.

Every hot equation has one home: a plain-Python function over scalars and small
arrays, decorated with :func:`kernel` (numba ``njit`` with an on-disk cache). The
Python-level API calls it; the paper's own definition (CasADi H, LAPACK SVD) stays
as the reference that tests compare against.

Which modules hold kernels: each package says so for its own modules, from its
``__init__`` (:func:`register_kernel_modules`; ``opnav.core``, ``opnav.approach``,
``opnav.landing``), so this module names none and the core depends on no paper. A package's
kernels may call its own kernels and the core's, never another paper's (the import layers,
tests/test_import_layers.py).

Compilation cost: numba writes each compiled signature to an on-disk cache
(``__pycache__`` beside the source, or ``NUMBA_CACHE_DIR``), so a job only loads what
an earlier job compiled. :func:`warm` compiles the given kernel modules once (the
workflow's first rules, ``compile_kernels``, one per paper, call it, so parallel jobs do not
all compile) and reports how long each module took; :func:`cache_stats` counts what this
process loaded and what it compiled (every job's log says it).

Cache validity: numba keys a cached function by its own file's content only, so a
kernel that calls a kernel of another module would be loaded with the callee's old
code compiled in after the callee's file changed. A kernel's cache entry here is
keyed by the content of every kernel module its package registered and of the core's
as well (:func:`kernel_set_digest`): editing a landing kernel module recompiles every
landing kernel, once, and no approach kernel.

A kernel becomes a numba dispatcher on its first call (:class:`LazyKernel`), so a job
that imports a kernel module for its plain-Python parts (a table, a figure) does not
import numba; a job that calls kernels loads only the signatures it calls. The CPU of making
kernels callable and of compiling is counted into the job's start-up
(:mod:`opnav.core.startup`). Every use of numba beyond its public API (the cache stamp, one
signature per argument type, the proxy's rebinding) is in :mod:`opnav.core.numba_adapter`,
pinned to the numba version by its test.

A module that holds kernels registers a warm-up function with :func:`warms`; the
function calls each of its kernels once with arguments of the types the pipeline
passes (float64 arrays, int64 indices), so the cached signatures are the ones used.
"""
from __future__ import annotations

import functools
import hashlib
import json
import sys
import time
from pathlib import Path
from typing import Callable, Iterable

from opnav.core import numba_adapter, startup

#: package -> the modules it registered (:func:`register_kernel_modules`), in its order
_PACKAGES: dict[str, tuple[str, ...]] = {}
#: the package whose kernel modules every package's kernels may call (this module's own)
CORE = __name__.rpartition(".")[0]
_WARMUPS: dict[str, Callable[[], None]] = {}
_KERNELS: list = []  # every LazyKernel made by kernel(), for cache_stats


def register_kernel_modules(package: str, modules: Iterable[str]) -> None:
    """Record the modules of ``package`` (already imported: its ``__init__`` calls this) that
    hold kernels, or whose source a kernel folds in (constants): their sources key the cache
    of the package's kernels and the workflow's compile job imports and warms them."""
    modules = tuple(modules)
    bad = [m for m in modules if not m.startswith(package + ".")]
    if bad:
        raise ValueError(f"register_kernel_modules({package!r}): {bad} are not modules of the package")
    _PACKAGES[package] = modules
    kernel_set_digest.cache_clear()


def _owner(module: str) -> str | None:
    """The registered package ``module`` belongs to (the longest registered prefix), or None."""
    owners = [p for p in _PACKAGES if module == p or module.startswith(p + ".")]
    return max(owners, key=len) if owners else None


def kernel_modules(package: str | None = None) -> tuple[str, ...]:
    """The registered kernel modules the jobs of ``package`` may run: the core's, then the
    package's own; without ``package``, those of every package registered so far."""
    if package is None:
        return tuple(m for p in _PACKAGES for m in _PACKAGES[p])
    if package not in _PACKAGES:
        raise KeyError(f"{package} registered no kernel modules (import it first; registered: "
                       f"{', '.join(_PACKAGES) or 'none'})")
    return tuple(dict.fromkeys([*_PACKAGES.get(CORE, ()), *_PACKAGES[package]]))


def _source(module: str) -> Path:
    """The source file of registered ``module``, found from its package's folder without
    importing it (``p.x.y`` -> ``<p>/x/y.py`` or ``<p>/x/y/__init__.py``)."""
    package = _owner(module)
    base = Path(sys.modules[package].__file__).parent.joinpath(*module[len(package) + 1:].split("."))
    return base / "__init__.py" if base.is_dir() else base.with_suffix(".py")


def kernel_sources(package: str | None = None) -> list[Path]:
    """This file, :mod:`opnav.core.numba_adapter`, and the source file of every module of
    :func:`kernel_modules` (``package``)."""
    here = Path(__file__).resolve()
    return [here, here.with_name("numba_adapter.py"), *(_source(m) for m in kernel_modules(package))]


@functools.lru_cache(maxsize=None)
def kernel_set_digest(package: str = CORE) -> str:
    """SHA-256 of the content of :func:`kernel_sources` (``package``; computed once a
    process): the stamp of the cache entries of that package's kernels (a kernel of a module
    no package registered: the core's)."""
    h = hashlib.sha256()
    for path in kernel_sources(package):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def _timed_load(load):
    """A signature loaded from the on-disk cache, its CPU counted as the job's start-up; a
    load that finds nothing (numba compiles next) counts as compile time."""
    with startup.overhead("kernels_s") as block:
        got = load()
        if got is None:
            block[0] = "compile_s"
        return got


def _compile_started():
    startup.start("compile_s")


class LazyKernel:
    """A kernel before its first use: the plain function (``py_func``) and the settings of
    the numba dispatcher it becomes when first called (or asked for a dispatcher attribute,
    ``stats``, ``signatures``...). A job that imports a kernel module and calls none of its
    kernels (a table, a figure, the manuscript) does not import numba (0.2-0.4 CPU-s).

    Once made, the dispatcher takes the proxy's place in the namespace of every loaded
    module that holds the proxy (``from m import k`` included: :func:`numba_adapter.rebind`),
    so later calls go to numba straight; a reference kept elsewhere (a tuple, a partial made
    before the first call) goes through :meth:`__call__`, one Python call more. numba types a
    proxy it meets as a global of a kernel it compiles as the dispatcher's type."""

    def __init__(self, f, settings: dict):
        self.py_func = f
        self._settings = settings
        self._dispatcher = None
        functools.update_wrapper(self, f)

    def dispatcher(self):
        """The numba dispatcher (made on first use)."""
        d = self._dispatcher
        if d is None:
            d = self._dispatcher = _dispatcher(self.py_func, self._settings)
            numba_adapter.rebind(self, d, self.py_func.__module__, __name__.split(".", 1)[0])
        return d

    def __call__(self, *args):
        return self.dispatcher()(*args)

    def __getattr__(self, name):  # only for names the proxy does not have: the dispatcher's
        if name.startswith("__") or name in ("_dispatcher", "_settings", "py_func"):
            raise AttributeError(name)
        return getattr(self.dispatcher(), name)

    def __repr__(self):
        return f"<kernel {self.py_func.__module__}.{self.py_func.__qualname__}>"


def _dispatcher(f, settings: dict):
    """The numba dispatcher of kernel ``f`` (:func:`numba_adapter.dispatcher`): its cache
    stamped with its package's :func:`kernel_set_digest`, its loads and compiles timed."""
    startup.wait_for_kernels(f.__module__)  # a test run's background warm-up of this module, if any
    with startup.overhead("kernels_s"):
        numba_adapter.register_proxy_type(LazyKernel, LazyKernel.dispatcher)
        numba_adapter.install_compile_timer(_compile_started, startup.stop)
        return numba_adapter.dispatcher(f, settings, kernel_set_digest(_owner(f.__module__) or CORE), _timed_load)


def kernel(fn=None, **options):
    """``numba.njit`` with the project's settings: on-disk cache, no fastmath (IEEE
    results, so compiled and reference paths agree to round-off), the GIL released; made
    on first use (:class:`LazyKernel`: importing a kernel module does not import numba).

    Use as ``@kernel`` or ``@kernel(parallel=False)``.
    """
    settings = {"cache": True, "fastmath": False, "nogil": True, **options}

    def make(f):
        proxy = LazyKernel(f, settings)
        _KERNELS.append(proxy)
        return proxy

    return make if fn is None else make(fn)


def warms(fn: Callable[[], None]) -> Callable[[], None]:
    """Register ``fn`` (no arguments) as its module's warm-up: it calls each kernel once."""
    _WARMUPS[fn.__module__] = fn
    return fn


#: The progress lines' estimates (CPU-s each kernel module's warm-up takes to compile on an
#: empty cache, and their source): a data file, not one of :func:`kernel_sources`, so a new
#: measurement changes no cache key and recompiles nothing. A module not listed: 2 CPU-s.
COMPILE_ESTIMATES = Path(__file__).resolve().parents[1] / "data" / "compile_cpu_s.json"


def compile_cpu_s() -> dict[str, float]:
    """Estimated compile CPU-s per kernel module (:data:`COMPILE_ESTIMATES`)."""
    return {name: float(v) for name, v in json.loads(COMPILE_ESTIMATES.read_text())["cpu_s"].items()}


def warm(modules: Iterable[str] | None = None,
         progress: Callable[[str], None] | None = None) -> dict[str, float]:
    """Run the warm-ups of the kernel modules ``modules`` (default: every registered one), in
    that order; each must be imported already (its ``@warms`` runs on import: the caller imports
    them, ``workflow/scripts/compile_kernels.py`` say). Return wall seconds per module (compile
    time on an empty cache, load time on a filled one). ``progress`` (``log.info``, say) gets a
    line as each module starts, with its estimate (:func:`compile_cpu_s`), and one as it ends,
    with the CPU it took and the signatures it compiled and loaded."""
    names = list(kernel_modules() if modules is None else modules)
    missing = [n for n in names if n not in sys.modules]
    if missing:
        raise RuntimeError(f"warm: import the kernel modules first: {', '.join(missing)}")
    todo = [n for n in names if n in _WARMUPS]
    say = progress or (lambda text: None)
    estimate = compile_cpu_s()
    total = sum(estimate.get(n, 2.0) for n in todo)
    say(f"kernels: {len(todo)} modules to warm up, about {total:.0f} CPU-s to compile on an empty cache")
    seconds: dict[str, float] = {}
    for i, name in enumerate(todo, 1):
        say(f"[{i}/{len(todo)}] {name}: warming up (about {estimate.get(name, 2.0):.1f} CPU-s "
            "if nothing is cached)")
        before, c0, t0 = cache_stats(), time.process_time(), time.perf_counter()
        _WARMUPS[name]()
        seconds[name] = time.perf_counter() - t0
        after = cache_stats()
        say(f"[{i}/{len(todo)}] {name}: {time.process_time() - c0:.1f} CPU-s, {seconds[name]:.1f} s wall, "
            f"{after['compiled'] - before['compiled']} signatures compiled, "
            f"{after['loaded'] - before['loaded']} loaded")
    return seconds


def used() -> bool:
    """Whether this process made any kernel callable (called it, or asked for its dispatcher)."""
    return any(k._dispatcher is not None for k in _KERNELS)


def cache_stats() -> dict[str, int]:
    """Kernel signatures this process took from the on-disk cache (``loaded``) and
    compiled itself (``compiled``, callees compiled for a caller included): after the
    workflow's ``compile_kernels`` a job should compile none."""
    made = [k._dispatcher for k in _KERNELS if k._dispatcher is not None]
    return {"loaded": sum(sum(d.stats.cache_hits.values()) for d in made),
            "compiled": sum(sum(d.stats.cache_misses.values()) for d in made)}

