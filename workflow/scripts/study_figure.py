"""A parameter study's figure: each metric against the swept value, one line per method."""

import sys

import pandas as pd

from opnav import figures
from opnav.snakeio import mock_snakemake, script_context
from opnav.study_plots import fig_study

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_fov_figure", argv=sys.argv[1:])

with script_context(snakemake) as log:
    tidy = pd.read_csv(snakemake.input.table, keep_default_na=False, na_values=[""])
    figures.save(fig_study(tidy, snakemake.params.study), snakemake.output.fig)
    log.info("study %s figure", snakemake.params.study["name"])
