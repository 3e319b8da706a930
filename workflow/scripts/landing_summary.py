"""B-T3 of one camera scenario (per-method accuracy, what the comparison rests
on, planning time beside the published reduction), its summary JSON (headline
numbers for the manuscript and the scorecard), B-F6 (navigation-error 3-sigma
envelopes) and B-F7 (planning-time box plots)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

import pandas as pd

from opnav.core import figures, published
from opnav.landing import timing
from opnav.report.landing import plots
from opnav.report.landing.timing_text import method_text
from opnav.landing.methods import colors as method_colors, labels as method_labels
from opnav.landing.own import compare_own, with_own
from opnav.landing.montecarlo import load
from opnav.landing.accuracy import accuracy_tests
from opnav.report.landing.summary import (end_phase_table, end_phase_text, nees_reading, nees_retuned_text,
                                  scenario_summary, summary_table)
from opnav.landing.trajectory import nominal_truth
from opnav.landing.setup import Equivalence, Setup
from opnav.landing.tuning import RetunedRecord, TuningReport
from opnav.core.snakeio import load_json, mock_snakemake, script_context
from opnav.core.tables import write_json, write_table
from opnav.report.claims import load_plan

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
                caption=(f"B-T3 ({scn} camera), per planning method: navigation errors at touchdown (final), at "
                         "the last vision update (lastvis) and RMS over the descent (mean, median, 3-sigma). It "
                         "adds the filter NEES, the planning calls on the edge of the visible interval and the "
                         "picked landmark's metric over the best detected one's. Per pair of methods: the "
                         "same-pick rate, median |delta beta*| and the paired difference of RMS and final "
                         "position errors with its 95 % interval. The median planning-call time has baselines "
                         f"on the {snakemake.params.eval_path} path over timed_calls and _alt on the other over "
                         "timed_calls_alt, with its reductions on the calls timed on both. Each reduction against "
                         "another method has its bootstrap standard deviation over runs; the published "
                         f"{pub['depth_time_reduction_vs_svd_pct']:g} % (depth vs SVD) is labelled published. Converged: final position error below "
                         f"{snakemake.params.converged_pos_err_m:g} m. " + method_text(tm)))
    single = load_json(snakemake.input.single)
    every = {**data, **{m: load(p) for m, p in zip(snakemake.params.eq_methods, snakemake.input.mc_eq)}}
    # B-C1's margin and same-pick threshold, B-C2's smallest difference: the analysis plan's
    # numbers, their one home
    plan = load_plan(snakemake.input.plan)
    # and (issue 52) B-C2's threshold and its sweep, and the one interval level (alpha = (1 - level) / 2)
    eq = Equivalence.from_config(snakemake.params.equivalence).replace(alpha=(1.0 - plan.level) / 2.0)
    acc = accuracy_tests(every, eq,
                         plan.setting("converge_threshold_m"),
                         margin_rel=plan.margin("B-C1", "margin_rel"),
                         same_pick_max_pct=plan.margin("B-C1", "same_pick_max_pct"),
                         min_difference_s=plan.margin("B-C2", "min_difference_s"),
                         thresholds_m=tuple(plan.setting("converge_threshold_sweep_m")))
    own = getattr(snakemake.params, "custom", None) or {}      # your own methods (landing.custom_methods)
    if own:   # paired against SVD and depth, no verdict (evidence rows of role beyond)
        acc = with_own(acc, compare_own(every, list(own), plan.margin("B-C1", "margin_rel"), (1.0 - plan.level) / 2.0))
    setup = Setup.from_config(snakemake.params.landing)    # the edge: paper B's config parsed once
    out = scenario_summary(scn, df, data, tm, single, setup,
                           eval_path=snakemake.params.eval_path,
                           yaw_ratio=plan.margin("B-C3", "yaw_ratio"),  # the plan's, its one home (issue 52)
                           published_reduction_vs_svd=pub["depth_time_reduction_vs_svd_pct"],
                           accuracy=acc)
    # chosen on a separate seed stream: out["nees"] is held out
    out["tuning"] = TuningReport.from_json(load_json(snakemake.input.tuning))
    # NEES read as it is (held out): consistent, under- or overconfident
    out["nees_reading"] = {m: nees_reading(v, scn) for m, v in out["nees"].items()}
    out["nees_text"] = out["nees_reading"]["depth"].text if "depth" in out["nees_reading"] else ""
    if snakemake.input.get("retuned"):      # the main sample: the retuned filter beside the paper's
        out["nees_retuned"] = RetunedRecord.from_json(load_json(snakemake.input.retuned))
        out["nees_retuned_text"] = nees_retuned_text(out["nees_retuned"])
    # the descent's end from the per-step records against the true altitude
    cut = snakemake.params.cutoff
    t = next(iter(data.values())).t
    alt = nominal_truth(setup, t).r[:, 2]
    end = end_phase_table(every, alt, float(cut["update_altitude_margin_m"]))
    write_table(end, snakemake.output.end_phase,
                caption=(f"B-T3 end phase ({scn} camera), per method over its runs: the time of the last "
                         "landmark update and of the last vision update (median, min, max, s) and the median time "
                         "between them. It counts, from the per-step records, the runs taking a vision update "
                         "with the true altitude below 1 m and below the vision cut-off's margin "
                         f"({float(cut['update_altitude_margin_m']):g} m). The cut-off compares the estimated "
                         f"altitude less that margin with {float(cut['min_update_altitude_m']):g} m."))
    out["end_phase"] = {r["method"]: {k: v for k, v in r.items() if k != "method"} for r in end.to_dict("records")}
    out["end_phase_text"] = end_phase_text(out["end_phase"], scn, float(cut["min_update_altitude_m"]))
    write_json(snakemake.output.summary, out)
    t = next(iter(data.values())).t
    labels = method_labels(own)
    colors = figures.own_colors(list(own), method_colors(own))
    figures.save(plots.fig_nav_error_envelopes(t, data, labels, colors), snakemake.output.f6)
    figures.save(plots.fig_planning_time(tm, methods, pub["depth_time_reduction_vs_svd_pct"], labels, colors),
                 snakemake.output.f7)
    log.info("B-T3 %s:\n%s\npairs:\n%s", scn, df.to_string(),
             pd.DataFrame(list(out["pairs"].values())).to_string())
