"""A job's start-up CPU: what a workflow job pays before (and beside) its own work.

Every Snakemake job is a fresh interpreter that runs Snakemake's preamble (it unpickles
the ``snakemake`` object), imports what its script imports, and, if it calls compiled
kernels, sets numba up and loads the kernels' cached signatures. With about 80 jobs in the
quick profile that fixed cost decides how long the profile takes (issue 47). This module
counts it, in process CPU seconds (``time.process_time``), without changing how anything
runs:

``before_work_s``
    the CPU of the process when :func:`begin` is called (``script_context`` calls it as
    the job's work starts): interpreter start-up, the preamble, the script's imports;
``kernels_s``
    CPU spent making compiled kernels callable (:mod:`opnav.core.compiled`: numba imported and
    a kernel's dispatcher made on its first use, each signature loaded from the on-disk cache).
    A kernel compiled instead (an empty cache: rule ``compile_kernels``' own work) is
    ``compile_s``, reported beside the start-up, not in it.

Which modules a job's imports cost is measured outside the jobs, with ``python -X
importtime`` (``benchmarks/job_costs.py --imports``): timing every import inside every job
meant replacing ``builtins.__import__`` (issue 56 item 2). A lazy import inside a job's work
is therefore part of its work here.

Nested blocks count once, under the outermost one's kind (:func:`overhead`, :func:`start`):
a callee loaded while its caller compiles is compile time. The sum is ``startup_s``;
:func:`line` is the job log's line and :func:`fields` the ``key=value`` text appended to the
log's resource line (``benchmarks/job_costs.py`` and ``benchmarks/bench_pipeline.py`` read it).
"""

from __future__ import annotations

import contextlib
import time
from typing import Iterator

_state = {"before_work_s": None, "kernels_s": 0.0, "compile_s": 0.0, "wait_s": 0.0}
_open: list = []  # [kind, CPU at start] of the outermost open block, then one entry per nested block


def start(kind: str) -> list:
    """Open a block of ``kind`` (``kernels_s`` or ``compile_s``); only the outermost is timed.
    Returns the block's ``[kind, ...]``: setting its first item before it closes names another
    kind (a cache load that missed is compile time)."""
    entry = [kind, time.process_time() if not _open else None]
    _open.append(entry)
    return entry


def stop() -> None:
    """Close the innermost open block; the outermost adds its CPU seconds to its kind."""
    kind, t0 = _open.pop()
    if not _open:
        _state[kind] += time.process_time() - t0


@contextlib.contextmanager
def overhead(kind: str) -> Iterator[list]:
    """Add the CPU seconds of the block to ``kind``, unless an enclosing block is already
    timing (nested overhead counts once, under the outer block's kind). The block may name
    another kind before it ends: ``with overhead(k) as o: ... o[0] = "compile_s"``."""
    entry = start(kind)
    try:
        yield entry
    finally:
        stop()


def _cpu_so_far() -> float:
    """This process's CPU-s, plus, in a job run by the build's job server, its client's before
    it delegated (:func:`opnav.core.jobserver.client_cpu`): the job's start-up either way."""
    from opnav.core.jobserver import client_cpu

    return time.process_time() + sum(client_cpu())


def begin() -> float:
    """Mark the start of the job's own work: record the process's CPU so far (:func:`_cpu_so_far`).
    Returns ``before_work_s``. Calling it again keeps the first mark."""
    if _state["before_work_s"] is None:
        _state["before_work_s"] = _cpu_so_far()
    return _state["before_work_s"]


def seconds() -> dict[str, float]:
    """``before_work_s``, ``kernels_s`` and their sum ``startup_s``, and ``compile_s`` (CPU
    seconds; before :func:`begin`, ``before_work_s`` is the CPU so far); ``wait_s``, the wall
    seconds spent waiting for a background warm-up (:func:`wait_for_kernels`)."""
    before = _state["before_work_s"]
    out = {"before_work_s": _cpu_so_far() if before is None else before,
           "kernels_s": _state["kernels_s"], "compile_s": _state["compile_s"], "wait_s": _state["wait_s"]}
    out["startup_s"] = out["before_work_s"] + out["kernels_s"]
    return out


def fields() -> str:
    """``startup_cpu_s=... before_work_s=... kernel_load_s=... kernel_compile_s=...`` for the
    resource line."""
    s = seconds()
    return (f"startup_cpu_s={s['startup_s']:.3f} before_work_s={s['before_work_s']:.3f} "
            f"kernel_load_s={s['kernels_s']:.3f} kernel_compile_s={s['compile_s']:.3f}")


def line() -> str:
    """The job log's sentence on its start-up CPU."""
    s = seconds()
    return (f"job start-up: {s['startup_s']:.2f} CPU-s ({s['before_work_s']:.2f} before the work: "
            f"interpreter, Snakemake's preamble, the script's imports; {s['kernels_s']:.2f} making "
            "compiled kernels callable)"
            + (f"; {s['compile_s']:.2f} CPU-s compiling kernels besides" if s["compile_s"] else ""))


#: names a background warm-up of the kernel cache this process may wait for, as JSON:
#: ``{"pid", "progress", "package", "cache"}`` (tests/conftest.py starts one for a whole test run,
#: so the kernels compile on the second core while the first tests run): its process, a file whose
#: first line is ``todo:`` and the kernel modules it will warm, then one line per module once its
#: warm-up has filled the cache, the ``opnav`` package folder it warms and its ``NUMBA_CACHE_DIR``
WARMING_ENV = "OPNAV_KERNELS_WARMING"


def wait_for_kernels(module: str, poll_s: float = 0.05) -> float:
    """Before a kernel of ``module`` is first made callable: where :data:`WARMING_ENV` names a
    warm-up of this very package and kernel cache (not a copy's, not another cache's) that is
    still running, will warm ``module`` and has not yet, wait until it has (or has ended), so
    this process loads the kernels instead of compiling them a second time. Returns the seconds
    waited (also summed in ``seconds()["wait_s"]``)."""
    import json
    import os
    import sys

    try:
        spec = json.loads(os.environ.get(WARMING_ENV) or "null")
        pid, progress, package, cache = int(spec["pid"]), spec["progress"], spec["package"], spec["cache"]
    except (ValueError, TypeError, KeyError):
        return 0.0
    here = sys.modules.get("opnav")
    if here is None or os.path.realpath(os.path.dirname(here.__file__)) != os.path.realpath(package) \
            or os.environ.get("NUMBA_CACHE_DIR", "") != cache:
        return 0.0                   # another copy of the sources or another cache: its own kernels
    t0 = time.perf_counter()
    while True:
        try:
            with open(progress) as f:
                lines = f.read().splitlines()
            if lines and lines[0].startswith("todo:") and (module not in lines[0].split()[1:] or module in lines[1:]):
                break                # not one it warms, or warmed
        except OSError:
            pass
        try:
            with open(f"/proc/{pid}/stat", "rb") as f:
                if f.read().rsplit(b")", 1)[1].split()[0] == b"Z":
                    break            # ended, not yet reaped
        except (OSError, IndexError):
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                break                # ended: what it did not warm, this process compiles
            except OSError:
                pass
        time.sleep(poll_s)
    waited = time.perf_counter() - t0
    _state["wait_s"] += waited
    return waited
