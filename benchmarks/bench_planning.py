"""Planning-call benchmark (issue 14 target): the depth-error call's overhead
(all but its objective evaluations) over the evaluations themselves, measured
by replay of recorded planning calls (opnav.landing.timing.call_overhead), and
the replay's per-method times on the same calls.

    PYTHONPATH=src python benchmarks/bench_planning.py [--runs 3] [--calls 200] [--scenario interior]

Last line: ``depth overhead ratio: X`` (median over calls of (call - evals) /
evals, thread CPU clock; the target is at most 2).
"""

import argparse
import time

import numpy as np

from opnav.config import load_config
from opnav.landing import timing
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import run_chunk
from opnav.landing.scenario import camera_scenarios


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=3, help="descents flown per method (run indices 0..)")
    ap.add_argument("--calls", type=int, default=200, help="recorded calls replayed (0 = all)")
    ap.add_argument("--scenario", default=None, help="camera scenario (default: every one)")
    ap.add_argument("--methods", default="depth,svd,gdop,cond", help="methods replayed, comma-separated")
    a = ap.parse_args()
    land = load_config()["landing"]
    scns = camera_scenarios(land)
    names = [a.scenario] if a.scenario else list(scns)
    methods = a.methods.split(",")
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
        red = timing.time_reduction(tm, "depth", "svd") if "svd" in methods else (np.nan, np.nan)
        print(f"[{name}] depth vs svd median reduction (wall): {red[0]:.1f} % +- {red[1]:.1f}")
        ov = timing.call_overhead(scn, rec, "depth", a.calls)
        r = float(np.median(ov["overhead_ratio"]))
        ratios.append(r)
        print(f"[{name}] depth call (thread CPU, min of 3): median {np.median(ov['call_ns']) / 1e3:.1f} us, "
              f"its {np.median(ov['n_evals']):.0f} evaluations {np.median(ov['evals_ns']) / 1e3:.1f} us, "
              f"overhead ratio median {r:.2f} (p90 {np.quantile(ov['overhead_ratio'], 0.9):.2f}) "
              f"over {len(ov['call_ns'])} calls ({int(ov['edge'].sum())} edge calls: detected "
              "landmarks batch-scored, counted as evaluations)")
    print(f"depth overhead ratio: {max(ratios):.2f}")


if __name__ == "__main__":
    main()
