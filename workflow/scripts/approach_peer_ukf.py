"""A-P1: Basilisk's pixelLineBiasUKF on one variant's headline-case measurements (one Snakemake job)."""

import sys
from pathlib import Path

from opnav.approach.peers import run_variant
from opnav.approach.setup import Setup
from opnav.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_peer_ukf", argv=sys.argv[1:], variant="roll")

with script_context(snakemake) as log:
    res = run_variant(Setup.from_config(snakemake.params.approach), snakemake.wildcards.variant, log=log)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], res)
