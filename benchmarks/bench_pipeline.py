"""Whole-pipeline time: a profile from an empty results folder, and where the time goes.

Description
-----------
In a scratch copy of the workflow (``opnav.core.snakeio.copy_workflow``), for each
profile asked (``quick``: ``--configfile config/quick.yaml``; ``full``: the
default config):

1. ``snakemake -n`` and its job count (the "Job stats" total) and per-rule counts;
2. ``snakemake --cores N`` from an empty results folder, timed: wall seconds, the
   CPU seconds of snakemake and every job (``getrusage`` of the children), and
   the load average before and after (other processes on a shared machine);
3. where the time goes, per rule: jobs, the wall seconds from each job's start to
   its end in Snakemake's log (whole seconds: the log's resolution), summed over
   the rule's jobs, and, for rules with a ``benchmark:`` file, the summed wall
   and CPU seconds the job measured itself. The CPU beyond the benchmarked
   jobs' own is what the other jobs and snakemake's per-job overhead cost.

With ``--compare REV`` it builds each profile twice in one invocation, from empty
results and with the same profile and cores: first the workflow of commit ``REV``
(``git archive`` of its workflow parts into a scratch folder), then the working tree's
(uncommitted edits included); each scratch copy imports its own ``src`` (its own
``PYTHONPATH``) and starts with an empty numba cache (``NUMBA_CACHE_DIR`` unset, no
``__pycache__`` copied: compilation is paid inside the build, as in a fresh clone).
It prints new/old ratios of wall time and CPU seconds with the issue's targets
(issue 53, :data:`TARGETS`: the full profile's wall at most 0.6 and CPU at most 0.85 from an
empty numba cache; the quick profile's CPU at most 1.0 from an empty cache and 0.8 warm; all of
them together at the end), and the kernel compile job's log (progress and CPU per
kernel module) and how many other jobs compiled. ``--cache warm`` (or ``both``) builds
each copy a second time from empty results with the numba cache its first build filled
(a developer's rebuild), and compares those builds too; ``both`` prints both ratios last.
Each build's summary has the jobs' start-up CPU (``job_costs.startup_lines``: the mean per
job, before the work, lazy imports, kernel loading; commits before issue 47 do not log it).

With ``--pytest`` it also times ``pytest -q`` of the checkout (wall and CPU).
Targets (issue 14): quick <= 45 s, full <= 5 min wall, pytest <= 90 s on two
cores. Ratios are the thing to compare on a loaded machine: run what you
compare in one invocation.

Machine reference (:func:`machine_reference`, printed first and last): the
thread CPU time of two fixed kernels shaped like the pipeline's own work, a
scalar-float Python loop (the landing planner's call) and stacked 6 x 6 numpy
products (paper A's batched filter). The VMs this project is measured on
differ by more than 2x in speed between sessions (the same commit's full
profile's outputs, the same scorecard: 445 s on one, 1009 s on another), so a total is quoted with the
reference beside it, and totals from different sessions are compared as
``wall / reference`` ("reference units"), never as seconds.

Use::

    python benchmarks/bench_pipeline.py                       # quick profile
    python benchmarks/bench_pipeline.py --profile quick full  # both, one after the other
    python benchmarks/bench_pipeline.py --pytest --profile    # pytest only
    python benchmarks/bench_pipeline.py --compare 960b5d0 --profile quick   # old vs new
    python benchmarks/bench_pipeline.py --compare 960b5d0 --profile quick --cache both   # issue 47
    python benchmarks/bench_pipeline.py --compare e19e33d --profile quick full  # issue 53: quick both caches, full empty
"""

from __future__ import annotations

import argparse
import collections
import datetime as dt
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))

from opnav.core.snakeio import copy_workflow  # noqa: E402

TARGET_S = {"quick": 45.0, "full": 300.0, "pytest": 90.0}
#: issue 53: new/old ratios of a profile built from empty results, at most, per (profile, numba
#: cache) and measure: the full profile from an empty kernel cache (as a fresh clone) wall <= 0.6
#: and CPU <= 0.85 of e19e33d; the quick profile's CPU <= 1.0 from an empty cache and <= 0.8 warm
#: (``--cache warm``: the kernels an earlier build of the same copy compiled)
TARGETS = {("quick", "empty"): {"cpu": 1.0}, ("quick", "warm"): {"cpu": 0.8},
           ("full", "empty"): {"cpu": 0.85, "wall": 0.6}, ("full", "warm"): {"cpu": 0.85, "wall": 0.6}}
