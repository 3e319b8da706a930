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

A module that holds kernels registers a warm-up function with :func:`warms`; the
function calls each of its kernels once with arguments of the types the pipeline
passes (float64 arrays, int64 indices), so the cached signatures are the ones used.
"""
from __future__ import annotations

import functools
import hashlib
import importlib
import importlib.util
import time
from pathlib import Path
from typing import Callable

#: Modules holding kernels, imported by :func:`warm` (each registers its warm-up on import).
KERNEL_MODULES: tuple[str, ...] = ("opnav.approach.kalman", "opnav.approach.ekf", "opnav.approach.smoother",
                                    "opnav.approach.em", "opnav.approach.augmented",
                                    "opnav.core.rotations", "opnav.landing.measurement", "opnav.landing.ekf",
                                    "opnav.landing.kernels",
                                    "opnav.landing.descent", "opnav.landing.imu")

_WARMUPS: dict[str, Callable[[], None]] = {}
_KERNELS: list = []  # every dispatcher made by kernel(), for cache_stats


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


def kernel(fn=None, **options):
    """``numba.njit`` with the project's settings: on-disk cache, no fastmath (IEEE
    results, so compiled and reference paths agree to round-off), the GIL released.

    Use as ``@kernel`` or ``@kernel(parallel=False)``.
    """
    settings = {"cache": True, "fastmath": False, "nogil": True, **options}

    def make(f):
        from numba import njit

        dispatcher = njit(**settings)(f)
        if settings["cache"]:
            dispatcher._cache = _kernel_cache_type()(dispatcher.py_func)  # keyed by the kernel set too
        _KERNELS.append(dispatcher)
        return dispatcher

    return make if fn is None else make(fn)


def warms(fn: Callable[[], None]) -> Callable[[], None]:
    """Register ``fn`` (no arguments) as its module's warm-up: it calls each kernel once."""
    _WARMUPS[fn.__module__] = fn
    return fn


def warm(modules: tuple[str, ...] | None = None) -> dict[str, float]:
    """Import the kernel modules and run their warm-ups; return seconds per module
    (compile time on an empty cache, load time on a filled one)."""
    seconds: dict[str, float] = {}
    for name in KERNEL_MODULES if modules is None else modules:
        importlib.import_module(name)
    for name, fn in sorted(_WARMUPS.items()):
        t0 = time.perf_counter()
        fn()
        seconds[name] = time.perf_counter() - t0
    return seconds


def cache_stats() -> dict[str, int]:
    """Kernel signatures this process took from the on-disk cache (``loaded``) and
    compiled itself (``compiled``, callees compiled for a caller included): after the
    workflow's ``compile_kernels`` a job should compile none."""
    return {"loaded": sum(sum(d.stats.cache_hits.values()) for d in _KERNELS),
            "compiled": sum(sum(d.stats.cache_misses.values()) for d in _KERNELS)}

