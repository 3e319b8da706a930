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
overhead by stage, each stage timed alone on the same calls (``--reps``
repeats per timing, minimum of 3): plane, visible interval, objective build
(eq. 19 and 22 constants), the search loop beyond its evaluations, the eq. 26
ground point, the edge rule's candidate list (its batch scoring counts as
evaluations), the nearest-landmark pick, and the rest (the call's wrapper,
result and clocks: the per-call remainder).

Last line: ``depth overhead ratio: X`` (the largest scenario's median ratio).
"""

import argparse
import time

import numpy as np

from opnav.config import load_config
from opnav.landing import planner as pl
from opnav.landing import timing
from opnav.landing.depth_error import ground_point_scalar, plane_geometry
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import run_chunk
from opnav.landing.scenario import camera_scenarios

STAGES = ("plane", "visible interval", "objective build", "search loop beyond evals",
          "ground point", "edge candidate list", "nearest-landmark pick")


def _timed(fn, reps: int, repeats: int = 3) -> float:
    """Thread CPU ns of one ``fn()``: ``reps`` calls per timing, the minimum of ``repeats``."""
    best = None
    for _ in range(repeats):
        c0 = time.thread_time_ns()
        for _ in range(reps):
            fn()
        dt = (time.thread_time_ns() - c0) / reps
        best = dt if best is None else min(best, dt)
    return best


def stage_breakdown(scn, d: dict, method: str, sel: np.ndarray, reps: int) -> dict:
    """Per selected call of ``d`` (a Monte-Carlo dict), the thread CPU ns of each
    stage of ``planner._plan`` for ``method``, timed alone (:data:`STAGES`); the
    search loop is the golden-section searches minus their evaluations (both
    timed here); calls without a visible interval are skipped, as
    ``timing.call_overhead`` skips them."""
    cam, field_, tr, cfg = scn.camera, scn.field, scn.truth, scn.planner
    build = pl.OBJECTIVES[method]
    out = {s: [] for s in STAGES}
    for i in sel:
        k = int(d["plan_step"][i])
        r_t, R_t = tr.r[k], tr.R_LtoB[k]
        det = np.flatnonzero(cam.in_view((field_.xyz - r_t) @ R_t.T, cfg.margin_px))
        state = pl.PlanState(d["plan_r"][i], d["plan_v"][i], d["plan_a"][i], d["plan_R"][i],
                             d["plan_P"][i])
        ex = int(d["plan_exclude"][i])
        exclude = {ex} if ex >= 0 else set()
        geom = plane_geometry(state.r, state.v)
        ivs = pl.visible_intervals(geom, state.R_LtoB, cam, cfg.n_grid, cfg.margin_px)
        if not ivs:
            continue
        f = build(state=state, geom=geom, cfg=cfg, camera=cam, sigma_b=cam.sigma_b)
        betas = []

        def spy(b, f=f, betas=betas):
            betas.append(b)
            return f(b)

        best = (np.inf, np.nan, np.nan, np.nan)
        for a, b in ivs:
            x, fx, _ = pl.golden_section(spy, a, b, cfg.tol_rad)
            if fx < best[0] or np.isnan(best[1]):
                best = (fx, x, a, b)
        _, x, a, b = best
        edge = min(x - a, b - x) <= cfg.tol_rad
        point = np.array(ground_point_scalar(geom)(x))

        def search():
            for a_, b_ in ivs:
                pl.golden_section(f, a_, b_, cfg.tol_rad)

        def evals():
            for bb in betas:
                f(bb)

        out["plane"].append(_timed(lambda: plane_geometry(state.r, state.v), reps))
        out["visible interval"].append(_timed(
            lambda: pl.visible_intervals(geom, state.R_LtoB, cam, cfg.n_grid, cfg.margin_px), reps))
        out["objective build"].append(_timed(
            lambda: build(state=state, geom=geom, cfg=cfg, camera=cam, sigma_b=cam.sigma_b), reps))
        out["search loop beyond evals"].append(_timed(search, reps) - _timed(evals, reps))
        out["ground point"].append(_timed(lambda: np.array(ground_point_scalar(geom)(x)), reps))
        out["edge candidate list"].append(_timed(lambda: pl._candidates(det, exclude), reps)
                                          if edge else 0.0)
        cand = pl._candidates(det, exclude) if edge else None
        nearest = not edge or not cand.size or not np.isfinite(f.batch(field_.xyz[cand])).any()
        out["nearest-landmark pick"].append(
            _timed(lambda: pl._pick_nearest(field_, point, det, exclude), reps) if nearest else 0.0)
    return {s: np.asarray(v) for s, v in out.items()}


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
        ov = timing.call_overhead(scn, rec, "depth", a.calls)
        sel = timing.select_calls(len(rec["depth"]["plan_step"]), a.calls)
        br = stage_breakdown(scn, rec["depth"], "depth", sel, a.reps)
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
        if len(br["plane"]) == len(call):
            parts = np.sum([br[s] for s in STAGES], axis=0) / 1e3
            print(f"    overhead by stage (each timed alone, {a.reps} repeats, min of 3; median us):")
            for s in STAGES:
                print(f"      {s:28s}{np.median(br[s]) / 1e3:8.1f}")
            print(f"      {'rest (wrapper, result, clocks)':28s}"
                  f"{np.median(call - ev - parts):8.1f}")
    print(f"depth overhead ratio: {max(ratios):.2f}")


if __name__ == "__main__":
    main()
