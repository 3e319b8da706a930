"""Glue for the thin ``workflow/scripts`` wrappers.

:func:`script_context` sends stderr/stdout and the ``logging`` module to the
rule's log file, and a failing job's traceback too (Snakemake then shows one
line naming the log); :func:`mock_snakemake` builds a stand-in ``snakemake`` object
(the real rule's job, built from the ``Snakefile``) so a script can be run by hand
for debugging, e.g.::

    python workflow/scripts/landing_tables.py --configfile config/quick.yaml
"""

from __future__ import annotations

import contextlib
import gc
import logging
import resource
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Iterator

from opnav.core import compiled, startup


@contextlib.contextmanager
def script_context(snakemake, console: bool = False) -> Iterator[logging.Logger]:
    """Redirect output to ``snakemake.log[0]`` (if any) and yield a logger.

    An exception inside the block is logged with its traceback to the log file
    and turned into ``SystemExit("<rule> failed: <error> (traceback in <log>)")``.
    A job that succeeds ends its log with one :func:`resource_line` (the whole
    process's CPU seconds and peak memory, start-up and imports included), which
    ``benchmarks/job_costs.py`` sums per rule.

    ``console``: the logger's lines also go to the job's own stderr, which Snakemake shows
    on its console (a long job's progress, rule ``compile_kernels``), each prefixed with the
    rule and its wildcards (jobs run side by side).
    """
    if type(snakemake).__module__.startswith("snakemake"):   # a workflow job, not a script run by hand
        from opnav.core.runguard import stop_with_parent

        stop_with_parent()  # the job ends with Snakemake, even a SIGKILLed one (opnav.core.runguard)
    startup.begin()  # the job's own work starts here (opnav.core.startup)
    log_path = snakemake.log[0] if len(getattr(snakemake, "log", [])) else None
    logger = logging.getLogger("opnav")
    if log_path is None:
        logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s")
        yield logger
        return
    Path(log_path).parent.mkdir(parents=True, exist_ok=True)
    # A job is one short-lived process whose imported libraries' objects (numpy, scipy,
    # pandas, matplotlib, CasADi) live until it ends: frozen, the cyclic collector no
    # longer walks them at every full collection nor at exit (about 0.2 CPU-s a job).
    gc.freeze()
    with open(log_path, "w") as fh:
        handler = logging.StreamHandler(fh)
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
        old_err, old_out = sys.stderr, sys.stdout
        shown = _console_handler(snakemake, old_err) if console else None
        if shown is not None:
            logger.addHandler(shown)
        sys.stderr = sys.stdout = fh
        try:
            logger.info("started: %.2f CPU-s before the work (interpreter, Snakemake's preamble, imports)",
                        startup.seconds()["before_work_s"])
            yield logger
            logger.info(startup.line())
            logger.info(resource_line())
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
            if shown is not None:
                logger.removeHandler(shown)
            gc.freeze()  # and what the job imported or made since: the process ends now


def _console_handler(snakemake, stream) -> logging.Handler:
    """A handler writing ``<rule> (<wildcards>): <message>`` lines to ``stream`` (flushed each)."""
    rule = getattr(snakemake, "rule", None) or Path(sys.argv[0]).stem or "job"
    wc = getattr(snakemake, "wildcards", None)
    items = wc.items() if hasattr(wc, "items") else []
    label = rule + (f" ({', '.join(f'{k}={v}' for k, v in items)})" if items else "")
    handler = logging.StreamHandler(stream)
    handler.setFormatter(logging.Formatter(f"{label}: %(message)s"))
    return handler


#: prefix of the last log line of a successful job (:func:`resource_line`)
RESOURCE_PREFIX = "job resources:"


