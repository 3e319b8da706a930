"""Compiled kernels: the project's one way to compile a hot equation, and the cache warm-up.

Every hot equation has one home: a plain-Python function over scalars and small
arrays, decorated with :func:`kernel` (numba ``njit`` with an on-disk cache). The
Python-level API calls it; the paper's own definition (CasADi H, LAPACK SVD) stays
as the reference that tests compare against.

Compilation cost: numba writes each compiled signature to an on-disk cache
(``__pycache__`` beside the source, or ``NUMBA_CACHE_DIR``), so a job only loads what
an earlier job compiled. :func:`warm` compiles every registered kernel once (the
workflow's first rule, ``compile_kernels``, calls it, so parallel jobs do not all
compile) and reports how long each module took; :func:`cache_stats` counts what this
process loaded and what it compiled (every job's log says it).

Cache validity: numba keys a cached function by its own file's content only, so a
kernel that calls a kernel of another module would be loaded with the callee's old
code compiled in after the callee's file changed. A kernel's cache entry here is
keyed by the content of every kernel module as well (:func:`kernel_set_digest`):
editing any kernel module recompiles every kernel, once.

A kernel becomes a numba dispatcher on its first call (:class:`LazyKernel`), so a job
that imports a kernel module for its plain-Python parts (a table, a figure) does not
import numba; a job that calls kernels loads only the signatures it calls. Each dispatch
that loads or compiles is timed into the job's start-up (:mod:`opnav.core.startup`).

A module that holds kernels registers a warm-up function with :func:`warms`; the
function calls each of its kernels once with arguments of the types the pipeline
passes (float64 arrays, int64 indices), so the cached signatures are the ones used.
"""
from __future__ import annotations

import functools
import hashlib
import importlib
import importlib.util
import json
import sys
import time
from pathlib import Path
from typing import Callable

from opnav.core import startup

#: Modules holding kernels, imported by :func:`warm` (each registers its warm-up on import).
KERNEL_MODULES: tuple[str, ...] = ("opnav.approach.kalman", "opnav.approach.ekf", "opnav.approach.smoother",
                                    "opnav.approach.em", "opnav.approach.augmented",
                                    "opnav.core.rotations", "opnav.landing.measurement", "opnav.landing.linalg",
                                    "opnav.landing.ekf", "opnav.landing.ekf_update",
                                    "opnav.landing.planning.layout", "opnav.landing.planning.geometry",
                                    "opnav.landing.planning.depth",
                                    "opnav.landing.planning.screens", "opnav.landing.planning.hmetrics",
                                    "opnav.landing.planning.information", "opnav.landing.planning.search",
                                    "opnav.landing.planning.warmup",
                                    "opnav.landing.descent", "opnav.landing.imu")

_WARMUPS: dict[str, Callable[[], None]] = {}
_KERNELS: list = []  # every LazyKernel made by kernel(), for cache_stats


def kernel_sources(modules: tuple[str, ...] | None = None) -> list[Path]:
    """This file and the source file of every kernel module (``KERNEL_MODULES``), found
    without importing them (``opnav.x.y`` -> ``<package>/x/y.py``)."""
    root = Path(__file__).resolve().parents[1]  # the opnav package
    out = [Path(__file__).resolve()]
    for name in KERNEL_MODULES if modules is None else modules:
        parts = name.split(".")
        if parts[0] != root.name:
            out.append(Path(importlib.util.find_spec(name).origin))
            continue
        base = root.joinpath(*parts[1:])
        out.append(base / "__init__.py" if base.is_dir() else base.with_suffix(".py"))
    return out


@functools.lru_cache(maxsize=None)
def kernel_set_digest() -> str:
    """SHA-256 of the content of :func:`kernel_sources` (computed once a process)."""
    h = hashlib.sha256()
    for path in kernel_sources():
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


@functools.lru_cache(maxsize=None)
def _kernel_cache_type():
    """numba's ``FunctionCache`` whose entries are stamped with :func:`kernel_set_digest`
    beside numba's own stamp (the function's file), so a change in a called kernel's
    module invalidates them. Built on first use: importing this module does not import
    numba (the Snakefile reads :func:`kernel_sources` at parse time)."""
    from numba.core import caching

    class Stamp:
        def get_source_stamp(self):
            return (super().get_source_stamp(), kernel_set_digest())

    class Impl(caching.CompileResultCacheImpl):
        # numba's own order: NUMBA_CACHE_DIR, else __pycache__ beside the source if
        # writable, else the user-wide cache directory
        _locator_classes = [type(f"KernelSet{c.__name__}", (Stamp, c), {})
                            for c in (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                                      caching.UserWideCacheLocator)]

    return type("KernelCache", (caching.FunctionCache,), {"_impl_class": Impl})


