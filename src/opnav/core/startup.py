"""A job's start-up CPU: what a workflow job pays before (and beside) its own work.

Every Snakemake job is a fresh interpreter that runs Snakemake's preamble (it unpickles
the ``snakemake`` object), imports what its script imports, and, if it calls compiled
kernels, sets numba's target up and loads the kernels' cached signatures. With about 80
jobs in the quick profile that fixed cost decides how long the profile takes (issue 47).
This module measures it, in process CPU seconds (``time.process_time``):

``before_work_s``
    the CPU of the process when :func:`begin` is called (``script_context`` calls it as
    the job's work starts): interpreter start-up, the preamble, the script's imports;
``imports_s``
    CPU spent in imports after that (a lazy ``import`` inside the work still costs
    start-up, so moving an import into a function does not hide it): ``builtins.__import__``
    is wrapped by :func:`begin`, and only the outermost import of a nest is timed;
``kernels_s``
    CPU spent making compiled kernels callable (:mod:`opnav.core.compiled`: numba's
    dispatch on a signature it has not seen in this process, which sets numba's target
    up on the first call and loads the signature from the on-disk cache). A dispatch that
    compiled instead (an empty cache: rule ``compile_kernels``' own work) is ``compile_s``,
    reported beside the start-up, not in it.

An import inside a kernel load counts once, under ``kernels_s`` (:func:`overhead` nests).
The sum is ``startup_s``; :func:`line` is the job log's line and :func:`fields` the
``key=value`` text appended to the log's resource line (``benchmarks/job_costs.py`` and
``benchmarks/bench_pipeline.py`` read it).
"""

from __future__ import annotations

import builtins
import contextlib
import sys
import time
from typing import Iterator

_state = {"before_work_s": None, "imports_s": 0.0, "kernels_s": 0.0, "compile_s": 0.0}
_depth = 0
_import = builtins.__import__


@contextlib.contextmanager
def overhead(kind: str) -> Iterator[dict]:
    """Add the CPU seconds of the block to ``kind`` (``imports_s``, ``kernels_s`` or
    ``compile_s``), unless an enclosing block is already timing (nested overhead counts
    once). The block may name another kind before it ends: ``with overhead(k) as o:
    ... o["kind"] = "compile_s"``."""
    global _depth
    holder = {"kind": kind}
    if _depth:
        _depth += 1
        try:
            yield holder
        finally:
            _depth -= 1
        return
    _depth = 1
    t0 = time.process_time()
    try:
        yield holder
    finally:
        _depth = 0
        _state[holder["kind"]] += time.process_time() - t0


def _loaded(name, fromlist) -> bool:
    """Whether ``import name`` / ``from name import *fromlist`` needs no module loaded."""
    mod = sys.modules.get(name)
    if mod is None:
        return False
    return not fromlist or all(hasattr(mod, f) for f in fromlist if f != "*")


def _timed_import(name, globals=None, locals=None, fromlist=(), level=0):
    # the common case first: a plain import of a module already loaded costs nothing
    if _depth or level == 0 and _loaded(name, fromlist):
        return _import(name, globals, locals, fromlist, level)
    with overhead("imports_s"):
        return _import(name, globals, locals, fromlist, level)


def begin() -> float:
    """Mark the start of the job's own work: record the process's CPU so far and time
    the imports from now on. Returns ``before_work_s``. Calling it again keeps the first mark."""
    if _state["before_work_s"] is None:
        _state["before_work_s"] = time.process_time()
        if builtins.__import__ is _import:
            builtins.__import__ = _timed_import
    return _state["before_work_s"]


def seconds() -> dict[str, float]:
    """``before_work_s``, ``imports_s``, ``kernels_s`` and their sum ``startup_s``, and
    ``compile_s`` (CPU seconds; before :func:`begin`, ``before_work_s`` is the CPU so far)."""
    before = _state["before_work_s"]
    out = {"before_work_s": time.process_time() if before is None else before,
           "imports_s": _state["imports_s"], "kernels_s": _state["kernels_s"], "compile_s": _state["compile_s"]}
    out["startup_s"] = out["before_work_s"] + out["imports_s"] + out["kernels_s"]
    return out


def fields() -> str:
    """``startup_cpu_s=... before_work_s=... imports_s=... kernel_load_s=... kernel_compile_s=...``
    for the resource line."""
    s = seconds()
    return (f"startup_cpu_s={s['startup_s']:.3f} before_work_s={s['before_work_s']:.3f} "
            f"imports_s={s['imports_s']:.3f} kernel_load_s={s['kernels_s']:.3f} "
            f"kernel_compile_s={s['compile_s']:.3f}")


def line() -> str:
    """The job log's sentence on its start-up CPU."""
    s = seconds()
    return (f"job start-up: {s['startup_s']:.2f} CPU-s ({s['before_work_s']:.2f} before the work: "
            f"interpreter, Snakemake's preamble, the script's imports; {s['imports_s']:.2f} imports "
            f"during the work; {s['kernels_s']:.2f} making compiled kernels callable)"
            + (f"; {s['compile_s']:.2f} CPU-s compiling kernels besides" if s["compile_s"] else ""))