#: ``--cache auto`` (the default): the numba caches each profile is compared with (the quick
#: profile both ways, the full one as a fresh clone builds it: a warm full rebuild is another 15 min)
AUTO_CACHE = {"quick": "both", "full": "empty"}
PROFILE_ARGS = {"quick": ["--configfile", "config/quick.yaml"], "full": []}


def _env(wd: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (str(wd / "src"), os.environ.get("PYTHONPATH", "")) if p))
    env.pop("NUMBA_CACHE_DIR", None)  # kernels cached beside the copy's own sources: from empty
    return env


def _children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def machine_reference(repeats: int = 5) -> dict:
    """Thread CPU ms of two fixed kernels (module docstring), each the minimum of
    ``repeats``: ``python_ms``, 200 000 steps of a scalar-float loop (math calls,
    branches, as ``opnav.landing.planner``'s golden-section search), and
    ``numpy_ms``, 2 000 products ``A @ B`` of (60, 6, 6) stacks (as paper A's
    batched EKF); ``ref_ms`` is their sum."""
    import math

    import numpy as np

    def py():
        x, acc, sin, sqrt = 0.3, 0.0, math.sin, math.sqrt
        for _ in range(200_000):
            s = sin(x)
            acc += sqrt(1.0 + s * s) if s > 0 else -s
            x += 1e-5
        return acc

    rng = np.random.default_rng(0)
    A, B = rng.standard_normal((2, 60, 6, 6))

    def npy():
        for _ in range(2_000):
            A @ B

    out = {}
    for key, fn in (("python_ms", py), ("numpy_ms", npy)):
        best = math.inf
        for _ in range(repeats):
            c0 = time.thread_time_ns()
            fn()
            best = min(best, (time.thread_time_ns() - c0) / 1e6)
        out[key] = best
    out["ref_ms"] = out["python_ms"] + out["numpy_ms"]
    return out


def report_reference(tag: str, repeats: int = 5) -> dict:
    ref = machine_reference(repeats)
    print(f"machine reference ({tag}): python {ref['python_ms']:.1f} ms, numpy {ref['numpy_ms']:.1f} ms, "
          f"sum {ref['ref_ms']:.1f} ms (thread CPU, min of {repeats})")
    return ref


def units(wall_s: float, ref_ms: float) -> str:
    """A wall time in reference units (wall / machine reference), as printed."""
    return f"{wall_s / (ref_ms / 1e3):.0f} reference units wall"


def timed(cmd: list[str], cwd: Path, env: dict) -> dict:
    """Run ``cmd``; wall and CPU seconds (the process and its waited-for children)."""
    load0, cpu0, t0 = os.getloadavg()[0], _children_cpu(), time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    return {"rc": proc.returncode, "wall_s": wall, "cpu_s": cpu, "load_before": load0,
            "load_after": os.getloadavg()[0], "out": proc.stdout + proc.stderr}


def job_stats(text: str) -> dict[str, int]:
    """{rule: jobs} of the last "Job stats" table in snakemake's output (with 'total')."""
    blocks = text.split("Job stats:")
    if len(blocks) < 2:
        return {}
    out = {}
    for line in blocks[-1].splitlines()[3:]:
        m = re.match(r"(\w+)\s+(\d+)$", line.strip())
        if not m:
            break
        out[m.group(1)] = int(m.group(2))
    return out


_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$", re.M)


def log_job_seconds(log_text: str) -> dict[str, float]:
    """{rule: summed seconds from each job's start to its 'Finished jobid'} from a snakemake log."""
    start, rule_of, per_rule = {}, {}, collections.Counter()
    pieces = _STAMP.split(log_text)
    for stamp, body in zip(pieces[1::2], pieces[2::2]):
        t = dt.datetime.strptime(" ".join(stamp.split()), "%a %b %d %H:%M:%S %Y")
        for m in re.finditer(r"^(?:local)?rule (\w+):\n(?:    .*\n)*?    jobid: (\d+)", body, re.M):
            start[m.group(2)], rule_of[m.group(2)] = t, m.group(1)
        for m in re.finditer(r"Finished jobid: (\d+)", body):
            j = m.group(1)
            if j in start:
                per_rule[rule_of[j]] += (t - start[j]).total_seconds()
    return dict(per_rule)