def resource_line() -> str:
    """``job resources: cpu_s=<user+sys> user_s=... sys_s=... max_rss_mb=...`` of this
    process so far, its finished child processes included (LaTeX, say), and in a job the build's
    job server ran (:mod:`opnav.core.jobserver`) its client process's CPU before it delegated:
    ``resource.getrusage``; the peak memory is ``VmHWM`` of ``/proc/self/status``
    (``ru_maxrss`` keeps the forking parent's peak across ``exec`` on Linux), else
    ``ru_maxrss`` (KiB on Linux). A job that called compiled kernels also gets the kernel
    signatures it loaded from numba's cache and compiled itself
    (:func:`opnav.core.compiled.cache_stats`; after rule ``compile_kernels``, none compiled),
    and last the job's start-up CPU (:func:`opnav.core.startup.fields`)."""
    from opnav.core.jobserver import client_cpu

    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    c_user, c_sys = client_cpu()       # a job the build's job server ran: its client's CPU too
    user, sys_ = me.ru_utime + kids.ru_utime + c_user, me.ru_stime + kids.ru_stime + c_sys
    rss_kib = float(me.ru_maxrss)
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                rss_kib = float(line.split()[1])
    out = (f"{RESOURCE_PREFIX} cpu_s={user + sys_:.3f} user_s={user:.3f} "
           f"sys_s={sys_:.3f} max_rss_mb={rss_kib / 1024:.1f}")
    if c_user or c_sys:  # its peak memory counts the job server's pages it shares
        out += " job_server=1"
    if compiled.used():  # a job that called kernels
        stats = compiled.cache_stats()
        out += f" kernels_loaded={stats['loaded']} kernels_compiled={stats['compiled']}"
    return f"{out} {startup.fields()}"


def resource_fields(log_path) -> dict | None:
    """The last :func:`resource_line` of a job's log as numbers (``cpu_s``, ``user_s``, ``sys_s``,
    ``max_rss_mb``; ``job_server`` 1 where the job ran in the build's job server), or None."""
    import re

    try:
        text = Path(log_path).read_text(errors="replace")
    except OSError:
        return None
    lines = [ln for ln in text.splitlines() if RESOURCE_PREFIX in ln]
    if not lines:
        return None
    out = {k: float(v) for k, v in re.findall(r"(\w+)=([0-9.]+)", lines[-1].split(RESOURCE_PREFIX, 1)[1])}
    out.setdefault("job_server", 0.0)
    return out


def benchmark_table(path):
    """A job's Snakemake ``benchmark:`` file (a one-row TSV) as a table. Where the job ran in
    the build's job server (:mod:`opnav.core.jobserver`), Snakemake measured only the job's
    own process (its client) and the work ran in the server's fork: ``cpu_time`` and
    ``max_rss`` are then its log's (``logs/<the same name>.log`` beside ``benchmarks/``:
    :func:`resource_fields`); wall time ``s`` is the job's either way."""
    import pandas as pd

    t = pd.read_csv(path, sep="\t")
    res = resource_fields(Path(path).parent.parent / "logs" / (Path(path).stem + ".log"))
    if res and res["job_server"] and len(t):
        t["cpu_time"] = res["cpu_s"]
        t["max_rss"] = res["max_rss_mb"]
    return t


def stand_in(input=None, output=None, params=None, log=None, wildcards=None,
             threads: int = 1, config: dict | None = None) -> SimpleNamespace:
    """A bare object shaped like a script's ``snakemake`` (named lists), for unit tests of
    this module's plumbing. To run a workflow script by hand use :func:`mock_snakemake`."""

    def ns(x):
        if x is None:
            return _Named([], {})
        if isinstance(x, dict):
            return _Named(list(x.values()), x)
        return _Named(list(x), {})

    return SimpleNamespace(input=ns(input), output=ns(output), params=ns(params),
                           log=ns(log), wildcards=ns(wildcards), threads=threads,
                           config={} if config is None else config)


def workflow_root(start: str | Path | None = None) -> Path:
    """The checkout holding the ``Snakefile``: ``start`` or its parents, else this
    package's checkout."""
    for base in ([Path(start).resolve()] if start else []) + [Path.cwd(), Path(__file__).resolve()]:
        for d in (base, *base.parents):
            if (d / "Snakefile").is_file() and (d / "workflow" / "rules").is_dir():
                return d
    raise FileNotFoundError("no Snakefile found above the current directory or the opnav package")


