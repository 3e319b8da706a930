"""The stars variant (beyond the paper): bound and estimates per number of stars per image."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach.alternatives import stars_study
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_stars", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    out = stars_study(setup, snakemake.params.target, log)  # A-C1's target (the analysis plan)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], out)
