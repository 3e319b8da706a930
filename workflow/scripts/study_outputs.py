"""A parameter study's outputs: its tables (every run, tidy; the summary, tidy: one row
per value, method and metric, and its page view; the log-log slopes if asked), the
generated caption (opnav.studies), and its figure: each metric against the swept value,
one line per method, drawn from the summary table as written."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

import pandas as pd

from opnav.core import figures
from opnav.core.snakeio import load_csv, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table
from opnav.report.study_plots import fig_study
from opnav.studies.captions import slopes_caption
from opnav.studies.tables import gather_runs, loglog_slopes, tidy_table, wide_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_fov_outputs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    study = snakemake.params.study
    parts = [(label, load_csv(path)) for path, label in zip(snakemake.input.runs, snakemake.params.labels)]
    runs = gather_runs(parts, study, snakemake.params.converged_pos_err_m)
    tidy = tidy_table(runs, study)
    cap = snakemake.params.caption
    write_table(tidy, [snakemake.output.table[0]], caption=cap)
    write_table(wide_table(tidy, study), snakemake.output.table[1:], caption=cap)
    write_table(runs, [snakemake.output.runs])
    if study["slopes"]:
        write_table(loglog_slopes(tidy, study), snakemake.output.slopes,
                    caption=slopes_caption(study))
    atomic_write_text(snakemake.output.caption, cap + "\n")
    log.info("study %s: %d runs, %d summary rows", study["name"], len(runs), len(tidy))
    # the figure reads the summary back from its CSV, as a user of the table would
    shown = pd.read_csv(snakemake.output.table[0], keep_default_na=False, na_values=[""])
    figures.save(fig_study(shown, study), snakemake.output.fig)
    log.info("study %s figure", study["name"])