def benchmark_seconds(results: Path) -> dict[str, tuple[int, float, float]]:
    """{benchmark file stem prefix: (files, summed wall s, summed CPU s)} of every
    benchmark TSV under ``results`` (grouped by the part of the name before the
    first wildcard-looking separator)."""
    import csv

    out: dict[str, list[float]] = collections.defaultdict(lambda: [0, 0.0, 0.0])
    for f in results.rglob("benchmarks/*.tsv"):
        with open(f) as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        if not rows:
            continue
        key = f"{f.parent.parent.name}/{re.split(r'_|__', f.stem)[0]}"
        acc = out[key]
        acc[0] += 1
        acc[1] += float(rows[0]["s"])
        try:
            acc[2] += float(rows[0]["cpu_time"])
        except (KeyError, ValueError):
            pass
    return {k: tuple(v) for k, v in out.items()}


def export_revision(rev: str, dst: Path) -> str:
    """The workflow parts (``opnav.core.snakeio.WORKFLOW_PARTS``) of commit ``rev`` of this
    checkout, extracted into ``dst`` (``git archive``); returns the full commit id."""
    from opnav.core.snakeio import WORKFLOW_PARTS

    def git(*args, **kw):
        return subprocess.run(["git", *args], cwd=REPO, check=True, capture_output=True, **kw).stdout

    try:
        commit = git("rev-parse", "--verify", f"{rev}^{{commit}}", text=True).strip()
    except subprocess.CalledProcessError:
        raise SystemExit(f"bench_pipeline: --compare {rev}: not a commit of {REPO}") from None
    parts = [p for p in WORKFLOW_PARTS if git("ls-tree", "--name-only", commit, p, text=True).strip()]
    dst.mkdir(parents=True, exist_ok=True)
    archive = git("archive", "--format=tar", commit, *parts)
    subprocess.run(["tar", "-x", "-C", str(dst)], input=archive, check=True)
    return commit


def run_profile(name: str, cores: int, keep: Path | None, rev: str | None = None,
                again: dict | None = None) -> dict:
    """Build profile ``name`` from empty in a scratch copy: of the working tree, or of
    commit ``rev`` (:func:`export_revision`); with ``again`` (an earlier result of this
    function), in that copy again from empty results, its numba cache kept (warm)."""
    if again is not None:
        wd, commit = again["wd"], again["commit"]
        for sub in ("results", ".snakemake"):
            shutil.rmtree(wd / sub, ignore_errors=True)
    else:
        tmp = Path(keep) if keep else Path(tempfile.mkdtemp(prefix=f"bench_pipeline_{name}_"))
        label = f"{name}-{rev}" if rev else name
        (tmp / label).mkdir(parents=True, exist_ok=True)
        if rev:
            commit = export_revision(rev, tmp / label)
            wd = tmp / label
        else:
            commit = "working tree"
            wd = copy_workflow(REPO, tmp / label, kernel_cache=False)  # compiled inside the build
    env = _env(wd)
    base = [sys.executable, "-m", "snakemake", *PROFILE_ARGS[name]]
    dry = timed([*base, "-n", "--cores", "1"], wd, env)
    jobs = job_stats(dry["out"])
    run = timed([*base, "--cores", str(cores)], wd, env)
    if run["rc"] != 0:
        print(run["out"][-3000:], file=sys.stderr)
        raise SystemExit(f"bench_pipeline: the {name} profile failed (scratch copy kept in {wd})")
    logs = sorted((wd / ".snakemake" / "log").glob("*.snakemake.log"))
    per_rule = log_job_seconds(logs[-1].read_text()) if logs else {}
    return {"name": name, "wd": wd, "jobs": jobs, "dry": dry, "run": run, "per_rule": per_rule,
            "bench": benchmark_seconds(wd / "results"), "commit": commit,
            "cache": "warm" if again is not None else "empty"}


