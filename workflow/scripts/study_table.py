"""A parameter study's tables: every run (tidy), the summary (tidy: one row per value,
method and metric) and its page view, the log-log slopes if asked, and the generated
caption (opnav.studies)."""

import sys

import pandas as pd

from opnav import studies
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import atomic_write_text, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_fov_table", argv=sys.argv[1:])

with script_context(snakemake) as log:
    study = snakemake.params.study
    parts = [(label, pd.read_csv(path)) for path, label in zip(snakemake.input.runs, snakemake.params.labels)]
    runs = studies.gather_runs(parts, study, snakemake.params.converged_pos_err_m)
    tidy = studies.tidy_table(runs, study)
    cap = snakemake.params.caption
    write_table(tidy, [snakemake.output.table[0]], caption=cap)
    write_table(studies.wide_table(tidy, study), snakemake.output.table[1:], caption=cap)
    write_table(runs, [snakemake.output.runs])
    if study["slopes"]:
        write_table(studies.loglog_slopes(tidy, study), snakemake.output.slopes,
                    caption=f"{study['id']} {study['name']}: log-log slopes against {study['keys'][0]}.")
    atomic_write_text(snakemake.output.caption, cap + "\n")
    log.info("study %s: %d runs, %d summary rows", study["name"], len(runs), len(tidy))
