"""Monte Carlo of one Table-1 case group under one scenario variant and EM scheme."""

import sys
from pathlib import Path

from opnav.approach.pipeline import run_group
from opnav.approach.setup import Setup
from opnav.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_mc", argv=sys.argv[1:], variant="literal", group="size", method="plain")

with script_context(snakemake) as log:
    w = snakemake.wildcards
    mode, _, method = w.method.rpartition("-")  # "growing-squarem" -> growing windows, SQUAREM
    res = run_group(Setup.from_config(snakemake.params.approach), w.variant, w.group, method, mode or "sliding", log=log)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], res)
