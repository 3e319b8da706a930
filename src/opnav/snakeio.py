"""Glue for the thin ``workflow/scripts`` wrappers.

:func:`script_context` sends stderr/stdout and the ``logging`` module to the
rule's log file, and a failing job's traceback too (Snakemake then shows one
line naming the log); :func:`mock_snakemake` builds a stand-in ``snakemake`` object
so a script can be run by hand for debugging, e.g.::

    python workflow/scripts/landing_tables.py   # uses mock_snakemake defaults
"""

from __future__ import annotations

import contextlib
import logging
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Iterator


@contextlib.contextmanager
def script_context(snakemake) -> Iterator[logging.Logger]:
    """Redirect output to ``snakemake.log[0]`` (if any) and yield a logger.

    An exception inside the block is logged with its traceback to the log file
    and turned into ``SystemExit("<rule> failed: <error> (traceback in <log>)")``.
    """
    log_path = snakemake.log[0] if len(getattr(snakemake, "log", [])) else None
    logger = logging.getLogger("opnav")
    if log_path is None:
        logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s")
        yield logger
        return
    Path(log_path).parent.mkdir(parents=True, exist_ok=True)
    with open(log_path, "w") as fh:
        handler = logging.StreamHandler(fh)
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
        old_err, old_out = sys.stderr, sys.stdout
        sys.stderr = sys.stdout = fh
        try:
            yield logger
        except Exception as exc:
            # the traceback goes to the rule's log; Snakemake shows one line naming it
            logger.error("job failed", exc_info=True)
            fh.flush()
            rule = getattr(snakemake, "rule", None) or Path(sys.argv[0]).stem or "job"
            what = " ".join(f"{type(exc).__name__}: {exc}".split())
            raise SystemExit(f"{rule} failed: {what} (traceback in {log_path})") from None
        finally:
            sys.stderr, sys.stdout = old_err, old_out
            logger.removeHandler(handler)


def mock_snakemake(input=None, output=None, params=None, log=None, wildcards=None,
                   threads: int = 1, config: dict | None = None) -> SimpleNamespace:
    """A minimal stand-in for the ``snakemake`` object of a script directive."""

    def ns(x):
        if x is None:
            return _Named([], {})
        if isinstance(x, dict):
            return _Named(list(x.values()), x)
        return _Named(list(x), {})

    if config is None:
        from opnav.config import load_config

        config = load_config()
    return SimpleNamespace(input=ns(input), output=ns(output), params=ns(params),
                           log=ns(log), wildcards=ns(wildcards), threads=threads,
                           config=config)


class CorruptIntermediate(ValueError):
    """An intermediate file is truncated or unreadable; the message names it and
    the command that rebuilds it."""


def corrupt_intermediate(path, exc: BaseException) -> CorruptIntermediate:
    """The error for an unreadable intermediate ``path`` (raise it ``from exc``)."""
    why = " ".join(f"{type(exc).__name__}: {exc}".split())
    return CorruptIntermediate(
        f"intermediate file {path} is truncated or corrupt ({why}); rebuild it with "
        f"`snakemake --cores 2 --force {path}` (plus your --configfile options), then rerun")


def save_pickle(path, obj) -> None:
    """Pickle ``obj`` to ``path`` atomically (complete or absent)."""
    import pickle

    from opnav.tables import atomic_target

    with atomic_target(path) as tmp, open(tmp, "wb") as fh:
        pickle.dump(obj, fh)


def load_pickle(path):
    """Unpickle an intermediate; a truncated or corrupt file raises
    :class:`CorruptIntermediate` naming it."""
    import pickle

    try:
        with open(path, "rb") as fh:
            return pickle.load(fh)
    except FileNotFoundError:
        raise
    except (EOFError, pickle.UnpicklingError, ValueError, TypeError, AttributeError, ImportError,
            IndexError, KeyError, OSError) as exc:
        raise corrupt_intermediate(path, exc) from exc


class _Named(list):
    """A list whose items are also attributes, like Snakemake's Namedlist."""

    def __init__(self, items, names):
        super().__init__(items)
        for k, v in names.items():
            setattr(self, k, v)


#: What a copy of the workflow needs (not results/ or .snakemake/).
WORKFLOW_PARTS = ("Snakefile", "config", "workflow", "src", "paper", "profiles")


def copy_workflow(repo: Path, dst: Path) -> Path:
    """Copy the workflow of checkout ``repo`` into ``dst`` (for tests and benchmarks
    that run snakemake in a scratch directory)."""
    import shutil

    for name in WORKFLOW_PARTS:
        p = Path(repo) / name
        if p.is_dir():
            shutil.copytree(p, Path(dst) / name, ignore=shutil.ignore_patterns("__pycache__", "*.pdf"))
        elif p.exists():
            shutil.copy2(p, Path(dst) / name)
    return Path(dst)
