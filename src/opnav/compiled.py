"""Compiled kernels: the project's one way to compile a hot equation, and the cache warm-up.

Every hot equation has one home: a plain-Python function over scalars and small
arrays, decorated with :func:`kernel` (numba ``njit`` with an on-disk cache). The
Python-level API calls it; the paper's own definition (CasADi H, LAPACK SVD) stays
as the reference that tests compare against.

Compilation cost: numba writes each compiled signature to an on-disk cache
(``__pycache__`` beside the source, or ``NUMBA_CACHE_DIR``), keyed by the source
file, so a job only loads what an earlier job compiled. :func:`warm` compiles every
registered kernel once (the workflow's first rule calls it, so parallel jobs do not
all compile) and reports how long each module took.

A module that holds kernels registers a warm-up function with :func:`warms`; the
function calls each of its kernels once with arguments of the types the pipeline
passes (float64 arrays, int64 indices), so the cached signatures are the ones used.
"""
from __future__ import annotations

import importlib
import time
from typing import Callable

from numba import njit

#: Modules holding kernels, imported by :func:`warm` (each registers its warm-up on import).
KERNEL_MODULES: tuple[str, ...] = ()

_WARMUPS: dict[str, Callable[[], None]] = {}


def kernel(fn=None, **options):
    """``numba.njit`` with the project's settings: on-disk cache, no fastmath (IEEE
    results, so compiled and reference paths agree to round-off), the GIL released.

    Use as ``@kernel`` or ``@kernel(parallel=False)``.
    """
    settings = {"cache": True, "fastmath": False, "nogil": True, **options}
    if fn is None:
        return lambda f: njit(**settings)(f)
    return njit(**settings)(fn)


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
