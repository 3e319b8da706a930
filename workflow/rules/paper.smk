# The reproduction manuscript: generated floats, macros, scorecard, and the PDF.
# Included last: result_outputs() (common.smk) reads every other rule file's rules.
import os
import shutil

from opnav import provenance

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


rule paper_floats:
    """Figure and table floats for the manuscript, captions from workflow/report/."""
    input:
        approach=_floats("approach"),
        landing=_floats("landing"),
        tables_csv=[c for c in (t[:-4] + ".csv" for t in _floats("approach") + _floats("landing")) if c in _targets],
        captions=sorted(str(p) for p in CAPTIONS.glob("*.rst")),
        study_captions=[t for ts in STUDY_TARGETS.values() for t in ts if t.endswith(".rst")],
        code=src("manuscript.py", "approach/report.py", "landing/report.py", "tables.py"),
    output:
        approach=f"{PAPER}/floats_approach.tex",
        landing=f"{PAPER}/floats_landing.tex",
        compact=directory(f"{PAPER}/compact"),
    params:
        paper_dir=str(PAPER_DIR),
        captions_dir=lambda wildcards, input: str(Path(input.captions[0]).parent),
    log:
        f"{PAPER}/logs/paper_floats.log",
    localrule: True
    script:
        "../scripts/paper_floats.py"


rule paper_scorecard:
    """Every published number beside ours, with a verdict (opnav.scorecard)."""
    input:
        **SCORE_INPUTS,
        **{f"summary_{k}": p for k, p in SUMMARIES.items()},
        published=src("data/published.yaml"),
        code=src("scorecard.py", "verdicts.py", "approach/report.py", "landing/report.py", "published.py"),
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
        published=src("data/published.yaml"),
        code=src("manuscript.py", "published.py"),
    output:
        f"{PAPER}/macros.tex",
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
    """Python, package versions and git commit of this run (opnav.provenance);
    collected when the workflow is parsed, so a new commit or upgrade reruns it."""
    input:
        code=src("provenance.py"),
    output:
        csv=report(res("provenance.csv"), caption=_caption("provenance"), category="Provenance"),
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


PAPER_INPUTS = [rules.paper_floats.output, rules.paper_macros.output, rules.paper_scorecard.output,
                rules.provenance.output]

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
    output:
        f"{PAPER}/main.pdf",
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
