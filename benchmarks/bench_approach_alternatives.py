"""A-X2 benchmark: run time per method per case (printed figures, not a timed test).

    python benchmarks/bench_approach_alternatives.py              # full profile, literal + roll
    python benchmarks/bench_approach_alternatives.py --quick      # quick profile
    python benchmarks/bench_approach_alternatives.py --seeds 5 --cases T1-01 T1-10

For each scenario variant and Table-1 case, on the same seeds and data, the
wall time per Monte-Carlo seed of: the EM-EKF (``cases.run_case``, each EM
scheme of the config), the augmented EKF, and the batch ML (NLP build incl.
JIT compilation once per process, preconditioner and IPOPT on the final
window; then the growing-window checkpoints separately). Also prints the
estimates' RMS error (tx, ty) so the times can be read beside the accuracy.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    from opnav.approach import alternatives as alt
    from opnav.approach import cases
    from opnav.approach import scenario as sc
    from opnav.core.config import load_config

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="use config/quick.yaml")
    ap.add_argument("--seeds", type=int, default=None, help="seeds per case (default: the config's)")
    ap.add_argument("--cases", nargs="*", default=["T1-01", "T1-09", "T1-12"], help="case ids")
    ap.add_argument("--variants", nargs="*", default=["literal", "roll"])
    args = ap.parse_args(argv)
    from opnav.approach.setup import Setup

    cfg = Setup.from_config(load_config(overlays=[REPO / "config" / "quick.yaml"] if args.quick else [])["approach"])
    S = args.seeds or cfg.n_seeds
    seeds = range(S)
    allc = {c.case_id: c for c in cases.table1_cases(cfg)}
    print(f"profile={'quick' if args.quick else 'full'} seeds={S} segments={cfg.segments.as_dict()}")
    hdr = f"{'variant':8s} {'case':6s} {'method':22s} {'s/seed':>9s} {'rmse_x':>8s} {'rmse_y':>8s}"
    print(hdr)
    print("-" * len(hdr))
    for v in args.variants:
        geo = sc.build_geometry(cfg, v)
        cache = alt._BatchCache()
        for cid in args.cases:
            case = allc[cid]
            truth = np.asarray(case.truth_arcsec)

            def rmse(th):
                return np.sqrt(np.mean((th[:, :2] - truth[:2]) ** 2, axis=0))

            for m in cfg.methods:
                t = time.perf_counter()
                r = cases.run_case(cfg, v, case, seeds, geo=geo, method=m)
                dt = (time.perf_counter() - t) / S
                e = rmse(r.theta_final_arcsec)
                print(f"{v:8s} {cid:6s} {'EM-EKF (' + m + ')':22s} {dt:9.4f} {e[0]:8.3f} {e[1]:8.3f}")
            r = alt.run_case_alternatives(cfg, v, case, seeds, geo, cache)
            a, b = r.augmented, r.batch_ml
            e = rmse(a.theta_final_arcsec)
            print(f"{v:8s} {cid:6s} {'augmented EKF':22s} {a.runtime_s_per_seed:9.4f} {e[0]:8.3f} {e[1]:8.3f}")
            e = rmse(b.theta_final_arcsec)
            print(f"{v:8s} {cid:6s} {'batch ML (incl build)':22s} {b.runtime_s_per_seed:9.4f} {e[0]:8.3f} {e[1]:8.3f}")
            print(f"{v:8s} {cid:6s} {'batch ML (solve only)':22s} {b.runtime_solve_s_per_seed:9.4f}")
            if b.checkpoint_data_used is not None:
                print(f"{v:8s} {cid:6s} {'batch ML checkpoints':22s} {b.runtime_checkpoints_s_per_seed:9.4f}"
                      f"   ({len(b.checkpoint_data_used)} growing windows)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
