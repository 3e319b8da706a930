"""B-T1, B-T2: the descent's initial state and Monte-Carlo error bounds, from the config."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.report.landing.tables import error_bounds_table, initial_state_table
from opnav.landing.setup import Setup
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_tables", argv=sys.argv[1:])

with script_context(snakemake) as log:
    cfg = Setup.from_config(snakemake.params.landing)    # the edge: paper B's config parsed once
    write_table(initial_state_table(cfg), snakemake.output.t1,
                caption="B-T1: lander initial state in the landing frame {L} (paper B Table 1).")
    write_table(error_bounds_table(cfg), snakemake.output.t2,
                caption="B-T2: Monte-Carlo initial-error bounds, uniform per axis (paper B Table 2).")
    log.info("wrote %s and %s", snakemake.output.t1, snakemake.output.t2)
