"""Planning-call benchmark (issue 14 target): the depth-error call's overhead
(all but its objective evaluations) over the evaluations themselves, measured
by replay of recorded planning calls (opnav.landing.timing.call_overhead),
with a breakdown of the overhead by stage of the call, and the replay's
per-method times on the same calls; everything in one run, one process.

    PYTHONPATH=src python benchmarks/bench_planning.py [--runs 2] [--calls 100] [--scenario interior]

Per scenario it prints the replay table, then for the depth call (thread CPU
clock; per call the minimum of 3 repeats, then the median over calls): the
call, its objective evaluations, overhead = call - evaluations, the ratio
overhead / evaluations (median of the per-call ratios; target <= 2) and the
overhead by stage (``timing.call_overhead(..., stage_reps)``: each stage
timed alone on the same calls, hot, ``--reps`` calls in a row, minimum of 3):
plane, visible interval, objective build
(eq. 19 and 22 constants), the search loop beyond its evaluations, the eq. 26
ground point, the edge rule's candidate list (its batch scoring counts as
evaluations), the nearest-landmark pick, the rest (the call's wrapper,
glue and result: the hot call less its hot evaluations and stages) and the
cold start (the overhead as replayed less the hot one: a replayed call runs
once, on cold caches). The hot call's own ratio is printed too.

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

from opnav.config import load_config
from opnav.landing import timing
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import run_chunk
from opnav.landing.scenario import camera_scenarios

def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=2, help="descents flown per method (run indices 0..)")
    ap.add_argument("--calls", type=int, default=100, help="recorded calls replayed (0 = all)")
    ap.add_argument("--scenario", default=None, help="camera scenario (default: every one)")
    ap.add_argument("--methods", default="depth,svd,gdop,cond", help="methods replayed, comma-separated")
    ap.add_argument("--reps", type=int, default=20, help="repeats per stage timing (breakdown)")
    a = ap.parse_args()
    land = load_config()["landing"]
    scns = camera_scenarios(land)
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
        tm = timing.replay(scn, rec, methods, a.calls)
        print(f"[{name}] replay: {len(tm['source'])} of {int(tm['n_pool'])} calls x "
              f"{tm['wall_ns'].shape[1]} variants in {time.perf_counter() - t0:.2f} s wall, "
              f"{time.process_time() - c0:.2f} s CPU; pick mismatches {int(tm['mismatch'].sum())} "
              f"of {int(tm['checked'].sum())}")
        print(timing.summary_frame(tm)[["method", "path", "eval_path", "calls", "wall_median_us",
                                        "cpu_median_us", "cpu_p05_us", "cpu_p95_us",
                                        "median_evals"]].to_string(index=False))
        if "svd" in methods:
            red = timing.time_reduction(tm, "depth", "svd")
            print(f"[{name}] depth vs svd median reduction (wall): {red[0]:.1f} % +- {red[1]:.1f}")
        ov = timing.call_overhead(scn, rec, "depth", a.calls, stage_reps=a.reps)
        br = ov["stages"]
        call, ev = ov["call_ns"] / 1e3, ov["evals_ns"] / 1e3
        r = float(np.median(ov["overhead_ratio"]))
        ratios.append(r)
        print(f"[{name}] depth planning call, thread CPU, {len(call)} calls "
              f"({int(ov['edge'].sum())} edge calls: detected landmarks batch-scored, counted as "
              "evaluations); per call min of 3 repeats, median over calls:")
        print(f"    call                        {np.median(call):8.1f} us")
        print(f"    objective evaluations       {np.median(ev):8.1f} us  "
              f"({np.median(ov['n_evals']):.0f} evaluations)")
        print(f"    overhead (call - evals)     {np.median(call - ev):8.1f} us")
        print(f"    overhead / evaluations      {r:8.2f}     (p90 {np.quantile(ov['overhead_ratio'], 0.9):.2f}; "
              "target <= 2)")
        if len(call):
            parts = np.sum([br[s] for s in timing.STAGES], axis=0) / 1e3
            hot, ev_hot = br["call"] / 1e3, br["evaluations"] / 1e3
            rest = hot - ev_hot - parts
            print(f"    overhead by stage (each timed alone, hot: {a.reps} repeats, min of 3; median us):")
            for s in timing.STAGES:
                print(f"      {s:32s}{np.median(br[s]) / 1e3:8.1f}")
            print(f"      {'rest (wrapper, glue, result)':32s}{np.median(rest):8.1f}"
                  "   (hot call - hot evaluations - stages)")
            print(f"      {'cold start':32s}{np.median(call - ev - parts - rest):8.1f}"
                  "   (overhead as replayed - hot overhead)")
            print(f"    hot: call {np.median(hot):.1f} us, evaluations {np.median(ev_hot):.1f} us, "
                  f"overhead / evaluations {np.median((hot - ev_hot) / ev_hot):.2f}")
    print(f"depth overhead ratio: {max(ratios):.2f}")


if __name__ == "__main__":
    main()
