"""B-T3 of one camera scenario (per-method accuracy, what the comparison rests
on, planning time beside the published 29.03 %), its summary JSON (headline
numbers for the manuscript and the scorecard), B-F6 (navigation-error 3-sigma
envelopes) and B-F7 (planning-time box plots)."""

import sys

import pandas as pd

from opnav.core import figures, published
from opnav.landing import plots, timing
from opnav.landing.montecarlo import load
from opnav.landing.report import accuracy_tests, scenario_summary, summary_table
from opnav.core.snakeio import load_json, mock_snakemake, script_context
from opnav.core.tables import write_json, write_table

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
                         f"baselines on the {snakemake.params.eval_path} path over timed_calls, _alt on the "
                         "other over timed_calls_alt, its reductions on the calls timed on both) "
                         "and its reduction against each other method (bootstrap standard "
                         "deviation over runs); the published 29.03 % (depth vs SVD) is "
                         "labelled published. Converged: final position error below "
                         f"{snakemake.params.converged_pos_err_m:g} m. " + timing.method_text(tm)))
    single = load_json(snakemake.input.single)
    every = {**data, **{m: load(p) for m, p in zip(snakemake.params.eq_methods, snakemake.input.mc_eq)}}
    acc = accuracy_tests(every, snakemake.params.equivalence, float(snakemake.params.converged_pos_err_m))
    out = scenario_summary(scn, df, data, tm, single, snakemake.params.landing,
                           eval_path=snakemake.params.eval_path,
                           yaw_ratio=float(snakemake.params.yaw_ratio),
                           published_reduction_vs_svd=pub["depth_time_reduction_vs_svd_pct"],
                           accuracy=acc)
    out["tuning"] = load_json(snakemake.input.tuning)        # chosen on a separate seed stream: out["nees"] is held out
    write_json(snakemake.output.summary, out)
    t = next(iter(data.values()))["t"]
    figures.save(plots.fig_nav_error_envelopes(t, data), snakemake.output.f6)
    figures.save(plots.fig_planning_time(tm, methods, pub["depth_time_reduction_vs_svd_pct"]),
                 snakemake.output.f7)
    log.info("B-T3 %s:\n%s\npairs:\n%s", scn, df.to_string(),
             pd.DataFrame(list(out["pairs"].values())).to_string())
