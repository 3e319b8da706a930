"""B-T3 (per-method accuracy and planning time beside the published 29.03 %)
and results/landing/B-summary.json (headline numbers for the manuscript)."""

import json
import math


from opnav import published
from opnav.landing.montecarlo import load, summary_table
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_json, write_table

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(
        input={"mc": [f"results/landing/mc/{m}.npz" for m in ("depth", "svd", "gdop", "cond")],
               "single": "results/landing/single/summary.json"},
        output={"t3": ["results/landing/B-T3_summary.csv"], "summary": "results/landing/B-summary.json"})
    snakemake.params = type("P", (), {"methods": ["depth", "svd", "gdop", "cond"],
                                      "yaw_ratio": 0.5, "converged_pos_err_m": 100.0})()


with script_context(snakemake) as log:
    pub = published.paper_b()
    data = {m: load(p) for m, p in zip(snakemake.params.methods, snakemake.input.mc)}
    df = summary_table(data, published_reduction_vs_svd=pub["depth_time_reduction_vs_svd_pct"],
                       converged_pos_err_m=float(snakemake.params.converged_pos_err_m))
    write_table(df, snakemake.output.t3,
                caption=("B-T3: per planning method, final and RMS navigation errors over the "
                         "Monte Carlo (mean and 3-sigma), filter NEES, median planning-call time "
                         "and objective evaluations per call, and the time reduction against "
                         "each other method; the published 29.03 % (depth vs SVD) is labelled "
                         "published. Converged: final position error below "
                         f"{snakemake.params.converged_pos_err_m:g} m."))
    with open(snakemake.input.single) as fh:
        single = json.load(fh)
    # yaw: does its Monte-Carlo 3-sigma envelope shrink? (paper: it does not)
    d0 = data[snakemake.params.methods[0]]
    yaw = d0["err_rpy_deg"][:, :, 2]
    s_first, s_last = float(3 * yaw[:, 0].std(ddof=1)), float(3 * yaw[:, -1].std(ddof=1))
    ratio = float(snakemake.params.yaw_ratio)
    converges = s_last < ratio * s_first
    out = {
        "single": single,
        "methods": {r["method"]: dict(r) for r in df.to_dict("records")},
        "time_reduction_vs_svd_pct": (df.set_index("method").get("time_reduction_vs_svd_pct",
                                                                      {}).get("depth", math.nan))
        if "svd" in data and "depth" in data else None,
        "published_time_reduction_vs_svd_pct": pub["depth_time_reduction_vs_svd_pct"],
        "initial_attitude_deg": single["initial_attitude_deg"],
        "yaw_converges": bool(converges),
        "yaw_reason": (f"yaw 3-sigma over the {yaw.shape[0]} runs ({snakemake.params.methods[0]}): "
                       f"{s_first:.2f} deg at start, {s_last:.2f} deg at touchdown "
                       f"({'below' if converges else 'not below'} {ratio:.0%} of the start)"),
        "n_runs": int(yaw.shape[0]),
    }
    write_json(snakemake.output.summary, out)
    log.info("B-T3:\n%s", df.to_string())
