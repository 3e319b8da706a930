"""A parameter study's tables: every run (tidy), the summary (tidy: one row per value,
method and metric) and its page view, and the generated caption (opnav.studies)."""

import sys

import pandas as pd

from opnav import studies
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import atomic_write_text, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_fov_table", argv=sys.argv[1:])

with script_context(snakemake) as log:
    study = snakemake.params.study
    parts = []
    for path, label in zip(snakemake.input.runs, snakemake.params.labels):
        df = pd.read_csv(path)
        df.insert(0, "instance", label)
        parts.append(df)
    runs = pd.concat(parts, ignore_index=True)
    runs = runs[runs["run"] < study["runs"]]
    if study["paper"] == "landing":
        from opnav.landing.study import add_derived

        runs = add_derived(runs, snakemake.params.converged_pos_err_m)
    for key in study["keys"]:  # the swept values beside each row
        runs.insert(1, key, [str(study["instances"][i][key]) for i in runs["instance"]])
    tidy = studies.summarize(runs, studies.table_metrics(study), study["methods"])
    for key in reversed(study["keys"]):
        tidy.insert(1, key, [study["instances"][i][key] for i in tidy["instance"]])
    tidy.insert(0, "study", study["name"])
    cap = studies.caption(study)
    write_table(tidy, [snakemake.output.table[0]], caption=cap)
    write_table(studies.wide_table(tidy, study), snakemake.output.table[1:], caption=cap)
    write_table(runs, [snakemake.output.runs])
    atomic_write_text(snakemake.output.caption, cap + "\n")
    log.info("study %s: %d runs, %d summary rows", study["name"], len(runs), len(tidy))
