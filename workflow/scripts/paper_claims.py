"""results/paper/claims.csv: one row per published claim of each paper, with its verdict
(opnav.report.claims); claims.json holds the counts and the generated abstract, conclusion and
limitations for the manuscript's macros."""

import json
import sys

import pandas as pd

from opnav.report import claims
from opnav.core import published
from opnav.report.approach_claims import HEADLINE_IDS as A_HEAD, claim_rows as rows_a
from opnav.report.landing_claims import HEADLINE_IDS as B_HEAD, claim_rows as rows_b
from opnav.report.manuscript import claims_detail_latex, claims_glance_latex
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_claims", argv=sys.argv[1:])

with script_context(snakemake) as log:
    inp = snakemake.input
    summaries = {k: json.loads(open(inp[f"summary_{k}"]).read()) for k in ("A", "B") if f"summary_{k}" in inp.keys()}
    t1 = pd.read_csv(inp["a_table1"]) if "a_table1" in inp.keys() else None
    pub = published.load()
    rows = rows_a(summaries["A"], t1, pub["paper_a"]) if "A" in summaries and t1 is not None else []
    rows += rows_b(summaries["B"], pub["paper_b"]) if "B" in summaries else []
    df = claims.frame(rows)
    df.to_csv(snakemake.output.csv, index=False)
    write_table(claims.glance(df), [snakemake.output.md],
                caption="Claims at a glance: each published claim, ours as written, the verdict.")
    atomic_write_text(snakemake.output.tex, claims_glance_latex(df))
    atomic_write_text(snakemake.output.detail, claims_detail_latex(df))
    atomic_write_text(snakemake.output.json, json.dumps({
        "n_claims": int(len(df)), "by_paper": claims.counts(df),
        "text": {"abstract": claims.abstract(df, A_HEAD + B_HEAD), "conclusion": claims.conclusion(df),
                 "limitations": claims.limitations(df)}}, indent=2, sort_keys=True) + "\n")
    log.info("claims: %d rows, %s", len(df), df["verdict"].value_counts().to_dict())
