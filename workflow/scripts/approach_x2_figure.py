"""A-X2 figure: EM-EKF vs augmented EKF vs batch ML, per scenario variant (from the long-form CSV)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys


from opnav.core import figures
from opnav.report.approach import plots
from opnav.report.approach.text import METHOD_LABELS
from opnav.core.snakeio import load_table, mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_x2_figure", argv=sys.argv[1:])


with script_context(snakemake) as log:
    long = load_table(snakemake.input.long)
    figures.save(plots.fig_alternatives(long, METHOD_LABELS), snakemake.output.fig)
    log.info("A-X2 figure: %d methods x %d variants", long["method"].nunique(), long["variant"].nunique())
