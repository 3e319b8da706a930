"""results/paper/evidence.csv and claims.csv: every number a verdict may read (the extractors of
opnav.report.approach_claims and landing_claims, main and replication samples, the published
values), keyed to the claims of the analysis plan, and each claim judged on it by the generic
scorer (opnav.report.scorer through opnav.report.claims.build); amendments.csv (every amendment
of the plan, its verdicts before and after on this evidence), the would_take figures, the plan
as a table (analysis_plan.csv), the derived inputs (inputs.csv) and claims.json (counts and the
generated abstract, conclusion, limitations and sample sentence)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import json
import sys
from pathlib import Path

from opnav.core import published
from opnav.core.snakeio import load_json, load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table
from opnav.report import claims, evidence, would_take_plot
from opnav.report.approach_claims import HEADLINE_IDS as A_HEAD
from opnav.report.approach_claims import evidence_rows as rows_a
from opnav.report.approach_claims import input_rows as inputs_a
from opnav.report.approach_claims import published_rows as pub_a
from opnav.landing.bsummary import BSummary
from opnav.report.landing_claims import HEADLINE_IDS as B_HEAD
from opnav.report.landing_claims import evidence_rows as rows_b
from opnav.report.landing_claims import input_rows as inputs_b
from opnav.report.landing_claims import published_rows as pub_b
from opnav.report.manuscript import claims_detail_latex, claims_glance_latex, prose_tex

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_claims", argv=sys.argv[1:])


def sample_rows(inp, prefix, sample, plan, windows, optima):
    """The evidence rows of one sample (main: prefix '', replication: 'rep_')."""
    keys = inp.keys()
    out, summ = [], {}
    if f"{prefix}summary_A" in keys and f"{prefix}a_table1" in keys:
        summ["A"] = load_json(inp[f"{prefix}summary_A"])
        out += rows_a(load_table(inp[f"{prefix}a_table1"]), summ["A"], sample, inp[f"{prefix}a_table1"],
                      inp[f"{prefix}summary_A"], windows)
    if f"{prefix}summary_B" in keys:
        summ["B"] = BSummary.from_json(load_json(inp[f"{prefix}summary_B"]))   # read by meaning (typed)
        out += rows_b(summ["B"], sample, inp[f"{prefix}summary_B"], plan, optima if not prefix else None)
    return summ, out


with script_context(snakemake) as log:
    inp, par, out = snakemake.input, snakemake.params, snakemake.output
    pub = published.load()
    plan = claims.load_plan(inp["plan"])
    windows = {k: float(v) for k, v in dict(par.windows).items()}
    optima = {}
    for p in (inp.get("optima") or []):
        o = load_json(p)
        optima[o["scenario"]] = o
    summ, rows = sample_rows(inp, "", "main", plan, windows, optima)
    rep_ids = claims.replication_plan(plan, dict(par.replication))
    if any(k.startswith("rep_") for k in inp.keys()):
        rows += sample_rows(inp, "rep_", "replication", plan, windows, None)[1]
    rows += pub_a(pub["paper_a"]) + pub_b(pub["paper_b"])
    ev = claims.evidence_table(plan, rows)
    crs, js, sweeps = claims.build(plan, ev, rep_ids, str(par.profile))
    evidence.write_csv(ev + claims.derived_rows(js), out.evidence)
    df = claims.frame(crs)
    unused = plan.unused()
    if unused:
        log.info("analysis plan entries no verdict read in this build: %s", ", ".join(unused))
    df.to_csv(out.csv, index=False)
    plan.table().to_csv(out.plan, index=False)
    am = claims.amendments(plan, ev, rep_ids)
    am.to_csv(out.amendments, index=False)
    atomic_write_text(out.amendments_tex, claims.amendments_latex(am, plan, prose_tex))
    names = {k: plan.name(k) for k in plan.raw.get("names", {}) if isinstance(plan.raw["names"][k], str)}
    for cid, stem in zip(par.sweep_claims, out.would_take):
        would_take_plot.plot(cid, sweeps, Path(stem).with_suffix(""), names)
    atomic_write_text(out.would_take_tex, would_take_plot.latex(
        par.sweep_claims, sweeps, {r["claim_id"]: r for r in df.to_dict("records")}, names=names))
    ins = (inputs_a(pub["paper_a"], plan, float(par.dt_s)) if "A" in summ else []) + (
        inputs_b(summ["B"], pub["paper_b"], plan, dict(par.landing)) if "B" in summ else [])
    claims.inputs_frame(ins).to_csv(out.inputs, index=False)
    write_table(claims.glance(df), [out.md], caption=claims.GLANCE_CAPTION)
    atomic_write_text(out.tex, claims_glance_latex(df))
    atomic_write_text(out.detail, claims_detail_latex(df))
    atomic_write_text(out.json, json.dumps({
        "n_claims": len(df), "by_paper": claims.counts(df), "sample": str(df["sample"].iloc[0]) if len(df) else "",
        "plan": plan.stamp, "n_evidence_rows": len(ev), "n_amendments": len(plan.amendments()),
        "text": {"abstract": claims.abstract(df, A_HEAD + B_HEAD), "conclusion": claims.conclusion(df),
                 "limitations": claims.limitations(df), "sample": claims.sample_sentence(df)}},
        indent=2, sort_keys=True) + "\n")
    log.info("claims: %d rows from %d evidence rows (plan %s), %s", len(df), len(ev), plan.stamp,
             df["verdict"].value_counts().to_dict())
