"""B-T3 of one camera scenario (per-method accuracy, what the comparison rests
on, planning time beside the published 29.03 %) and its summary JSON (headline
numbers for the manuscript and the scorecard)."""

import json
import math
import sys

from opnav import published
from opnav.landing import timing
from opnav.landing.montecarlo import load, summary_table, yaw_convergence
from opnav.landing.ranking import pair_table
from opnav.landing.scenario import initial_attitude_report
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_json, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_summary", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    pub = published.paper_b()
    scn = snakemake.wildcards.bscn
    methods = list(snakemake.params.methods)
    data = {m: load(p) for m, p in zip(methods, snakemake.input.mc)}
    tm = timing.load(snakemake.input.timing)     # planning times by replay, not the descents'
    df = summary_table(data, tm, published_reduction_vs_svd=pub["depth_time_reduction_vs_svd_pct"],
                       converged_pos_err_m=float(snakemake.params.converged_pos_err_m))
    write_table(df, snakemake.output.t3,
                caption=(f"B-T3 ({scn} camera): per planning method, navigation errors at touchdown "
                         "(final), at the last vision update (lastvis) and RMS over the descent "
                         "(mean, median, 3-sigma), filter NEES, planning calls on the edge of the "
                         "visible interval and the picked landmark's metric over the best detected "
                         "one's; per pair of methods the same-pick rate, median |delta beta*| and "
                         "the paired difference of RMS and final position errors with its 95 % "
                         "interval; median planning-call time ("
                         f"baselines on the {snakemake.params.eval_path} path, _alt on the other) "
                         "and its reduction against each other method (bootstrap standard "
                         "deviation over runs); the published 29.03 % (depth vs SVD) is "
                         "labelled published. Converged: final position error below "
                         f"{snakemake.params.converged_pos_err_m:g} m. " + timing.method_text(tm)))
    with open(snakemake.input.single) as fh:
        single = json.load(fh)
    yaw = yaw_convergence(data[methods[0]], float(snakemake.params.yaw_ratio), methods[0])
    pairs = pair_table(data)
    att = initial_attitude_report(snakemake.params.landing)
    t = df.set_index("method")
    out = {
        "scenario": scn,
        "single": single,
        "methods": {r["method"]: dict(r) for r in df.to_dict("records")},
        "pairs": {f"{r['method_a']}_vs_{r['method_b']}": dict(r) for r in pairs.to_dict("records")},
        "time_reduction_vs_svd_pct": (float(t.loc["depth", "time_reduction_vs_svd_pct"])
                                      if {"svd", "depth"} <= set(t.index) else None),
        "eval_path": snakemake.params.eval_path,
        "timing": timing.method_summary(tm),
        "published_time_reduction_vs_svd_pct": pub["depth_time_reduction_vs_svd_pct"],
        "initial_attitude_deg": att["paper_convention_deg"],
        "initial_tilt_deg": att["tilt_deg"],
        "initial_azimuth_deg": att["azimuth_deg"],
        "yaw_converges": yaw["converges"],
        "yaw_reason": yaw["reason"],
        "n_runs": yaw["n_runs"],
        "min_same_pick_vs_depth_pct": float(min((t.loc[m, "same_pick_as_depth_pct"] for m in methods
                                                 if m != "depth"), default=math.nan)),
    }
    write_json(snakemake.output.summary, out)
    log.info("B-T3 %s:\n%s\npairs:\n%s", scn, df.to_string(), pairs.to_string())
