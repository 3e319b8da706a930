"""Paper B filter tuning evidence: NEES and final errors of filter
configurations on the same seeded descents (issue 10, step 6).

    PYTHONPATH=src python benchmarks/bench_landing_filter.py [n_runs] [method]

Prints, per configuration (bearing-noise scale, update iterations), the mean
position / velocity NEES over runs and time (3 degrees of freedom: a
consistent filter gives ~3), the position error at the last vision update and
at touchdown (mean, median, 3 sigma over runs) and the final yaw 1-sigma.
"""

import sys
import time

import numpy as np
from scipy.stats import chi2

from opnav.core.config import load_config
from opnav.landing.montecarlo import per_run_stats, run_chunk
from opnav.landing.setup import Setup

CONFIGS = [(8.0, 1), (1.0, 1), (2.0, 3), (4.0, 3), (5.0, 3), (6.0, 3), (8.0, 3)]


def main(n_runs: int = 10, method: str = "depth") -> None:
    base = Setup.from_config(load_config()["landing"])
    lo, hi = chi2.ppf(0.025, 3 * n_runs) / n_runs, chi2.ppf(0.975, 3 * n_runs) / n_runs
    print(f"{n_runs} runs, method {method}; NEES for 3 dof, 95 % band of a {n_runs}-run mean "
          f"[{lo:.2f}, {hi:.2f}]")
    print(f"{'scale':>5} {'iter':>4} {'NEES r':>7} {'NEES v':>7} {'lastvis mean/med/3s (m)':>26} "
          f"{'touchdown mean/med/3s (m)':>28} {'yaw sig (deg)':>13} {'s/run':>6} in band")
    for scale, it in CONFIGS:
        cfg = base.with_filter(meas_noise_scale=scale, iterations=it)
        t0 = time.perf_counter()
        d = run_chunk(cfg, method, range(n_runs))
        dt = (time.perf_counter() - t0) / n_runs
        st = per_run_stats(d)
        lv, fi = st["lastvis_pos_err_m"], st["final_pos_err_m"]
        print(f"{scale:5g} {it:4d} {st['mean_nees_pos'].mean():7.2f} {st['mean_nees_vel'].mean():7.2f} "
              f"{lv.mean():8.2f} {lv.median():8.2f} {3 * lv.std(ddof=1):8.2f} "
              f"{fi.mean():9.2f} {fi.median():9.2f} {3 * fi.std(ddof=1):8.2f} "
              f"{np.mean(d.sig_yaw_deg[:, -1]):13.3f} {dt:6.2f} "
              f"{lo < st['mean_nees_pos'].mean() < hi and lo < st['mean_nees_vel'].mean() < hi}")


if __name__ == "__main__":
    main(*(int(a) if i == 0 else a for i, a in enumerate(sys.argv[1:])))
