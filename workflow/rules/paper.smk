# The reproduction manuscript: generated floats, macros, scorecard, and the PDF.
# Included last: result_outputs() (common.smk) reads every other rule file's rules.
import os
import shutil

from opnav.report import differences, manuscript
from opnav.core import provenance

PAPER = res("paper")
PAPER_DIR = Path(workflow.basedir) / "paper"
CAPTIONS = Path(workflow.basedir) / "workflow" / "report"

_targets = result_outputs()


SUMMARIES = {
    k: p
    for k, p in {
        "A": res("approach", "A-summary.json"),
        "B": res("landing", "B-summary.json"),
        "AX2": res("approach", "A-X2-summary.json"),
        "BX1": res("landing", "B-X1-summary.json"),
        "AP1": res("approach", "A-P1-summary.json"),
    }.items()
    if p in _targets
}
SCORE_INPUTS = {
    k: p
    for k, p in {
        "a_table1": res("approach", "A-T1_table1.csv"),
        "b_summary_table": res("landing", f"B-T3_summary_{B_HEADLINE}.csv"),
    }.items()
    if p in _targets
}


#: the replication sample's summaries (workflow/rules/replication.smk), where it is flown
REPLICATION_INPUTS = dict(REPLICATION_SUMMARIES)


from opnav.report.plan import load_plan as _load_plan

_PLAN = _load_plan(str(src("data/analysis_plan.yaml")[0]))


rule landing_optima:
    """B-C8's evidence: local minima of the depth error over the visible angles on each side of
    the velocity, per recorded planning call of one scenario's depth Monte Carlo (opnav.landing.optima;
    the grid is the analysis plan's settings.optimum_angle_grid)."""
    input:
        mc=lambda wc: b_mc(wc.bscn, ["depth"])[0],
        plan=src("data/analysis_plan.yaml")[0],
        code=B_SRC + src("landing/optima.py", "report/landing/optima_text.py", "report/landing/equivalence_text.py"),
    output:
        f"{LANDING}/optima/{{bscn}}.json",
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: B_SIMS[wc.bscn],
        n_grid=lambda wc: int(_PLAN.setting("optimum_angle_grid")),
        max_calls=0,
    log:
        f"{LANDING}/logs/optima_{{bscn}}.log",
    script:
        "../scripts/landing_optima.py"


B_OPTIMA = [f"{LANDING}/optima/{s}.json" for s in B_SCENARIOS] if "B" in SUMMARIES else []


#: the claims whose plan entry sweeps a choice for what it would take (one figure each)
SWEEP_CLAIMS = [cid for cid, t in _PLAN.tests().items() if any(w.kind == "sweep" for w in t.would_take)]


rule paper_claims:
    """The evidence table (every number a verdict may read, evidence.csv) and the claims table
    judged on it by the generic scorer against the analysis plan (opnav.report.claims, scorer,
    plan), with the replication sample where it was flown; the plan's amendments and their
    verdicts before and after (amendments.csv), the would_take figures, the derived inputs
    (inputs.csv) and the generated abstract, conclusion and limitations (claims.json)."""
    input:
        **{f"summary_{k}": p for k, p in SUMMARIES.items() if k in ("A", "B")},
        **{k: p for k, p in SCORE_INPUTS.items() if k == "a_table1"},
        **REPLICATION_INPUTS,
        optima=B_OPTIMA,
        published=src("data/published.yaml"),
        plan=src("data/analysis_plan.yaml")[0],  # one path: the script reads it as a file
        code=src("report/claims.py", "report/approach_claims.py", "report/landing_claims.py", "landing/bsummary.py", "report/evidence.py",
                 "report/plan.py", "report/scorer.py", "report/would_take_plot.py", "report/manuscript.py", "core/wording.py",
                 "core/published.py"),
    output:
        csv=report(f"{PAPER}/claims.csv", caption=_caption("claims"), category="Claims", subcategory="claims table"),
        evidence=f"{PAPER}/evidence.csv",
        amendments=f"{PAPER}/amendments.csv",
        amendments_tex=f"{PAPER}/amendments.tex",
        would_take=[f"{PAPER}/would_take/{cid}.png" for cid in SWEEP_CLAIMS],
        would_take_pdf=[f"{PAPER}/would_take/{cid}.pdf" for cid in SWEEP_CLAIMS],
        would_take_tex=f"{PAPER}/would_take.tex",
        md=f"{PAPER}/claims.md",
        tex=f"{PAPER}/claims_glance.tex",
        detail=f"{PAPER}/claims_detail.tex",
        json=f"{PAPER}/claims.json",
        plan=f"{PAPER}/analysis_plan.csv",
        inputs=f"{PAPER}/inputs.csv",
    params:
        profile=config["profile"],
        replication=canonical(config["replication"]),
        sweep_claims=SWEEP_CLAIMS,
        # the smallest data-to-converge count each EM mode can report (its first window, samples)
        windows={"sliding": config["approach"]["segments"]["N"], "growing": config["approach"]["growing"]["N"]},
        dt_s=config["approach"]["dt_s"],
        landing=canonical({k: config["landing"][k] for k in ("duration_s", "gravity_mps2", "initial_state", "yaw_deg",
                                                               "terminal_accel_mps2")}),
    log:
        f"{PAPER}/logs/paper_claims.log",
    localrule: True
    script:
        "../scripts/paper_claims.py"


