"""The console a newcomer reads during a build: Snakemake's job headers without the lists
nobody reads.

Every rule lists the package's source files it depends on as inputs (so editing one reruns
it: ``src()``, ``with_kernels()`` in workflow/rules/common.smk), up to 31 of them, and a
first build gives every job the reason "Missing output files: " with each output. The
header Snakemake prints then runs to thousands of characters a job. :func:`quiet_job_headers`
puts a filter on Snakemake's logger that, for the console and Snakemake's own log file
alike, prints a job's source-file inputs as their count and its other inputs and a reason's
file lists as their first few names and a count. Nothing else changes: the rule name, its
outputs, log, wildcards, threads and resources print as before (an error's block keeps every
input), and what reruns a job does not depend on what is printed.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from pathlib import Path

#: a reason's file list prints at most this many names, a job's inputs (other than source files) this many
REASON_FILES = 3
INPUT_FILES = 6

_FILTER_NAME = "opnav-quiet-job-headers"


def _under(path: str, roots: tuple[str, ...]) -> bool:
    p = os.path.abspath(str(path).split(" (")[0])  # format_files appends flags: "x (pipe)"
    return any(p == r or p.startswith(r + os.sep) for r in roots)


def short_inputs(inputs: Iterable[str], roots: Iterable[str | Path], max_files: int = INPUT_FILES) -> list[str]:
    """A job's inputs as the header prints them: those under ``roots`` (the repository's
    source files: package, workflow, captions, manuscript frame) replaced by one item that
    counts them, and the rest cut to its first ``max_files`` and a count."""
    roots = tuple(os.path.abspath(r) for r in roots)
    inputs = list(inputs)
    keep = [f for f in inputs if not _under(f, roots)]
    n = len(inputs) - len(keep)
    if len(keep) > max_files + 1:
        keep = keep[:max_files] + [f"{len(keep) - max_files} more files"]
    return keep + ([f"{n} source file{'s' if n != 1 else ''} of the repository"] if n else [])


def short_reason(reason: str, max_files: int = REASON_FILES) -> str:
    """A job's reason with each file list cut to its first ``max_files`` names and a count
    (``Missing output files: a, b, c and 12 more``)."""
    parts = []
    for clause in str(reason).split("; "):
        head, sep, files = clause.partition(": ")
        names = files.split(", ") if sep else []
        if len(names) > max_files + 1:
            clause = f"{head}: {', '.join(names[:max_files])} and {len(names) - max_files} more"
        parts.append(clause)
    return "; ".join(parts)


class _QuietJobHeaders(logging.Filter):
    def __init__(self, roots: tuple[str, ...]):
        super().__init__(_FILTER_NAME)
        self.roots = roots

    def filter(self, record: logging.LogRecord) -> bool:
        if str(getattr(record, "event", "")).lower().endswith("job_info"):
            if isinstance(getattr(record, "input", None), list):
                record.input = short_inputs(record.input, self.roots)
            if isinstance(getattr(record, "reason", None), str):
                record.reason = short_reason(record.reason)
        return True


def quiet_job_headers(source_roots: Iterable[str | Path]) -> None:
    """Install the filter on Snakemake's logger (once: a second call replaces the first)."""
    from snakemake.logging import logger

    for f in [f for f in logger.filters if getattr(f, "name", "") == _FILTER_NAME]:
        logger.removeFilter(f)
    logger.addFilter(_QuietJobHeaders(tuple(os.path.abspath(r) for r in source_roots)))

