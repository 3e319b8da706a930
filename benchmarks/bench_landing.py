"""Planning-call timing of paper B's landmark planners and the Monte-Carlo wall time.

Description
-----------
Issue 5 "Fair timing / Performance": every method runs the same planning call
(``opnav.landing.planner.plan``: visible interval, golden-section search,
nearest detected landmark); only the objective differs. This script

1. builds the planning states of one descent (the filter's estimate and
   covariance at every planning instant of run 0 with the depth planner), then
   times one planning call per (state, method) with ``time.perf_counter_ns``,
   methods interleaved state by state so clock drift and load hit them alike,
   ``--reps`` rounds; it prints per method the median time per call (us), the
   median objective evaluations per call, the time per evaluation beyond the
   depth method's, and the ratio to the SVD baseline measured in the same
   process; on the configured path (``landing.planner.eval_path``, default
   ``compiled``) and on the other (``paper``: the paper's definition, CasADi H +
   LAPACK SVD, interpreted);
2. with ``--mc``, runs the landing Monte Carlo of the config (every method)
   through Snakemake with ``--cores 2`` in a scratch results directory and
   prints its wall time.

Use::

    python benchmarks/bench_landing.py                   # planning-call table
    python benchmarks/bench_landing.py --mc              # + full Monte Carlo wall time
    python benchmarks/bench_landing.py --config config/quick.yaml --mc
"""

from __future__ import annotations

import argparse
import dataclasses
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))

from opnav.core.config import load_config  # noqa: E402
from opnav.landing import descent as D  # noqa: E402
from opnav.landing import planner as PL  # noqa: E402


def planning_states(landing, run_index: int = 0):
    """(PlanState, visible-function) at every planning instant of one depth descent."""
    scn = D.build_scenario(landing)
    captured = []
    orig = D.plan_batch

    def spy(method, states, camera, field, visible, cfg, exclude, rngs=None, detected=None, **kw):
        for j, ex in enumerate(exclude):          # the descent plans a batch of runs at once
            state = PL.PlanState(states.r[j], states.v[j], states.a[j], states.R_LtoB[j], states.P[j])
            captured.append((state, visible, {int(ex)} if ex >= 0 else set(), detected))
        return orig(method, states, camera, field, visible, cfg, exclude, rngs, detected, **kw)

    D.plan_batch = spy
    try:
        D.run_descent(scn, "depth", run_index)
    finally:
        D.plan_batch = orig
    return scn, captured


def time_methods(scn, states, methods, reps: int, eval_path: str):
    cfg = dataclasses.replace(scn.planner, eval_path=eval_path)
    times = {m: [] for m in methods}
    cpu = {m: [] for m in methods}
    evals = {m: [] for m in methods}
    for _ in range(reps):
        for state, visible, exclude, detected in states:
            for m in methods:
                t0 = time.perf_counter_ns()
                res = PL.plan(m, state, scn.camera, scn.field, visible, cfg, exclude=exclude,
                              detected=detected)
                times[m].append(time.perf_counter_ns() - t0)
                cpu[m].append(res.cpu_ns)
                evals[m].append(res.n_evals)
    return times, cpu, evals


def table(times, evals, ref="svd"):
    med = {m: float(np.median(v)) / 1e3 for m, v in times.items()}
    ev = {m: float(np.median(v)) for m, v in evals.items()}
    base = med.get("depth", 0.0)
    rows = []
    for m in times:
        per_eval = (med[m] - base) / ev[m] if ev[m] else float("nan")
        rows.append((m, med[m], ev[m], per_eval, med[m] / med[ref] if ref in med else float("nan"),
                     med[ref] / med[m] if ref in med else float("nan")))
    print(f"{'method':8s} {'median us/call':>15s} {'evals/call':>11s} {'extra us/eval':>14s} "
          f"{'ratio to ' + ref:>13s} {ref + '/method':>11s}")
    for m, t, e, pe, r, inv in rows:
        print(f"{m:8s} {t:15.1f} {e:11.0f} {pe:14.2f} {r:13.3f} {inv:11.2f}")
    if "depth" in med and ref in med:
        print(f"depth vs {ref}: median planning time {100 * (1 - med['depth'] / med[ref]):.1f} % lower "
              f"(published: 29.03 %); {ref} / depth = {med[ref] / med['depth']:.2f}x")
    return med


def run_mc(config: str | None) -> float:
    """Wall time (s) of the landing Monte Carlo (all methods) with --cores 2."""
    tmp = Path(tempfile.mkdtemp(prefix="bench_landing_"))
    try:
        res_dir = tmp / "results"
        targets = [str(res_dir / "landing" / "B-summary.json")]     # every camera scenario
        cmd = [sys.executable, "-m", "snakemake", "--cores", "2", "--quiet", "rules",
               "--config", f"results_dir={res_dir}"]
        if config:
            cmd[3:3] = ["--configfile", config]
        cmd += ["--", *targets]
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=REPO, check=True)
        return time.perf_counter() - t0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=None, help="config file (default config/config.yaml)")
    ap.add_argument("--reps", type=int, default=3, help="rounds over the planning states")
    ap.add_argument("--methods", default=None, help="comma list (default landing.mc.methods)")
    ap.add_argument("--mc", action="store_true", help="also time the full Monte Carlo (--cores 2)")
    args = ap.parse_args(argv)
    from opnav.landing.setup import Setup

    landing = Setup.from_config(load_config(overlays=[args.config] if args.config else [])["landing"])
    methods = args.methods.split(",") if args.methods else list(landing.mc.methods)
    scn, states = planning_states(landing)
    print(f"{len(states)} planning states from run 0 (depth), {args.reps} rounds, "
          f"methods interleaved per state")
    path = scn.planner.eval_path
    print(f"\n== baselines via eval_path = {path} (configured) ==")
    t, c, e = time_methods(scn, states, methods, args.reps, path)
    print("-- wall time (perf_counter_ns) --")
    table(t, e)
    print("-- CPU time of the thread (thread_time_ns) --")
    table(c, e)
    other = PL.alternative_path(scn.planner).eval_path
    print(f"\n== eval_path = {other} (the other path) ==")
    t, c, e = time_methods(scn, states, methods, args.reps, other)
    table(t, e)
    if args.mc:
        wall = run_mc(args.config)
        n = landing.mc.n_runs
        print(f"\nMonte Carlo: {len(methods)} methods x {n} runs, snakemake --cores 2: {wall:.1f} s wall")
    return 0


if __name__ == "__main__":
    sys.exit(main())
