"""Planning-call benchmark (issue 31 target): the compiled depth-error call's
overhead (all but its objective evaluations) over the evaluations themselves,
measured by replay of recorded planning calls (opnav.landing.timing.call_overhead),
and the replay's per-method times on the same calls, compiled and as the paper
defines it (CasADi H, LAPACK SVD; interpreted); everything in one run, one process.

    PYTHONPATH=src python benchmarks/bench_planning.py [--runs 2] [--calls 100] [--scenario interior]

Per scenario it prints the replay table, then for the compiled depth call (thread
CPU clock; per call the minimum of 3 averages over --reps calls in a row, then the
median over calls): the call, its objective evaluations (timed inside a kernel, so
no call overhead counts as evaluation), overhead = call - evaluations and the ratio
overhead / evaluations (median of the per-call ratios; target <= 2). The call is the
compiled kernel's (``planner.compiled_call``: numba's dispatch included), as the replay
times it; ``planner.plan`` from Python (the wrapper that packs a ``PlanResult`` for the
Monte Carlo added) is printed beside it, hot and once cold.

Last line: ``depth overhead ratio: X`` (the largest scenario's median ratio).
"""

import argparse
import os
import time

# one BLAS thread, as the workflow's jobs run (Snakemake sets OPENBLAS_NUM_THREADS to a job's
# threads): OpenBLAS's own threads on a shared 2-core machine cost up to ~80x on the planner's
# small batched GEMMs (measured); set before numpy is imported
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from opnav.core.config import load_config
from opnav.landing import timing, timing_summary
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import run_chunk
from opnav.landing.setup import Setup
from opnav.report.landing import timing_text

def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=2, help="descents flown per method (run indices 0..)")
    ap.add_argument("--calls", type=int, default=100, help="recorded calls replayed (0 = all)")
    ap.add_argument("--scenario", default=None, help="camera scenario (default: every one)")
    ap.add_argument("--methods", default="depth,svd,gdop,cond", help="methods replayed, comma-separated")
    ap.add_argument("--reps", type=int, default=200, help="calls in a row per timing (hot)")
    a = ap.parse_args()
    land = load_config()["landing"]
    scns = Setup.from_config(land).scenarios_by_name()
    names = [a.scenario] if a.scenario else list(scns)
    methods = a.methods.split(",")
    if "depth" not in methods:
        methods = ["depth"] + methods
    ratios = []
    for name in names:
        scn = build_scenario(scns[name])
        rec = {m: run_chunk(scns[name], m, range(a.runs)) for m in methods}
        t0 = time.perf_counter()
        c0 = time.process_time()
        tm = timing.replay(scn, rec, methods, a.calls, decompose=True)
        print(f"[{name}] replay: {len(tm.source)} of {int(tm.n_pool)} calls x "
              f"{tm.wall_ns.shape[1]} variants in {time.perf_counter() - t0:.2f} s wall, "
              f"{time.process_time() - c0:.2f} s CPU; pick mismatches {int(tm.mismatch.sum())} "
              f"of {int(tm.checked.sum())}")
        print(timing_text.summary_frame(tm)[["method", "path", "eval_path", "calls",
                                        "cpu_median_us", "cpu_p05_us", "cpu_p95_us",
                                        "median_evals"]].to_string(index=False))
        for m in methods:                  # the call's two parts (timing_summary.decomposition)
            d = timing_summary.decomposition(tm, m)
            if d.n_calls:
                print(f"[{name}] {m:10s} shared {d.shared_us:6.2f} us + {d.evals_per_call:.0f} evaluations x "
                      f"{1e3 * d.per_eval_us:5.0f} ns = {d.eval_us:6.2f} us (least squares: shared "
                      f"{d.fit_shared_us:.2f} us, {1e3 * d.fit_per_eval_us:.0f} ns an evaluation)")
        if "svd" in methods:
            red = timing_summary.time_reduction(tm, "depth", "svd")
            print(f"[{name}] depth vs svd median reduction ({timing_text.CLOCK_WORDS}): {red[0]:.1f} % "
                  f"+- {red[1]:.1f} (one replay's bootstrap; the claims read the spread between replays)")
        ov = timing.call_overhead(scn, rec, "depth", a.calls, reps=a.reps)
        call, ev = ov.call_ns / 1e3, ov.evals_ns / 1e3
        r = float(np.median(ov.overhead_ratio))
        ratios.append(r)
        print(f"[{name}] compiled depth planning call, thread CPU, {len(call)} calls "
              f"({int(ov.edge.sum())} edge calls: detected landmarks scored, counted as "
              f"evaluations); per call min of 3 averages of {a.reps}, median over calls:")
        print(f"    call                        {np.median(call):8.2f} us")
        print(f"    objective evaluations       {np.median(ev):8.2f} us  "
              f"({np.median(ov.n_evals):.0f} evaluations)")
        print(f"    overhead (call - evals)     {np.median(call - ev):8.2f} us")
        print(f"    overhead / evaluations      {r:8.2f}     (p90 {np.quantile(ov.overhead_ratio, 0.9):.2f}; "
              "target <= 2)")
        wr = np.median(ov.wrapped_ns) / 1e3
        print(f"    plan() from Python, hot     {wr:8.2f} us  (the call + the Python wrapper the Monte "
              f"Carlo adds; overhead / evaluations {(wr - np.median(ev)) / np.median(ev):.2f})")
        print(f"    plan() once, cold           {np.median(ov.cold_ns) / 1e3:8.2f} us")
    print(f"depth overhead ratio: {max(ratios):.2f}")


if __name__ == "__main__":
    main()