def kernel_report(wd: Path) -> list[str]:
    """The compile_kernels jobs' log lines (compile seconds per kernel module), the
    load seconds of every kernel in a fresh process from the filled cache, and the
    count of other jobs that loaded or compiled kernels themselves (job_costs)."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    from job_costs import kernel_counts

    lines = []
    for log in sorted(wd.glob("results/**/kernels/logs/compile_*.log")):
        lines += [line for line in log.read_text(errors="replace").splitlines()
                  if (" INFO " in line or " WARNING " in line) and "job resources" not in line]
    if (wd / "src" / "opnav" / "core" / "numba_adapter.py").is_file():  # every kernel again in a fresh process
        code = ("import importlib, json, opnav.approach, opnav.landing, opnav.core.compiled as c; "
                "[importlib.import_module(m) for m in c.kernel_modules()]; s = c.warm(); "
                "print(json.dumps({'seconds': s, **c.cache_stats()}))")
        c0 = _children_cpu()
        proc = subprocess.run([sys.executable, "-c", code], cwd=wd, env=_env(wd), capture_output=True, text=True)
        if proc.returncode == 0:
            fresh = json.loads(proc.stdout.splitlines()[-1])
            lines.append(f"a fresh process loads every kernel from the filled cache: {fresh['loaded']} signatures "
                         f"loaded, {fresh['compiled']} compiled, {sum(fresh['seconds'].values()):.2f} s wall "
                         f"({_children_cpu() - c0:.2f} CPU-s with numba's import and the interpreter); "
                         + ", ".join(f"{m} {t:.3f} s" for m, t in sorted(fresh["seconds"].items())))
    counts = [c for c in kernel_counts(wd / "results") if Path(c[0]).parent.parent.name != "kernels"]
    if counts:
        compiling = [c for c in counts if c[2]]
        lines.append(f"{len(counts)} jobs used kernels: {sum(c[1] for c in counts)} signatures loaded, "
                     f"{sum(c[2] for c in counts)} compiled by {len(compiling)} jobs"
                     + "".join(f"\n  {c[2]} compiled in {c[0]}" for c in compiling))
    return lines


def report_compare(old: dict, new: dict, ref_ms: float) -> dict:
    """New/old ratios of wall and CPU seconds of one profile, with the target."""
    name, o, n = new["name"], old["run"], new["run"]
    cpu, wall = n["cpu_s"] / o["cpu_s"], n["wall_s"] / o["wall_s"]
    print(f"\n== compare, {name} profile, {new['cache']} kernel cache: old {old['commit'][:10]}, new {new['commit']}")
    print(f"old: {o['wall_s']:.1f} s wall, {o['cpu_s']:.0f} CPU-s, {old['jobs'].get('total', 0)} jobs; "
          f"{units(o['wall_s'], ref_ms)}")
    print(f"new: {n['wall_s']:.1f} s wall, {n['cpu_s']:.0f} CPU-s, {new['jobs'].get('total', 0)} jobs; "
          f"{units(n['wall_s'], ref_ms)}")
    for line in kernel_report(new["wd"]):
        print(f"new kernels: {line}")
    out = {"name": name, "cache": new["cache"], "cpu": cpu, "wall": wall}
    print(ratio_line(out))
    return out


def ratio_line(r: dict) -> str:
    """``<profile> profile new/old, <cache> kernel cache: CPU-s x (target <= t: met), wall y (...)``:
    both ratios, each with its issue-53 target (:data:`TARGETS`) where it has one."""
    tg = TARGETS.get((r["name"], r["cache"]), {})

    def one(key, label):
        t = tg.get(key)
        return f"{label} {r[key]:.3f}" + ("" if t is None else f" (target <= {t}: {'met' if r[key] <= t else 'NOT met'})")
    return f"{r['name']} profile new/old, {r['cache']} kernel cache: {one('cpu', 'CPU-s')}, {one('wall', 'wall')}"


def report_profile(r: dict, cores: int, ref_ms: float) -> None:
    run, jobs = r["run"], r["jobs"]
    print(f"\n== {r['name']} profile of {r['commit']} (snakemake --cores {cores}"
          f"{' ' + ' '.join(PROFILE_ARGS[r['name']]) if PROFILE_ARGS[r['name']] else ''}), scratch copy {r['wd']}")
    print(f"dry run: {jobs.get('total', 0)} jobs, parse + DAG {r['dry']['wall_s']:.1f} s wall, {r['dry']['cpu_s']:.1f} CPU-s")
    print(f"{'rule':28s} {'jobs':>5s} {'job-s (log)':>12s}")
    rows = sorted(((k, v) for k, v in jobs.items() if k != "total"),
                  key=lambda kv: -r["per_rule"].get(kv[0], 0.0))
    for rule, n in rows:
        print(f"{rule:28s} {n:5d} {r['per_rule'].get(rule, 0.0):12.0f}")
    # a benchmark file's CPU is the job's own process tree: with the build's job server
    # (opnav.core.jobserver) only the job's client, the work being in the server's fork
    print(f"{'benchmark files':28s} {'files':>5s} {'wall s':>8s} {'CPU s':>8s}  (CPU: the job's own processes)")
    for k, (n, w, c) in sorted(r["bench"].items(), key=lambda kv: -kv[1][1]):
        print(f"{k:28s} {n:5d} {w:8.1f} {c:8.1f}")
    sys.path.insert(0, str(REPO / "benchmarks"))
    from job_costs import costs, startup_lines

    logged = costs(r["wd"] / "results")
    log_cpu = sum(c for _, c, _ in logged)
    print(f"CPU: {run['cpu_s']:.0f} CPU-s in all, {log_cpu:.0f} in the {len(logged)} jobs' logs (each job's whole "
          f"CPU, start-up included), {run['cpu_s'] - log_cpu:.0f} for snakemake itself and the job server")

    for line in startup_lines(r["wd"] / "results"):
        print(line)
    print(f"load average {run['load_before']:.1f} before, {run['load_after']:.1f} after")
    print(f"{r['name']} profile: {run['wall_s']:.1f} s wall, {run['cpu_s']:.0f} CPU-s, "
          f"{jobs.get('total', 0)} jobs (target {TARGET_S[r['name']]:.0f} s wall); "
          f"{units(run['wall_s'], ref_ms)}")


def run_pytest(ref_ms: float) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (str(REPO / "src"), os.environ.get("PYTHONPATH", "")) if p))
    with tempfile.TemporaryDirectory(prefix="bench_pytest_") as base:
        r = timed([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"--basetemp={base}/t"],
                  REPO, env)
    tail = [line for line in r["out"].splitlines() if line.strip()][-1:]
    print(f"\n== pytest ({tail[0] if tail else 'no output'})")
    print(f"load average {r['load_before']:.1f} before, {r['load_after']:.1f} after")
    print(f"pytest: {r['wall_s']:.1f} s wall, {r['cpu_s']:.0f} CPU-s (target {TARGET_S['pytest']:.0f} s wall); "
          f"{units(r['wall_s'], ref_ms)}")
    return r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", nargs="*", default=["quick"], choices=sorted(PROFILE_ARGS),
                    help="profiles to run from empty, in order (none: skip)")
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--pytest", action="store_true", help="also time the test suite")
    ap.add_argument("--keep", help="make the scratch copies under this folder (kept)")
    ap.add_argument("--cache", choices=("auto", "empty", "warm", "both"), default="auto",
                    help="the numba kernel cache of the build(s) compared: empty (compiled inside the build, "
                         "as in a fresh clone), warm (each copy built a second time from empty results, the "
                         "kernels its first build compiled kept; the first builds are printed too), both, or "
                         "auto (default: quick both, full empty; AUTO_CACHE)")
    ap.add_argument("--compare", metavar="REV",
                    help="also build commit REV (first) and print new/old ratios (module docstring)")
    args = ap.parse_args(argv)
    if args.cores < 1:
        ap.error("--cores must be >= 1")
    print(f"{os.cpu_count()} CPUs; load average {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    ref_ms = report_reference("before")["ref_ms"]
    keep = Path(args.keep) if args.keep else None
    if args.compare:  # a bad revision stops before any build
        export_revision(args.compare, Path(tempfile.mkdtemp(prefix="bench_pipeline_rev_")))
    all_ratios = []
    for name in args.profile:
        cache = ((AUTO_CACHE[name] if args.compare else "empty") if args.cache == "auto" else args.cache)
        old = None
        if args.compare:
            old = run_profile(name, args.cores, keep, rev=args.compare)
            report_profile(old, args.cores, ref_ms)
            report_reference(f"after the old {name} build")
        new = run_profile(name, args.cores, keep)
        report_profile(new, args.cores, ref_ms)
        ratios = []
        if old and cache in ("empty", "both"):
            ratios.append(report_compare(old, new, ref_ms))
        if cache in ("warm", "both"):  # each copy again, its numba cache kept
            if old and list((old["wd"] / "results").rglob("kernels/*.json")):
                old = run_profile(name, args.cores, keep, again=old)
                report_profile(old, args.cores, ref_ms)
            elif old:  # a commit without compiled kernels: nothing to warm, its build stands
                print(f"\n(old {old['commit'][:10]} compiles no kernels: its build above is its warm build too)")
                old = {**old, "cache": "warm"}
            new = run_profile(name, args.cores, keep, again=new)
            report_profile(new, args.cores, ref_ms)
            if old:
                ratios.append(report_compare(old, new, ref_ms))
        all_ratios += ratios
    if all_ratios:  # every ratio with its target together, last
        print(f"\n== new/old against {args.compare}, both ratios of each build compared")
        for r in all_ratios:
            print(ratio_line(r))
    if args.pytest:
        run_pytest(ref_ms)
    after = report_reference("after")["ref_ms"]
    print(f"machine reference drift over the benchmark: {100 * (after / ref_ms - 1):+.0f} % "
          "(units above use the 'before' reference)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
