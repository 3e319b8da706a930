"""A-X7: the navigation error after compensation against arc length, table and figure."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.approach import summaries
from opnav.report.approach import plots
from opnav.core import figures
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import write_table
from opnav.report.plan import load_plan

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_nav_arc_outputs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    nf = load_pickle(snakemake.input.nav_arc)["nav_floor_by_arc"]
    frame = summaries.nav_floor_frame(nf)
    write_table(frame, snakemake.output.table,
                caption=(f"A-X7: navigation error against arc length, km, {nf.variant} in the headline case, "
                         f"mean (median, sd) over {nf.n_seeds} seeds. The *_rule columns follow the analysis plan's "
                         f"rule (RMS over the last {nf.last_fraction:g} of the arc), the *_last ones the arc's last "
                         "sample. true_theta is the filter given the true theta (a filter's floor), before the "
                         "filter with theta = 0."))
    limit = load_plan(snakemake.input.plan).margin("A-C7", "limit_km")  # the paper's limit (read only)
    figures.save(plots.fig_nav_floor(nf, limit), snakemake.output.fig)
    log.info("A-X7: %d arcs", len(frame))