def _timed_dispatch(compile_for_args):
    """numba's dispatch of a call whose argument types this process has not met yet (the
    target set up on the first, the signature loaded from the cache or compiled), its CPU
    counted as the job's start-up if it loaded, as compile time if it compiled
    (:func:`opnav.core.startup.overhead`); numba's C dispatcher looks ``_compile_for_args``
    up on the instance, so the wrapper sees every miss."""

    dispatcher = compile_for_args.__self__

    @functools.wraps(compile_for_args)
    def timed(*args, **kws):
        with startup.overhead("kernels_s") as spent:
            misses = sum(dispatcher.stats.cache_misses.values())
            try:
                return compile_for_args(*args, **kws)
            finally:
                if sum(dispatcher.stats.cache_misses.values()) > misses:  # compiled, not loaded
                    spent["kind"] = "compile_s"

    return timed


class LazyKernel:
    """A kernel before its first use: the plain function (``py_func``) and the settings of
    the numba dispatcher it becomes when first called (or asked for a dispatcher attribute,
    ``stats``, ``signatures``...). A job that imports a kernel module and calls none of its
    kernels (a table, a figure, the manuscript) does not import numba (0.2-0.4 CPU-s).

    Once made, the dispatcher takes the proxy's place in the namespace of every loaded
    module that holds the proxy (``from m import k`` included), so later calls go to numba
    straight; a reference kept elsewhere (a tuple, a partial made before the first call)
    goes through :meth:`__call__`, one Python call more. numba types a proxy it meets as a
    global of a kernel it compiles as the dispatcher's type (:func:`_typeof_lazy`)."""

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
            _rebind(self, d)
        return d

    def __call__(self, *args):
        return self.dispatcher()(*args)

    def __getattr__(self, name):  # only for names the proxy does not have: the dispatcher's
        if name.startswith("__") or name in ("_dispatcher", "_settings", "py_func"):
            raise AttributeError(name)
        return getattr(self.dispatcher(), name)

    def __repr__(self):
        return f"<kernel {self.py_func.__module__}.{self.py_func.__qualname__}>"


def _rebind(proxy: LazyKernel, d) -> None:
    """Put dispatcher ``d`` where ``proxy`` is a module global (its own module, and every
    loaded module that imported it by name)."""
    home = proxy.py_func.__module__
    for name, mod in list(sys.modules.items()):
        if mod is None or not (name == home or name.split(".", 1)[0] == "opnav"):
            continue
        ns = getattr(mod, "__dict__", None)
        if ns is None:
            continue
        for key, value in list(ns.items()):
            if value is proxy:
                ns[key] = d


@functools.lru_cache(maxsize=None)
def _register_typeof() -> None:
    """numba's ``typeof`` of a :class:`LazyKernel` (a global of a kernel being compiled,
    or an argument): its dispatcher's type."""
    from numba.core.typing.typeof import typeof_impl

    @typeof_impl.register(LazyKernel)
    def _typeof_lazy(val, c):
        return typeof_impl(val.dispatcher(), c)


def _dispatcher(f, settings: dict):
    """The numba dispatcher of kernel ``f``: numba's on-disk cache keyed by the kernel set
    too, its dispatch misses timed (:func:`_timed_dispatch`)."""
    from numba import njit

    _register_typeof()
    d = njit(**settings)(f)
    if settings["cache"]:
        d._cache = _kernel_cache_type()(d.py_func)  # keyed by the kernel set too
    d._compile_for_args = _timed_dispatch(d._compile_for_args)
    d.get_call_template = _unliteral_calls(d.get_call_template)
    return d


def _unliteral_calls(get_call_template):
    """numba's typing of a call to this kernel from another kernel, with the argument types
    made non-literal: numba would otherwise compile the callee once more for every constant
    a caller passes (``cholesky_shifted(S, 12, ...)``: ``Literal[int](12)``, a tuple holding a
    ``0``, a ``True`` flag), each such copy a full compile, and with ``n`` a constant LLVM
    unrolls the callee's loops completely (``cholesky_shifted`` for n = 12: most of the
    landing kernels' compile, docs/performance.md). One signature per argument type; the
    arithmetic is the same IEEE operations in the same order (no fastmath), so the results
    are the same bits."""
    from numba.core import types

    @functools.wraps(get_call_template)
    def typed(args, kws):
        return get_call_template(tuple(types.unliteral(a) for a in args),
                                 {k: types.unliteral(v) for k, v in kws.items()})

    return typed


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


def warm(modules: tuple[str, ...] | None = None,
         progress: Callable[[str], None] | None = None) -> dict[str, float]:
    """Import the kernel modules ``modules`` (default ``KERNEL_MODULES``) and run their
    warm-ups, in that order; return wall seconds per module (compile time on an empty
    cache, load time on a filled one). ``progress`` (``log.info``, say) gets a line as each
    module starts, with its estimate (:func:`compile_cpu_s`), and one as it ends, with
    the CPU it took and the signatures it compiled and loaded."""
    names = list(KERNEL_MODULES if modules is None else modules)
    for name in names:
        importlib.import_module(name)
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


def cache_stats() -> dict[str, int]:
    """Kernel signatures this process took from the on-disk cache (``loaded``) and
    compiled itself (``compiled``, callees compiled for a caller included): after the
    workflow's ``compile_kernels`` a job should compile none."""
    made = [k._dispatcher for k in _KERNELS if k._dispatcher is not None]
    return {"loaded": sum(sum(d.stats.cache_hits.values()) for d in made),
            "compiled": sum(sum(d.stats.cache_misses.values()) for d in made)}