def _argv_options(argv) -> tuple[list[str], dict[str, str]]:
    """``--configfile A [B ...]`` and ``NAME=VALUE`` wildcards from a script's command line."""
    usage = "by hand a script takes [--configfile FILE ...] [NAME=VALUE ...]"
    files, wildcards, in_files = [], {}, False
    for a in argv:
        if a == "--configfile":
            in_files = True
        elif "=" in a and not a.startswith("-"):
            k, v = a.split("=", 1)
            wildcards[k] = v
            in_files = False
        elif in_files and not a.startswith("-"):
            files.append(a)
        else:
            raise SystemExit(f"unexpected argument {a!r}: {usage}")
    return files, wildcards


def mock_snakemake(rule: str, *, configfiles=(), root: str | Path | None = None,
                   argv=None, **wildcards):
    """The ``snakemake`` object the real job of ``rule`` would get, for running a script
    by hand (PyPSA-Eur's ``mock_snakemake``): the workflow (``Snakefile``, its
    ``configfile:`` and the overlays ``configfiles``, validated as in a run) is parsed
    with Snakemake's API, and the job of ``rule`` with ``wildcards`` gives ``input``,
    ``output``, ``params``, ``wildcards``, ``log``, ``threads``, ``resources`` and
    ``config``; paths are made absolute (under ``root``, the checkout by default).

    ``argv`` (a script passes ``sys.argv[1:]``) may add ``--configfile FILE ...`` and
    ``NAME=VALUE`` wildcards, which override the script's defaults::

        python workflow/scripts/landing_tables.py --configfile config/quick.yaml
        python workflow/scripts/approach_mc.py variant=roll group=headline

    See ``workflow/scripts/README.md``.
    """
    from snakemake.api import SnakemakeApi
    from snakemake.dag import DAG
    from snakemake.jobs import Job
    from snakemake.script import Snakemake
    from snakemake.settings.types import ConfigSettings, DAGSettings, ResourceSettings

    root = workflow_root(root)
    extra_files, extra_wc = _argv_options(argv or [])
    files = [Path(f) if Path(f).is_absolute() else Path.cwd() / f for f in [*configfiles, *extra_files]]
    for f in files:
        if not f.is_file():
            raise SystemExit(f"config file not found: {f}")
    wildcards = {**wildcards, **extra_wc}
    with SnakemakeApi() as api:
        wapi = api.workflow(resource_settings=ResourceSettings(),
                            config_settings=ConfigSettings(configfiles=files),
                            snakefile=root / "Snakefile", workdir=root)
        wf = wapi._workflow
        wf.dag_settings = DAGSettings()
        try:
            job_rule = wf.get_rule(rule)
        except Exception:
            raise SystemExit(f"no rule {rule!r} in {root / 'Snakefile'}") from None
        missing = sorted(set(job_rule.wildcard_names) - set(wildcards))
        if missing:
            raise SystemExit(f"rule {rule} needs the wildcard(s) {', '.join(missing)} "
                             f"(give NAME=VALUE on the command line)")
        dag = DAG(wf, rules=[job_rule], targetfiles=[], targetrules=[])
        job = Job(job_rule, dag, wildcards_dict=wildcards)
        for io in (job.input, job.output, job.log):
            for i, p in enumerate(io):
                io[i] = str(Path(p) if Path(p).is_absolute() else root / p)
        smk = Snakemake(job.input, job.output, job.params, job.wildcards, job.threads,
                        job.resources, job.log, wf.config, job_rule.name, None)
    for p in [*smk.output, *smk.log]:
        Path(p).parent.mkdir(parents=True, exist_ok=True)
    return smk


def config_exit(exc) -> None:
    """Leave the workflow (Snakefile, rule files) on config problems: their lines after
    ``ConfigError (no job was run):``, no traceback, exit status 1 (``opnav study``
    forwards these lines: :func:`opnav.cli.snakemake_error`)."""
    sys.exit(f"ConfigError (no job was run):\n{exc}")


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

    from opnav.core.tables import atomic_target

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


