"""A-P1: Basilisk's pixelLineBiasUKF on each A-P1 variant's headline-case measurements (one Snakemake job)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach.peers import run_variant
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_peer_ukf", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    for variant, out in zip(snakemake.params.variants, snakemake.output):
        res = run_variant(setup, variant, log=log)
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        save_pickle(out, res)
