"""Page 1 of the manuscript and the report's landing page, from the claims table: the short
abstract (abstract.tex), the verdict figure (one row per claim), the claims at a glance as
CSV for the HTML report's first page, and the table of what we did differently
(differences.tex: every open or changed choice, ours from the run's configuration)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

import pandas as pd

from opnav.core import figures, published
from opnav.core.snakeio import benchmark_table, load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text
from opnav.report import claims_prose, differences, manuscript, verdict_plot

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_page_one", argv=sys.argv[1:])

with script_context(snakemake) as log:
    out = snakemake.output
    df = load_table(snakemake.input.claims, keep_default_na=False)
    sample = claims_prose.sample_sentence_of(df)
    atomic_write_text(out.abstract, claims_prose.page_one_abstract_tex(df, sample))
    figures.save(verdict_plot.fig_verdicts(df), [out.fig_pdf, out.fig_png])
    atomic_write_text(out.conclusion, "\\newcommand{\\PageConclusion}{" + manuscript.prose_tex(
        claims_prose.conclusion_text(df)) + "}\n\\newcommand{\\PageLimitations}{" + manuscript.prose_tex(
        claims_prose.limitations_text(df)) + "}\n")
    # the HTML report's claims in the PDF's words: the landing page's glance and the full table
    glance = df[[c for c in ("claim_id", "claim", "published", "ours_as_written", "verdict") if c in df.columns]]
    manuscript.claims_for_readers(glance.assign(claim=glance["claim"].map(verdict_plot.short_claim))).to_csv(
        out.glance, index=False)
    manuscript.claims_for_readers(df).to_csv(out.readers, index=False)
    # the appendix tables of the claims job: the analysis plan and the inputs we derive
    atomic_write_text(out.plan_tex, manuscript.plan_latex(pd.read_csv(snakemake.input.plan, keep_default_na=False)))
    atomic_write_text(out.inputs_tex, manuscript.inputs_latex(pd.read_csv(snakemake.input.inputs,
                                                                          keep_default_na=False)))
    rows = differences.rows(dict(snakemake.params.config), published.load())
    atomic_write_text(out.differences, differences.latex(rows))
    # the build's cost: Snakemake's records of its jobs and the heavy jobs' benchmark files
    # (read, not inputs: this is a description of the build, not a result)
    bench = sorted(Path(snakemake.params.results).glob("*/benchmarks/*.tsv"))
    jobs = manuscript.snakemake_jobs(Path(".snakemake") / "metadata", snakemake.params.results)
    atomic_write_text(out.runinfo, manuscript.run_info_tex(
        (benchmark_table(b) for b in bench), manuscript.machine_text(), jobs))   # a job in the job server: its log's CPU
    log.info("page 1: abstract %d words, %d claims, %d choices", claims_prose.word_count(
        claims_prose.page_one_abstract_tex(df, sample)), len(df), len(rows))