#: First line of an intermediate CSV written by :func:`save_csv`: its data rows and the
#: SHA-256 of the text after this line (a CSV cut inside its last row still parses).
CSV_STAMP = "# opnav-csv"


def save_csv(path, df) -> None:
    """Write the intermediate table ``df`` to ``path`` atomically, stamped (:data:`CSV_STAMP`)
    with its row count and checksum, which :func:`load_csv` checks."""
    import hashlib

    from opnav.core.tables import atomic_target

    body = df.to_csv(index=False, lineterminator="\n")
    head = f"{CSV_STAMP} rows={len(df)} sha256={hashlib.sha256(body.encode()).hexdigest()}\n"
    with atomic_target(path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as fh:
        fh.write(head + body)


def load_csv(path, **kw):
    """Read an intermediate table written by :func:`save_csv`; a missing or wrong stamp,
    row count or checksum (a cut, an edit, an older writer) raises
    :class:`CorruptIntermediate` naming the file and the rebuild command."""
    import hashlib
    import io
    import re

    import pandas as pd

    try:
        text = Path(path).read_bytes().decode("utf-8")
        head, _, body = text.partition("\n")
        m = re.fullmatch(re.escape(CSV_STAMP) + r" rows=(\d+) sha256=([0-9a-f]{64})", head)
        if not m:
            raise ValueError(f"no '{CSV_STAMP} rows=... sha256=...' first line")
        if hashlib.sha256(body.encode()).hexdigest() != m.group(2):
            raise ValueError("checksum mismatch")
        df = pd.read_csv(io.StringIO(body), **kw)
        if len(df) != int(m.group(1)):
            raise ValueError(f"{len(df)} rows, {m.group(1)} written")
        return df
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, ValueError, pd.errors.ParserError) as exc:
        raise corrupt_intermediate(path, exc) from exc


def _checked_text(path) -> tuple[str, bool]:
    """The text of the intermediate ``path`` and whether a checksum sidecar vouched for it
    (:func:`opnav.core.tables.write_checksum`); a sidecar that disagrees raises ValueError."""
    import hashlib
    import re

    from opnav.core.tables import checksum_path

    data = Path(path).read_bytes()
    side = checksum_path(path)
    if not side.exists():
        return data.decode("utf-8"), False
    m = re.fullmatch(r"sha256=([0-9a-f]{64}) bytes=(\d+)\s*", side.read_text())
    if not m:
        raise ValueError(f"unreadable checksum sidecar {side.name}")
    if len(data) != int(m.group(2)):
        raise ValueError(f"{len(data)} bytes, {m.group(2)} written (cut or edited)")
    if hashlib.sha256(data).hexdigest() != m.group(1):
        raise ValueError("checksum mismatch with its .sha256 sidecar (edited)")
    return data.decode("utf-8"), True


def load_table(path, **kw):
    """Read a table (CSV) another job wrote, checked: against its checksum sidecar where
    :func:`opnav.core.tables.write_table` wrote one, else validated (ends with a newline,
    every row as many fields as the header), so a cut or edited file raises
    :class:`CorruptIntermediate` naming it and the command that rebuilds it instead of
    losing rows silently. ``kw`` goes to :func:`pandas.read_csv`."""
    import csv
    import io

    import pandas as pd

    try:
        text, vouched = _checked_text(path)
        if not vouched:
            if text and not text.endswith("\n"):
                raise ValueError("no newline at the end (cut inside its last row?)")
            sep = kw.get("sep", ",")
            widths = {len(row) for row in csv.reader(io.StringIO(text), delimiter=sep)}
            if len(widths) > 1:
                raise ValueError(f"rows of {sorted(widths)} fields (cut or edited)")
        return pd.read_csv(io.StringIO(text), **kw)
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, ValueError, pd.errors.ParserError, csv.Error) as exc:
        raise corrupt_intermediate(path, exc) from exc


