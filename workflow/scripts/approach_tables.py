"""A-T1 (Table 1 beside the published values), A-X1 table + verdict text, A-summary.json."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from dataclasses import replace

from opnav.approach import summaries
from opnav.approach.setup import Setup
from opnav.core import published
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, json_ready, write_json, write_table
from opnav.report import approach_text, approach_views
from opnav.report.approach import text as words

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_tables", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    results = []
    for p in snakemake.input.mc:
        results.extend(load_pickle(p))
    conv = {}
    for p in snakemake.input.conv:
        c = load_pickle(p)
        conv[c.variant] = c
    curves = load_pickle(snakemake.input.crlb)
    pub = published.paper_a()
    target = snakemake.params.target  # the claimed accuracy: A-C1's target (the analysis plan)
    t1 = words.with_readings(summaries.table1_frame(results, pub, target), results, target)  # + each run's reading
    csv, tex, md = snakemake.output.t1
    cap = approach_views.CAPTIONS["A-T1"]
    write_table(t1, [csv], caption=cap)  # every column
    write_table(approach_views.table1_compact(t1), [tex, md], caption=cap)  # the columns that fit a page
    x1 = summaries.crlb_rows(setup, curves["Q"], conv, t1, target, curves["Q0"])
    write_table(x1, snakemake.output.x1,
                caption=approach_views.CAPTIONS["A-X1"])
    atomic_write_text(snakemake.output.verdict, approach_text.identifiability_text(setup, x1, target))
    summ = summaries.summary(setup, t1, x1, target, curves.get("roll_rate"))
    if snakemake.input.stars:  # the stars variant (beyond the paper)
        summ = summ.replace(stars=summaries.stars_summary(load_pickle(snakemake.input.stars), target))
    summ = summ.replace(nees=summaries.nees_summary(t1))  # each compensated filter against the true-theta filter
    if "camera" in snakemake.params.approach:  # (the replication's tables pass no camera: main sample's bounds)
        summ = summ.replace(mars_attitude=summaries.mars_attitude_summary(setup, curves.get("mars_attitude"),
                                                                          curves["Q"]))
    if "roll_rate" in curves:  # the bound against the roll rate (A-C1's would_take, scored from the plan)
        summ = summ.replace(roll_rate_bound=summaries.roll_rate_bound_summary(curves["roll_rate"]))
    if "nav_arc" in snakemake.input.keys():  # navigation error against arc length (A-C7's would_take); tz on
        nav_arc = load_pickle(snakemake.input.nav_arc)           # and off (not in the replication's tables)
        summ = summ.replace(nav_floor_by_arc=summaries.nav_floor_summary(nav_arc["nav_floor_by_arc"]),
                            tz_nav_effect=nav_arc["tz_nav_effect"])
    summ = summ.replace(figures_5_6=summaries.figures_5_6(results), profile=snakemake.params.profile)
    summ = words.with_words(summ, t1)  # the words beside the numbers (report layer)
    # the manuscript's finding sentences, from the summary as the report reads it back
    text = approach_text.findings(setup, summaries.HeadlineSummary.from_json(json_ready(summ, nan_as_none=False)),
                                  pub["headline"], target)
    if "readings" in curves:  # the installation rows and the sample time (opnav.approach.readings)
        chk, st = curves["readings"]["installation"], curves["readings"]["sample_time"]
        summ = summ.replace(installation=replace(chk, why=words.installation_why(chk)), sample_time=st)
        text = {**text, "installation": words.installation_text(chk), "sample_time": words.sample_time_text(st)}
    write_json(snakemake.output.summary, summ.replace(text=text))
    log.info("wrote %d Table-1 rows", len(t1))
