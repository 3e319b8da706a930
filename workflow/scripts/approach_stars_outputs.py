"""A-X6: the stars study (beyond the paper) as a table and a figure against attitude knowledge
and stars per image."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.core import figures
from opnav.approach import summaries
from opnav.report.approach import star_plots
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_stars_outputs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    frame = summaries.stars_frame(load_pickle(snakemake.input.stars))
    write_table(frame, snakemake.output.table,
                caption="A-X6: star calibration on Hipparcos stars against the stars in every image (each count "
                        "with the magnitude limit and field that make it real) and the attitude knowledge per star "
                        "image. Columns: the bound of tx, ty (all data; stars alone), the attitude floor and the "
                        "EM-EKF (growing windows, SQUAREM) over the seeds, arcsec.")
    with figures.style():
        fig = star_plots.stars_figure(frame, snakemake.params.target)
        figures.save(fig, snakemake.output.fig)
    log.info("A-X6: %d rows", len(frame))
