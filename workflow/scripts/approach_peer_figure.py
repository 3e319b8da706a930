"""A-P1 figure: the peer UKF's (tx, ty) over the arc with its own 3 sigma, against the others' end values."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys


from opnav.core import figures
from opnav.report.approach import peer_plots
from opnav.core.snakeio import load_pickle, load_table, mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_peer_figure", argv=sys.argv[1:])

with script_context(snakemake) as log:
    peer = [load_pickle(p) for p in snakemake.input.peer]
    table = load_table(snakemake.input.table)
    with figures.style():
        fig = peer_plots.peer_figure(peer, table)
        figures.save(fig, snakemake.output.fig)
    log.info("A-P1 figure: %d variants", len(peer))
