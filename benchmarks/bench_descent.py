"""Descent throughput of paper B's Monte Carlo: descents per CPU-second
(time.process_time) of the same runs flown one at a time (batch size 1) and
as batches of the default size (landing.mc.batch_size; 0 = the whole chunk,
here all runs at once), per camera scenario and planning method, in one
process; also the pre-refactor per-run descent (tests/descent_reference.py)
on the same runs, and a check that the batched numbers equal the per-run ones;
and the batched descent's CPU per run less its planning calls (the filter and
the descent's own bookkeeping: ``filter ms/run``).

    PYTHONPATH=src python benchmarks/bench_descent.py [--runs 50] [--methods depth,svd]
        [--scenarios interior,site-tilt] [--batch N] [--no-reference]

The last line reads ``batch speedup: X``: total descents per CPU-second at the
default batch size over the same at batch size 1 (all cells pooled).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

# one BLAS thread, as the workflow's jobs run (Snakemake sets OPENBLAS_NUM_THREADS to a job's
# threads): OpenBLAS's own threads on a shared 2-core machine cost up to ~80x on the planner's
# small batched GEMMs (measured); set before numpy is imported
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
sys.path.insert(0, str(REPO / "tests"))

from opnav.core.config import load_config  # noqa: E402
from opnav.landing import descent  # noqa: E402
from opnav.landing.descent import run_descents  # noqa: E402
from opnav.landing.scenario import build_scenario  # noqa: E402
from opnav.landing.setup import Setup  # noqa: E402


PLAN_CPU = [0.0]      # CPU s spent in the planner (descent.plan_batch) since the last reset


def _timed_plan_batch(*args, **kw):
    t0 = time.process_time()
    try:
        return _plan_batch(*args, **kw)
    finally:
        PLAN_CPU[0] += time.process_time() - t0


def fly(scn, method, runs, batch):
    """Fly ``runs`` in batches of ``batch``: (runs, CPU s, of which planning CPU s)."""
    size = len(runs) if batch <= 0 else batch
    PLAN_CPU[0] = 0.0
    t0 = time.process_time()
    out = []
    for a in range(0, len(runs), size):
        out.extend(run_descents(scn, method, runs[a:a + size]))
    return out, time.process_time() - t0, PLAN_CPU[0]


def _field(run, k):
    """A field of a Descent record, or a key of the frozen reference's dict."""
    return run[k] if isinstance(run, dict) else getattr(run, k)


def max_rel_diff(a, b) -> float:
    worst = 0.0
    for x, y in zip(a, b):
        for k in ("err_r", "err_v", "sig_r", "plan_beta"):
            u, v = np.asarray(_field(x, k), float), np.asarray(_field(y, k), float)
            if u.shape != v.shape:
                return np.inf
            fin = np.isfinite(v)
            worst = max(worst, float(np.max(np.abs(u[fin] - v[fin]) / (1e-9 + np.abs(v[fin])), initial=0)))
        if not np.array_equal(_field(x, "plan_index"), _field(y, "plan_index")):
            return np.inf
    return worst


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=50)
    ap.add_argument("--methods", default="depth,svd")
    ap.add_argument("--scenarios", default="interior,site-tilt")
    ap.add_argument("--batch", type=int, default=None,
                    help="batched size (default landing.mc.batch_size; 0 = all runs)")
    ap.add_argument("--no-reference", action="store_true", help="skip the pre-refactor per-run code")
    args = ap.parse_args(argv)
    global _plan_batch
    _plan_batch = descent.plan_batch
    descent.plan_batch = _timed_plan_batch
    cfg = Setup.from_config(load_config()["landing"])
    batch = int(cfg.mc.batch_size) if args.batch is None else args.batch
    runs = list(range(args.runs))
    scns = cfg.scenarios_by_name()
    ref = None
    if not args.no_reference:
        import descent_reference as ref
    print(f"{len(runs)} runs per cell; batched size {batch or len(runs)} "
          f"({'landing.mc.batch_size' if args.batch is None else '--batch'} = {batch}); CPU s = process_time")
    print(f"{'scenario':10s} {'method':7s} {'per-run ref':>12s} {'batch 1':>10s} {'batched':>10s} "
          f"{'x vs 1':>7s} {'x vs ref':>8s} {'max rel diff':>12s} {'filter ms/run':>13s}   (descents per "
          f"CPU-second; filter: the batched descent's CPU per run less its planning calls)")
    tot = {"1": 0.0, "b": 0.0, "ref": 0.0, "filter": 0.0}
    n_cells = 0
    for name in args.scenarios.split(","):
        scn = build_scenario(scns[name])
        for m in args.methods.split(","):
            run_descents(scn, m, [0, 1])                          # warm caches / imports
            one, t1, _ = fly(scn, m, runs, 1)
            bat, tb, tp = fly(scn, m, runs, batch)
            tot["filter"] += tb - tp
            diff = max_rel_diff(bat, one)
            tr = np.nan
            if ref is not None:
                t0 = time.process_time()
                refr = [ref.run_descent(scn, m, i) for i in runs]
                tr = time.process_time() - t0
                diff = max(diff, max_rel_diff(bat, refr))
                tot["ref"] += tr
            tot["1"] += t1
            tot["b"] += tb
            n_cells += 1
            n = len(runs)
            print(f"{name:10s} {m:7s} {n / tr if tr == tr else math.nan:12.1f} {n / t1:10.1f} {n / tb:10.1f} {t1 / tb:7.1f} "
                  f"{tr / tb:8.1f} {diff:12.2e} {(tb - tp) / n * 1e3:13.2f}", flush=True)
    n = len(runs) * n_cells
    vs_ref = (f"per-run reference {n / tot['ref']:.1f}, " if ref is not None else "")
    print(f"all cells: {vs_ref}batch 1 {n / tot['1']:.1f}, batched {n / tot['b']:.1f} descents per "
          f"CPU-second" + (f"; batched vs per-run reference {tot['ref'] / tot['b']:.1f}x"
                           if ref is not None else ""))
    print(f"descent excluding planning, batched: {tot['filter'] / n * 1e3:.2f} ms CPU per run")
    print(f"batch speedup: {tot['1'] / tot['b']:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
