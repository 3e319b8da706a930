"""Where a Snakemake run's CPU time goes: per rule, from the jobs' logs; and what the
workflow scripts' imports cost, with ``python -X importtime``.

Every successful job ends its log with ``job resources: cpu_s=... max_rss_mb=...``
(:func:`opnav.core.snakeio.resource_line`: the whole process, interpreter start-up and
imports included). This script finds those lines under a results folder and prints,
per group of logs (the part's folder and the log name's first word: ``landing/mc``,
``studies/runs``, ...), the job count, total and largest CPU seconds and the largest
peak memory, sorted by total CPU; then the compiled kernels (``kernels_loaded=``,
``kernels_compiled=`` on the same line, :mod:`opnav.core.compiled`): how many jobs loaded
them from numba's cache, and every job but ``compile_kernels`` that compiled some
itself (a warm-up missing a signature the pipeline calls); then each job's start-up CPU
(``startup_cpu_s=`` and its parts, :mod:`opnav.core.startup`): the mean per job and the
groups whose start-up is largest.

``--imports`` measures, instead of reading logs, what each workflow script's imports cost
(the part of a job's ``before_work_s`` that is not the interpreter or Snakemake's preamble):
each script's top-level imports run in a fresh ``python -X importtime`` (the package on
``src``), and the table gives the milliseconds they took and the modules that cost the most
(self time, summed over the scripts). A lazy import inside a job's work is not seen here:
it counts as the job's work. Usage::

    python benchmarks/job_costs.py results/quick
    python benchmarks/job_costs.py results --top 20
    python benchmarks/job_costs.py --imports [--top 15]
"""

from __future__ import annotations

import argparse
import ast
import os
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

_LINE = re.compile(r"job resources: cpu_s=([0-9.]+) user_s=([0-9.]+) sys_s=([0-9.]+) max_rss_mb=([0-9.]+)")
_KERNELS = re.compile(r"kernels_loaded=(\d+) kernels_compiled=(\d+)")
# imports_s= (the jobs' own import timing) only in logs of commits before issue 56: read, not needed
_STARTUP = re.compile(r"startup_cpu_s=([0-9.]+) before_work_s=([0-9.]+) (?:imports_s=[0-9.]+ )?kernel_load_s=([0-9.]+)")
#: rule compile_kernels' logs: its compiling is its work, and its start-up is not a job's
_COMPILE_LOG = "kernels"


def _last_matches(root: Path, pattern: re.Pattern) -> list[tuple[str, re.Match]]:
    """(log path relative to ``root``, the last match of ``pattern``) of every job log that has one."""
    out = []
    for log in sorted(root.rglob("logs/*.log")):
        m = None
        for m in pattern.finditer(log.read_text(errors="replace")):
            pass
        if m:
            out.append((str(log.relative_to(root)), m))
    return out


def kernel_counts(root: Path) -> list[tuple[str, int, int]]:
    """(log path relative to ``root``, kernel signatures loaded, compiled) of every job
    log whose resource line counts kernels."""
    return [(p, int(m.group(1)), int(m.group(2))) for p, m in _last_matches(root, _KERNELS)]


def startups(root: Path) -> list[tuple[str, float, float, float]]:
    """(log path relative to ``root``, start-up CPU seconds, of them before the work, making
    kernels callable) of every job log whose resource line has them (:mod:`opnav.core.startup`;
    logs of commits before issue 47 have none), the ``compile_kernels`` jobs' aside."""
    return [(p, *(float(m.group(i)) for i in range(1, 4))) for p, m in _last_matches(root, _STARTUP)
            if Path(p).parent.parent.name != _COMPILE_LOG]


def startup_lines(root: Path, top: int = 8) -> list[str]:
    """The start-up summary: the mean per job and its parts, then the groups of logs
    (:func:`family`) with the largest mean start-up."""
    rows = startups(root)
    if not rows:
        return ["start-up: no job log carries the start-up figure (a commit before issue 47?)"]
    n = len(rows)
    mean = [sum(r[i] for r in rows) / n for i in range(1, 4)]
    out = [f"start-up CPU per job: mean {mean[0]:.2f} s over {n} jobs (before the work {mean[1]:.2f}, "
           f"making kernels callable {mean[2]:.2f}); {sum(r[1] for r in rows):.1f} CPU-s in all "
           "(the scripts' imports: --imports)"]
    groups: dict[str, list[float]] = {}
    for r in rows:
        groups.setdefault(family(r[0]), []).append(r[1])
    ranked = sorted(groups.items(), key=lambda kv: -sum(kv[1]) / len(kv[1]))[:top]
    out.append("  largest mean start-up: " + ", ".join(f"{g} {sum(v) / len(v):.2f} s ({len(v)})" for g, v in ranked))
    return out


def script_imports(script: Path) -> str:
    """The top-level ``import`` statements of a workflow script, as one program."""
    tree = ast.parse(script.read_text())
    return "\n".join(ast.unparse(n) for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))
                     and not (isinstance(n, ast.ImportFrom) and n.module == "__future__"))


_IMPORTTIME = re.compile(r"^import time:\s+(\d+) \|\s+(\d+) \|( *)(\S.*)$")