#: outputs of these variants stay in results/ and the HTML report, not the PDF
PDF_DROP = [v for v in A_VARIANTS if v not in ("literal", "roll")] + [s for s in B_SCENARIOS if s != B_HEADLINE]
PDF_FLOATS = {part: [p for p in _floats(part) if manuscript.in_pdf(p, PDF_DROP)] for part in ("approach", "landing")}


def _producing_job(path):
    """The rule, wildcards and plain params of the job that writes `path`: what Snakemake's
    report gives that output's caption template."""
    import json
    from snakemake.io import apply_wildcards

    for r in workflow.rules:
        if r.is_producer(path):
            wc = {k: str(v) for k, v in r.get_wildcards(path).items()}
            params = {}
            for k, v in r.params.items():
                if isinstance(v, str):
                    v = apply_wildcards(v, wc)
                try:
                    json.dumps(v)
                except TypeError:  # a function of the job: known only when it runs
                    continue
                params[k] = v
            return {"rule": r.name, "wildcards": wc, "params": params}
    return {}


def _float_captions():
    """Each float's caption from workflow/report/, rendered as Snakemake's HTML report renders
    it (the run's config, the producing job's wildcards and params), by path: the PDF prints
    the report's words, and a caption whose rendered text changes reruns the floats. A
    parameter study's caption is written by its rule (opnav.studies.captions), not here."""
    out = {}
    for p in PDF_FLOATS["approach"] + PDF_FLOATS["landing"]:
        cap = manuscript.caption_path(p, CAPTIONS)
        if cap is not None:
            ctx = manuscript.CaptionContext(config, **_producing_job(p))
            out[p] = manuscript.render_caption(cap.read_text(), ctx, source=str(cap.relative_to(workflow.basedir)))
    return out


rule paper_floats:
    """Figure and table floats for the manuscript (headline variants only, opnav.report.manuscript.in_pdf),
    captions from workflow/report/; paper A's Table 1 as one grouped table."""
    input:
        approach=PDF_FLOATS["approach"],
        landing=PDF_FLOATS["landing"],
        a_table1=[t for t in [res("approach", "A-T1_table1.csv")] if t in _targets],
        tables_csv=[c for c in (t[:-4] + ".csv" for t in PDF_FLOATS["approach"] + PDF_FLOATS["landing"]) if c in _targets],
        captions=sorted(str(p) for p in CAPTIONS.glob("*.rst")),
        study_captions=[t for ts in STUDY_TARGETS.values() for t in ts if t.endswith(".rst")],
        code=src("report/manuscript.py", "report/approach_views.py", "report/landing/summary.py", "report/landing/timing_text.py", "core/tables.py"),
    output:
        approach=f"{PAPER}/floats_approach.tex",
        landing=f"{PAPER}/floats_landing.tex",
        compact=directory(f"{PAPER}/compact"),
        table1=f"{PAPER}/A-T1_grouped.tex",
    params:
        paper_dir=str(PAPER_DIR),
        captions_dir=lambda wildcards, input: str(Path(input.captions[0]).parent),
        # each float's caption rendered with its job's context (the report's words)
        captions=_float_captions(),
    log:
        f"{PAPER}/logs/paper_floats.log",
    localrule: True
    script:
        "../scripts/paper_floats.py"


rule paper_scorecard:
    """Every published number beside ours, with a verdict (opnav.report.scorecard)."""
    input:
        **SCORE_INPUTS,
        **{f"summary_{k}": p for k, p in SUMMARIES.items()},
        published=src("data/published.yaml"),
        plan=src("data/analysis_plan.yaml")[0],  # B-C4's band for the timing rows
        code=src("report/scorecard.py", "core/verdicts.py", "report/approach_scorecard.py", "approach/summaries.py", "report/landing/summary.py", "report/landing/timing_text.py", "landing/bsummary.py", "core/published.py"),
    output:
        table=report_table(f"{PAPER}/scorecard", "scorecard", "Scorecard"),
        longtable=f"{PAPER}/scorecard_longtable.tex",
        counts=f"{PAPER}/scorecard_counts.tex",
        headline=f"{PAPER}/scorecard_headline.tex",
        json=f"{PAPER}/scorecard.json",
    log:
        f"{PAPER}/logs/paper_scorecard.log",
    localrule: True
    script:
        "../scripts/paper_scorecard.py"


