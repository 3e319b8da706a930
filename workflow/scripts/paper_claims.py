"""results/paper/claims.csv: one row per published claim of each paper, with its verdict
(opnav.report.claims), judged by the analysis plan (data/analysis_plan.yaml, written out as
analysis_plan.csv) and, where the replication sample was flown, re-judged on it
(verdict_replication; 'unstable' where the two differ); inputs.csv holds the inputs we
derive; claims.json holds the counts and the generated abstract, conclusion, limitations
and the sample sentence for the manuscript's macros."""

import json
import sys

from opnav.approach.summaries import ClaimsSummary
from opnav.core import published
from opnav.core.snakeio import load_json, load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table
from opnav.landing.claims_summary import LandingSummary
from opnav.report import claims
from opnav.report.approach_claims import HEADLINE_IDS as A_HEAD
from opnav.report.approach_claims import claim_rows as rows_a
from opnav.report.approach_claims import input_rows as inputs_a
from opnav.report.landing_claims import HEADLINE_IDS as B_HEAD
from opnav.report.landing_claims import claim_rows as rows_b
from opnav.report.landing_claims import input_rows as inputs_b
from opnav.report.manuscript import claims_detail_latex, claims_glance_latex

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_claims", argv=sys.argv[1:])


def score(inp, prefix, pub, plan, windows):
    """The claims rows of one sample (main: prefix '', replication: 'rep_')."""
    keys = inp.keys()
    summ = {k: load_json(inp[f"{prefix}summary_{k}"]) for k in ("A", "B") if f"{prefix}summary_{k}" in keys}
    t1 = load_table(inp[f"{prefix}a_table1"]) if f"{prefix}a_table1" in keys else None
    rows = rows_a(ClaimsSummary.from_json(summ["A"]), t1, pub["paper_a"], plan, windows) if "A" in summ and t1 is not None else []
    rows += rows_b(LandingSummary.from_json(summ["B"]), pub["paper_b"], plan) if "B" in summ else []
    return summ, rows


with script_context(snakemake) as log:
    inp, par = snakemake.input, snakemake.params
    pub = published.load()
    plan = claims.load_plan(inp["plan"])
    windows = {k: float(v) for k, v in dict(par.windows).items()}
    summ, rows = score(inp, "", pub, plan, windows)
    df = claims.frame(rows)
    claims.check_plan_covers(df, plan)
    rep_ids = claims.replication_plan(plan, dict(par.replication))
    if any(k.startswith("rep_") for k in inp.keys()):
        _, rep_rows = score(inp, "rep_", pub, claims.load_plan(inp["plan"]), windows)
        df = claims.with_replication(df, claims.frame(rep_rows), rep_ids)
    df = claims.mark_sample(df, str(par.profile))
    unused = plan.unused()
    if unused:
        log.info("analysis plan entries no verdict read in this build: %s", ", ".join(unused))
    df.to_csv(snakemake.output.csv, index=False)
    plan.table().to_csv(snakemake.output.plan, index=False)
    ins = (inputs_a(pub["paper_a"], plan, float(par.dt_s)) if "A" in summ else []) + (
        inputs_b(LandingSummary.from_json(summ["B"]), pub["paper_b"], plan, dict(par.landing)) if "B" in summ else [])
    claims.inputs_frame(ins).to_csv(snakemake.output.inputs, index=False)
    write_table(claims.glance(df), [snakemake.output.md],
                caption=claims.GLANCE_CAPTION)
    atomic_write_text(snakemake.output.tex, claims_glance_latex(df))
    atomic_write_text(snakemake.output.detail, claims_detail_latex(df))
    atomic_write_text(snakemake.output.json, json.dumps({
        "n_claims": len(df), "by_paper": claims.counts(df), "sample": str(df["sample"].iloc[0]) if len(df) else "",
        "text": {"abstract": claims.abstract(df, A_HEAD + B_HEAD), "conclusion": claims.conclusion(df),
                 "limitations": claims.limitations(df), "sample": claims.sample_sentence(df)}},
        indent=2, sort_keys=True) + "\n")
    log.info("claims: %d rows, %s", len(df), df["verdict"].value_counts().to_dict())