def parse_importtime(stderr: str) -> tuple[float, dict[str, float]]:
    """From ``python -X importtime``'s report: the milliseconds of the top-level imports
    (cumulative times of the least-indented lines) and each module's self milliseconds."""
    total, selfs = 0.0, {}
    for line in stderr.splitlines():
        m = _IMPORTTIME.match(line)
        if not m:
            continue
        self_us, cum_us, indent, name = int(m.group(1)), int(m.group(2)), len(m.group(3)), m.group(4).strip()
        selfs[name] = selfs.get(name, 0.0) + self_us / 1000
        if indent == 1:
            total += cum_us / 1000
    return total, selfs


def import_costs(scripts: list[Path], src: Path = REPO / "src") -> list[tuple[str, float, dict[str, float]]]:
    """(script name, ms its imports took, self ms per module) of each script, each in a fresh
    ``python -X importtime`` with ``src`` on the path."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(src), os.environ.get("PYTHONPATH", "")) if p))
    env.pop("PYTHONPROFILEIMPORTTIME", None)
    out = []
    for script in scripts:
        proc = subprocess.run([sys.executable, "-X", "importtime", "-c", script_imports(script)],
                              capture_output=True, text=True, env=env, cwd=REPO)
        if proc.returncode:
            raise RuntimeError(f"{script.name}: its imports failed: {proc.stderr.strip().splitlines()[-1]}")
        out.append((script.name, *parse_importtime(proc.stderr)))
    return out


def import_lines(rows: list[tuple[str, float, dict[str, float]]], top: int = 10) -> list[str]:
    """The --imports table: scripts by import time, then the modules costing the most."""
    out = [f"{'script':40s} {'imports_ms':>10s}"]
    out += [f"{name:40s} {ms:10.0f}" for name, ms, _ in sorted(rows, key=lambda r: -r[1])]
    out.append(f"{'mean over ' + str(len(rows)) + ' scripts':40s} {sum(r[1] for r in rows) / max(len(rows), 1):10.0f}")
    selfs: dict[str, float] = {}
    for _, _, s in rows:
        for k, v in s.items():
            selfs[k] = selfs.get(k, 0.0) + v
    heavy = sorted(selfs.items(), key=lambda kv: -kv[1])[:top]
    out.append("largest self import time, summed over the scripts: "
               + ", ".join(f"{k} {v:.0f} ms" for k, v in heavy))
    return out


def costs(root: Path) -> list[tuple[str, float, float]]:
    """(log path relative to ``root``, CPU seconds, max RSS MB) of every job log that has the line."""
    return [(p, float(m.group(1)), float(m.group(4))) for p, m in _last_matches(root, _LINE)]


def family(path: str) -> str:
    """A group name for a log: its part's folder and the stem's first word (``mc``,
    ``runs``, ...); a study's ``<name>_outputs`` (once ``_table`` / ``_figure``) logs group by that suffix."""
    p = Path(path)
    words = p.stem.split("_")
    head = words[-1] if words[-1] in ("table", "figure", "outputs") and len(words) > 1 else words[0]
    return f"{p.parent.parent.name or '.'}/{head}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", type=Path, nargs="?", help="results folder of a finished run")
    ap.add_argument("--top", type=int, default=0, help="also list the N most expensive jobs (modules with --imports)")
    ap.add_argument("--imports", action="store_true",
                    help="time each workflow script's imports with python -X importtime instead")
    a = ap.parse_args(argv)
    if a.imports:
        for line in import_lines(import_costs(sorted((REPO / "workflow" / "scripts").glob("*.py"))), a.top or 10):
            print(line)
        return 0
    if a.results is None:
        ap.error("give a results folder, or --imports")
    if not a.results.is_dir():
        print(f"job_costs: results folder {a.results} not found", file=sys.stderr)
        return 2
    rows = costs(a.results)
    if not rows:
        print(f"job_costs: no job log with a resource line under {a.results}", file=sys.stderr)
        return 1
    groups: dict[str, list] = {}
    for path, cpu, rss in rows:
        groups.setdefault(family(path), []).append((cpu, rss))
    total = sum(c for _, c, _ in rows)
    print(f"{'group':40s} {'jobs':>5s} {'cpu_s':>9s} {'share':>6s} {'max_cpu_s':>9s} {'max_rss_mb':>10s}")
    for g, v in sorted(groups.items(), key=lambda kv: -sum(c for c, _ in kv[1])):
        s = sum(c for c, _ in v)
        print(f"{g:40s} {len(v):5d} {s:9.1f} {100 * s / total:5.1f}% {max(c for c, _ in v):9.2f} "
              f"{max(r for _, r in v):10.0f}")
    print(f"{'total':40s} {len(rows):5d} {total:9.1f}")
    for path, cpu, rss in sorted(rows, key=lambda r: -r[1])[:a.top]:
        print(f"  {cpu:8.2f} s {rss:6.0f} MB  {path}")
    for line in startup_lines(a.results):
        print(line)
    kernels = kernel_counts(a.results)
    if kernels:
        compiling = [(p, c) for p, _, c in kernels if c and not Path(p).parent.parent.name == "kernels"]
        print(f"kernels: {len(kernels)} jobs used them, {sum(n for _, n, _ in kernels)} signatures loaded from "
              f"the cache; {len(compiling)} jobs besides compile_kernels compiled some themselves")
        for path, n in compiling:
            print(f"  {n:4d} compiled  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