def load_json(path):
    """Read a JSON summary another job wrote, checked against its checksum sidecar where
    :func:`opnav.core.tables.write_json` wrote one; a cut, edited or unparsable file raises
    :class:`CorruptIntermediate` naming it and the rebuild command."""
    import json

    try:
        text, _ = _checked_text(path)
        return json.loads(text)
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise corrupt_intermediate(path, exc) from exc


class _Named(list):
    """A list whose items are also attributes, like Snakemake's Namedlist."""

    def __init__(self, items, names):
        super().__init__(items)
        for k, v in names.items():
            setattr(self, k, v)


#: What a copy of the workflow needs (not results/ or .snakemake/).
WORKFLOW_PARTS = ("Snakefile", "config", "workflow", "src", "paper", "profiles")


def copy_workflow(repo: Path, dst: Path, kernel_cache: bool = True) -> Path:
    """Copy the workflow of checkout ``repo`` into ``dst`` (for tests and benchmarks
    that run snakemake in a scratch directory). ``kernel_cache``: numba's cache files
    (``__pycache__/*.nbi``, ``*.nbc``) come along, so the copy loads the kernels the
    checkout compiled (entries are keyed by source content, :mod:`opnav.core.compiled`);
    without, the copy compiles them itself, as a fresh clone does. Bytecode is never
    copied."""
    import shutil

    skip = ("*.pyc", "*.pdf") if kernel_cache else ("__pycache__", "*.pdf")
    for name in WORKFLOW_PARTS:
        p = Path(repo) / name
        if p.is_dir():
            shutil.copytree(p, Path(dst) / name, ignore=shutil.ignore_patterns(*skip))
        elif p.exists():
            shutil.copy2(p, Path(dst) / name)
    return Path(dst)


def _literal(text: str):
    import ast

    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return text


def _short(value, width: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def _leaf_diff(old, new, path: str = "") -> list[str]:
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for k in sorted(set(old) | set(new), key=str):
            p = f"{path}.{k}" if path else str(k)
            if k not in old:
                out.append(f"{p}: (new) {_short(new[k])}")
            elif k not in new:
                out.append(f"{p}: {_short(old[k])} (removed)")
            else:
                out += _leaf_diff(old[k], new[k], p)
        return out
    return [] if old == new else [f"{path or 'value'}: {_short(old)} -> {_short(new)}"]


def params_change_text(only_old, only_new, limit: int = 8) -> str:
    """What changed between a job's recorded and current ``params:``, key by key.

    Snakemake records each param value as its ``repr``; its own reason text
    prints every changed value whole, before and after (a config section,
    tens of kB per job). Here each new value is paired with the recorded one
    sharing most keys, and only the differing leaves are listed
    (``mc.runs_per_job: 2 -> 1``), at most ``limit`` of them.
    """
    old = [_literal(s) for s in sorted(only_old, key=str)]
    new = [_literal(s) for s in sorted(only_new, key=str)]
    lines = []
    for n in new:
        def overlap(o):
            return len(set(o) & set(n)) if isinstance(o, dict) and isinstance(n, dict) else -1
        if old:
            o = max(old, key=overlap)
            old.remove(o)
            lines += _leaf_diff(o, n)
        else:
            lines.append(f"new param {_short(n)}")
    lines += [f"param removed: {_short(o)}" for o in old]
    more = f" (and {len(lines) - limit} more)" if len(lines) > limit else ""
    return "; ".join(lines[:limit]) + more


def compact_params_change_reasons() -> None:
    """Make Snakemake's "Params have changed" job reasons name the changed keys
    (:func:`params_change_text`) instead of dumping the values whole. Called by
    ``workflow/rules/common.smk``; a no-op if Snakemake's internals move."""
    try:
        from snakemake.persistence import ParamsChange
    except ImportError:  # pragma: no cover
        return

    def __str__(self):
        if not self:
            return "No params change"
        return params_change_text(self.only_old, self.only_new)

    ParamsChange.__str__ = __str__
