"""A-X1 figure: the CRLB per variant beside the EM estimates; EM iterations plain vs SQUAREM."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys


from opnav.core import figures
from opnav.report.approach import plots
from opnav.approach.setup import Setup
from opnav.core.snakeio import load_pickle, load_table, mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_x1_figure", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    curves = load_pickle(snakemake.input.crlb)["Q"]
    conv = {}
    for p in snakemake.input.conv:
        c = load_pickle(p)
        conv[c.variant] = c
    x1 = load_table(snakemake.input.x1)
    fig = plots.fig_crlb(curves, conv, x1, snakemake.params.target, setup.segments.N0)
    figures.save(fig, snakemake.output.fig)
