"""Paper-A benchmark (printed figures, not a timed test).

    python benchmarks/bench_approach.py            # EM iteration timings
    python benchmarks/bench_approach.py --workflow # also the whole part-A workflow, full profile

Reports the wall time of one EM iteration (EKF + smoother + E/M step) on a
250-sample segment for a batch of seeds, per seed count, and optionally the
wall time of `snakemake --cores 2` for every part-A output from an empty
results directory (in a temporary copy of the workflow).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from opnav.snakeio import copy_workflow

REPO = Path(__file__).resolve().parents[1]


def em_iteration_timing(n_samples: int = 250, seeds=(1, 20, 100), repeats: int = 5) -> list[dict]:
    from opnav.approach import em, scenario as sc
    from opnav.config import load_config

    cfg = load_config(REPO / "config" / "config.yaml")["approach"]
    geo = sc.build_geometry(cfg, "roll", n=n_samples)
    Rvar = sc.measurement_variance(geo, cfg, cfg["camera"]["sigma3_px"])
    win = geo.window(Rvar)
    rows = []
    for S in seeds:
        z, _ = sc.simulate(geo, Rvar, sc.rad(cfg["truth_bias_arcsec"]), sc.seed_streams(1, 1, range(S)))
        theta = np.zeros((S, 3))
        x0 = np.zeros((S, 6))
        em.em_map(theta, z, x0, geo.P0, win, 1e-6)  # warm-up
        t = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            em.em_map(theta, z, x0, geo.P0, win, 1e-6)
            t.append(time.perf_counter() - t0)
        best = min(t)
        rows.append({"seeds": S, "samples": n_samples, "em_iteration_s": best,
                     "per_seed_ms": 1e3 * best / S})
    return rows


def workflow_timing(configfile: str | None = None) -> float:
    with tempfile.TemporaryDirectory() as d:
        dst = copy_workflow(REPO, Path(d))
        targets = ["results/approach/A-T1_table1.csv", "results/approach/A-X1_crlb.pdf"] + [
            f"results/approach/A-F4_bias_estimate_{v}.pdf" for v in ("literal", "prior", "roll", "reference-start")]
        cmd = [sys.executable, "-m", "snakemake", "--cores", "2", *targets]
        if configfile:
            cmd += ["--configfile", configfile]
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=dst, check=True, capture_output=True)
        return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workflow", action="store_true", help="also time the whole part-A workflow")
    ap.add_argument("--configfile", default=None, help="overlay config for the workflow run (e.g. config/quick.yaml)")
    args = ap.parse_args()
    print("one EM iteration (EKF + RTS/Bryson-Frazier smoother + E-step + closed-form M-step), 250 samples:")
    for r in em_iteration_timing():
        print(f"  seeds={r['seeds']:4d}: {r['em_iteration_s'] * 1e3:8.1f} ms  ({r['per_seed_ms']:.2f} ms per seed)")
    if args.workflow:
        w = workflow_timing(args.configfile)
        print(f"part-A workflow, snakemake --cores 2 from empty results/: {w:.1f} s")


if __name__ == "__main__":
    main()
