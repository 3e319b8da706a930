"""Gather the Monte-Carlo chunks of one method of paper B (in run order)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.landing.montecarlo import gather, load, save
from opnav.core.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_mc_gather", argv=sys.argv[1:], bscn="site-tilt", bmethod="depth")

with script_context(snakemake) as log:
    data = gather([load(p) for p in snakemake.input])
    save(snakemake.output[0], data, snakemake.wildcards.bmethod)
    log.info("%s: %d runs gathered", snakemake.wildcards.bmethod, data.n_runs)