rule paper_macros:
    """One \\newcommand per number quoted in the manuscript's text."""
    input:
        **{f"summary_{k}": p for k, p in SUMMARIES.items()},
        scorecard=rules.paper_scorecard.output.json,
        claims=rules.paper_claims.output.json,
        published=src("data/published.yaml"),
        code=src("report/manuscript.py", "core/published.py", "report/text_tables.py", "core/wording.py"),
    output:
        f"{PAPER}/macros.tex",
        tables=f"{PAPER}/tables.tex",
    params:
        profile=config["profile"],
        # the model configuration the text may quote (\Cfg... macros); study values are
        # reported by the studies' own outputs, so editing a study reruns no macro
        config=canonical({k: config[k] for k in ("approach", "landing")}),
    log:
        f"{PAPER}/logs/paper_macros.log",
    localrule: True
    script:
        "../scripts/paper_macros.py"


rule provenance:
    """Python, package versions and git commit of this run (opnav.core.provenance);
    collected when the workflow is parsed, so a new commit or upgrade reruns it."""
    input:
        code=src("core/provenance.py"),
    output:
        csv=report(res("provenance.csv"), caption=_caption("provenance"), category="Provenance",
                   subcategory="environment"),
        md=res("provenance.md"),
        json=res("provenance.json"),
        tex=f"{PAPER}/provenance.tex",
    params:
        info=provenance.collect(workflow.basedir),
    log:
        f"{PAPER}/logs/provenance.log",
    localrule: True
    script:
        "../scripts/provenance.py"


rule paper_page_one:
    """Page 1 (short abstract, verdict figure), the report's claims at a glance and the table
    of what we did differently, from the claims table (opnav.report.claims_prose, manuscript, verdict_plot,
    differences)."""
    input:
        claims=rules.paper_claims.output.csv,
        plan=rules.paper_claims.output.plan,
        inputs=rules.paper_claims.output.inputs,
        published=src("data/published.yaml"),
        choices=src("data/differences.yaml"),
        code=src("report/manuscript.py", "report/claims_prose.py", "report/verdict_plot.py", "report/differences.py",
                 "core/wording.py"),
    output:
        abstract=f"{PAPER}/abstract.tex",
        fig_pdf=f"{PAPER}/verdicts.pdf",
        fig_png=report(f"{PAPER}/verdicts.png", caption=_caption("verdicts"), category="Claims",
                       subcategory="verdicts"),
        glance=f"{PAPER}/claims_glance.csv",
        # the claims table in the PDF's words (claims.csv keeps the codes, for programs)
        readers=report(f"{PAPER}/claims_table.csv", caption=_caption("claims"), category="Claims",
                       subcategory="claims table"),
        differences=f"{PAPER}/differences.tex",
        runinfo=f"{PAPER}/runinfo.tex",
        conclusion=f"{PAPER}/conclusion.tex",
        plan_tex=f"{PAPER}/analysis_plan.tex",
        inputs_tex=f"{PAPER}/inputs.tex",
    params:
        config=canonical(differences.subset(config)),  # only the keys the table of choices reads
        results=RESULTS,
    log:
        f"{PAPER}/logs/paper_page_one.log",
    localrule: True
    script:
        "../scripts/paper_page_one.py"


PAPER_INPUTS = [rules.paper_floats.output, rules.paper_macros.output, rules.paper_scorecard.output,
                rules.paper_claims.output, rules.provenance.output, rules.paper_page_one.output]

LATEX_HINT = (
    "opnav: LaTeX not found, skipping results/paper/main.pdf; to build it install: "
    "apt-get install latexmk texlive-latex-base texlive-latex-recommended "
    "texlive-fonts-recommended texlive-science lmodern"
)
HAVE_LATEX = shutil.which("latexmk") is not None and shutil.which("pdflatex") is not None


rule paper_pdf:
    """The manuscript, built reproducibly (SOURCE_DATE_EPOCH) with latexmk."""
    input:
        main=str(PAPER_DIR / "main.tex"),
        tex=sorted(str(p) for p in PAPER_DIR.rglob("*.tex")),
        generated=PAPER_INPUTS,
        results=[t for t in _targets if t.endswith((".pdf", ".tex"))],
        code=src("report/print_size.py"),
    output:
        report(f"{PAPER}/main.pdf", caption=_caption("manuscript"), category="Claims", subcategory="manuscript"),
    params:
        paper_dir=lambda wildcards, input: str(Path(input.main).parent),
        build=f"{PAPER}/build",
    log:
        f"{PAPER}/logs/paper_pdf.log",
    localrule: True
    script:
        "../scripts/paper_pdf.py"


if config["paper"]["build_pdf"] and not HAVE_LATEX:
    print(LATEX_HINT, file=sys.stderr)
