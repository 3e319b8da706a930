"""The reproduced-vs-published scorecard from the generated tables and summaries."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import json
import sys

from opnav.approach.summaries import HeadlineSummary
from opnav.core import published
from opnav.core.snakeio import load_json, load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table
from opnav.landing.bsummary import BSummary
from opnav.report.landing.summary import rows_paper_b
from opnav.report import scorecard
from opnav.report.approach_scorecard import rows_paper_a
from opnav.report.claims import load_plan

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_scorecard", argv=sys.argv[1:])

with script_context(snakemake) as log:
    inp = snakemake.input
    rows = []
    if "a_table1" in inp.keys():
        summary_a = load_json(inp["summary_A"]) if "summary_A" in inp.keys() else {}
        rows += rows_paper_a(load_table(inp["a_table1"]), HeadlineSummary.from_json(summary_a), published.paper_a())
    if "b_summary_table" in inp.keys():
        summary_b = load_json(inp["summary_B"]) if "summary_B" in inp.keys() else {}
        # B-C4's band (the analysis plan's numbers, as the claims table judges it)
        plan = load_plan(inp["plan"])
        band = {"rel_tol": plan.margin("B-C4", "rel_tol"), "k_spread": plan.margin("B-C4", "spread_k"),
                "max_band_rel": plan.margin("B-C4", "max_band_rel")}
        rows += rows_paper_b(load_table(inp["b_summary_table"]), BSummary.from_json(summary_b), published.paper_b(),
                             band)
    df = scorecard.score_rows(rows)
    write_table(df, snakemake.output.table, caption=scorecard.CAPTION)
    atomic_write_text(snakemake.output.longtable, scorecard.to_longtable(df))
    write_table(scorecard.verdict_counts(df), [snakemake.output.counts], float_format="{:.0f}")
    write_table(scorecard.headline(df), [snakemake.output.headline])
    counts = df["verdict"].value_counts().to_dict() if len(df) else {}
    atomic_write_text(snakemake.output.json, json.dumps(
        {"n_items": len(df), "verdicts": {k: int(v) for k, v in sorted(counts.items())},
         "by_paper": {p: {k: int(v) for k, v in sorted(g["verdict"].value_counts().items())}
                      for p, g in df.groupby("paper")}},
        indent=2, sort_keys=True) + "\n")
    log.info("scorecard: %d items, %s", len(df), counts)
