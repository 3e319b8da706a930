"""A-X2 table (EM-EKF vs augmented EKF vs batch ML), long form per case, A-X2-summary.json."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from dataclasses import replace

from opnav.approach import alternatives_summary
from opnav.approach.setup import Setup
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import write_json, write_table
from opnav.report import approach_views
from opnav.report.approach import text as words

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_x2_tables", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    alt_res, em_times = [], {}
    for p in snakemake.input.x2:
        d = load_pickle(p)
        alt_res.extend(d["results"])
        if d["em_times"]:
            em_times[d["variant"]] = d["em_times"]
    em_res = []
    variants = {r.variant for r in alt_res}
    for p in snakemake.input.mc:
        em_res.extend(r for r in load_pickle(p) if r.variant in variants)
    long = alternatives_summary.long_frame(alt_res, em_res, em_times)
    words.with_method_labels(long).to_csv(snakemake.output.long, index=False)  # + the methods' words
    rows = alternatives_summary.method_summaries(long)
    table = approach_views.x2_table(rows)
    write_table(table, snakemake.output.table,
                caption=approach_views.CAPTIONS["A-X2"])
    summ = alternatives_summary.summary_json(long, rows, setup)
    write_json(snakemake.output.summary, replace(summ, profile=snakemake.params.profile))
    log.info("A-X2: %d long rows, %d table rows", len(long), len(table))
