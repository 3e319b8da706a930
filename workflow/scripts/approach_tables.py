"""A-T1 (Table 1 beside the published values), A-X1 table + verdict text, A-summary.json."""

import sys

from opnav.approach import readings, summaries
from opnav.approach.setup import Setup
from opnav.core import published
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_json, write_table
from opnav.report import approach_text, approach_views

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
    t1 = summaries.table1_frame(results, pub, target)
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
        summ["stars"] = summaries.stars_summary(load_pickle(snakemake.input.stars), target)
    summ["nees"] = summaries.nees_summary(t1)  # each compensated filter against the true-theta filter
    if "camera" in snakemake.params.approach:  # (the replication's tables pass no camera: main sample's bounds)
        summ["mars_attitude"] = summaries.mars_attitude_summary(setup, curves.get("mars_attitude"), curves["Q"])
    if "roll_rate" in curves:  # the bound against the roll rate (A-C1's would_take, scored from the plan)
        summ["roll_rate_bound"] = summaries.roll_rate_bound_summary(curves["roll_rate"])
    if "nav_arc" in snakemake.input.keys():  # navigation error against arc length (A-C7's would_take); tz on
        nav_arc = load_pickle(snakemake.input.nav_arc)           # and off (not in the replication's tables)
        summ["nav_floor_by_arc"] = summaries.nav_floor_summary(nav_arc["nav_floor_by_arc"])
        summ["tz_nav_effect"] = nav_arc["tz_nav_effect"]
    summ["figures_5_6"] = summaries.figures_5_6(results)
    summ["profile"] = snakemake.params.profile
    summ["text"] = approach_text.findings(setup, summaries.HeadlineSummary.from_json(summ), pub["headline"], target)  # the manuscript's finding sentences
    if "readings" in curves:  # the installation rows and the sample time (opnav.approach.readings)
        chk = curves["readings"]["installation"]
        summ["installation"] = {**chk, **summaries.installation_summary(chk)}
        summ["sample_time"] = curves["readings"]["sample_time"]
        summ["text"]["installation"] = readings.installation_text(chk)
        summ["text"]["sample_time"] = readings.sample_time_text(summ["sample_time"])
    write_json(snakemake.output.summary, summ)
    log.info("wrote %d Table-1 rows", len(t1))
