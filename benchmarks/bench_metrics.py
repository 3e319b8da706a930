"""Timing of the landmark-selection metrics (paper B sec. 2.2 baselines, B-X1).

Description
-----------
Project issue 5 ("Fair timing"): the paper's Fig. 7 compares planning times of
its depth-error model against matrix metrics; how fast a matrix metric is
depends on how it is implemented, so this script times both implementations of
every metric of :mod:`opnav.landing.metrics` on the same inputs:

* ``fast``       ``metric(ctx, cand)``: the compiled closed form (svd, gdop, cond;
  ``planning.hmetrics.h_metric``) or the batched tangent update / Gram eigenvalues;
* ``reference``  ``metric.reference(ctx, cand)``: the paper's definition, H of
  eq. 14-18 from CasADi (``Function.map``), LAPACK SVD / pinv.

A second table times the Jacobian alone by each route (per-candidate
Function, ``Function.map`` serial and thread, numpy).

A "call" is one planning call of n candidate evaluations (default n = 50, the
order of a golden-section search to 1e-3 rad over a 60 deg field of view);
``ctx`` is the cost of building the :class:`MetricContext` once per call (not
included in the per-call figures).  Each figure is the median over ``--reps``
repetitions of ``time.perf_counter_ns``, the repetitions interleaved across
all (metric, implementation) pairs so that load on a shared machine hits them
alike; ``ratio_to_svd`` divides by the svd
metric's time with the same implementation.  Geometry: paper B Table 1 initial
state, candidates uniformly on the ground in a +-6 km square.

Use::

    python benchmarks/bench_metrics.py [--n 50] [--reps 30] [--csv out.csv]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from opnav.landing import casadi_model as cm
from opnav.landing import measurement as me
from opnav.landing.metrics import METRIC_NAMES, MetricContext, make_metric

IMPLEMENTATIONS = ("fast", "reference")


def make_inputs(n: int, seed: int = 0):
    """(ctx kwargs, candidates (n, 3)) at paper B's initial state."""
    rng = np.random.default_rng(seed)
    r = np.array([3300.0, 5870.0, 6570.0])
    R = Rotation.from_euler("xyz", [-25.7, -9.8, 0.0], degrees=True).as_matrix()
    P = np.diag([577.0**2] * 3 + [5.8**2] * 3 + [np.deg2rad(1.15) ** 2] * 3 + [2000.0**2] * 3)
    kw = dict(
        r_L=r, v_L=np.array([-56.0, -66.0, -90.0]), R_LtoB=R, p_known_L=np.zeros(3),
        P=P, R_meas=(5e-4) ** 2 * np.eye(6), boresight_B=None,
    )
    cand = rng.uniform(-6000.0, 6000.0, size=(n, 3))
    cand[:, 2] = 0.0
    return kw, cand


def _median_ns(fn, reps: int) -> float:
    fn()  # warm-up (CasADi map compilation, caches)
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter_ns()
        fn()
        ts.append(time.perf_counter_ns() - t0)
    return float(np.median(ts))


def _paths(m, ctx, cand) -> dict:
    return {"fast": lambda: m(ctx, cand), "reference": lambda: m.reference(ctx, cand)}


def run(n: int = 50, reps: int = 30, seed: int = 0) -> pd.DataFrame:
    """Time every (metric, implementation); the repetitions are interleaved
    (each repetition runs every pair once) so that load changes on a shared
    machine hit all implementations alike and the ratios stay comparable."""
    kw, cand = make_inputs(n, seed)
    ctx = MetricContext(**kw)
    cm.jacobian_map(n)  # build the mapped Function outside the timing
    jobs, meta = {}, {}
    for name in METRIC_NAMES:
        m = make_metric(name)
        ref = m.reference(ctx, cand)
        for impl, fn in _paths(m, ctx, cand).items():
            vals = np.ravel(np.asarray(fn(), dtype=float))  # also the warm-up
            meta[name, impl] = float(np.max(np.abs(vals - ref) / np.maximum(np.abs(ref), 1e-300)))
            jobs[name, impl] = fn
    jobs["ctx", ""] = lambda: MetricContext(**kw)
    times = {k: [] for k in jobs}
    for _ in range(reps):
        for k, fn in jobs.items():
            t0 = time.perf_counter_ns()
            fn()
            times[k].append(time.perf_counter_ns() - t0)
    rows = []
    for (name, impl), err in meta.items():
        t = float(np.median(times[name, impl]))
        rows.append(
            dict(metric=name, impl=impl, n=n, us_per_call=t / 1e3, us_per_eval=t / 1e3 / n, max_rel_diff_vs_ref=err)
        )
    df = pd.DataFrame(rows)
    svd = df[df.metric == "svd"].set_index("impl").us_per_call
    df["ratio_to_svd"] = df.us_per_call / df.impl.map(svd)
    df.attrs["us_ctx"] = float(np.median(times["ctx", ""])) / 1e3
    return df


def run_jacobian(n: int = 50, reps: int = 30, seed: int = 0) -> pd.DataFrame:
    """The Jacobian alone (n candidates -> (n, 6, 12) ndarray) by each route."""
    kw, cand = make_inputs(n, seed)
    args = (kw["r_L"], kw["v_L"], kw["p_known_L"])
    R = kw["R_LtoB"]
    routes = {
        "casadi_per_cand": lambda: [cm.jacobian_casadi(*args, p, R) for p in cand],
        "casadi_map_serial": lambda: cm.jacobian_casadi_batch(*args, cand, R, "serial"),
        "casadi_map_thread": lambda: cm.jacobian_casadi_batch(*args, cand, R, "thread"),
        "numpy": lambda: me.selection_jacobian(kw["r_L"], R, kw["p_known_L"], cand),
    }
    rows = []
    for k, f in routes.items():
        t = _median_ns(f, reps)
        rows.append(dict(route=k, n=n, us_per_call=t / 1e3, us_per_eval=t / 1e3 / n))
    return pd.DataFrame(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=50, help="candidate evaluations per planning call")
    ap.add_argument("--reps", type=int, default=30, help="repetitions (median)")
    ap.add_argument("--csv", default=None, help="also write the table as CSV")
    a = ap.parse_args(argv)
    df = run(a.n, a.reps)
    with pd.option_context("display.width", 200, "display.max_rows", 200):
        print(f"MetricContext build: {df.attrs['us_ctx']:.1f} us per planning call")
        print(df.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
        print()
        print("us per call (n = %d evaluations), median of %d:" % (a.n, a.reps))
        print(df.pivot(index="impl", columns="metric", values="us_per_call")
              .loc[list(IMPLEMENTATIONS), list(METRIC_NAMES)].to_string(float_format=lambda x: f"{x:.1f}"))
        print()
        print("Jacobian H only (n = %d):" % a.n)
        print(run_jacobian(a.n, a.reps).to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    if a.csv:
        df.to_csv(a.csv, index=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
