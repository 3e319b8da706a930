"""Monte Carlo of one Table-1 case group under one scenario variant, every EM scheme of the job;
or, in a pack (rules approach_mc_pack*, jobs.approach_mc_per_job), several such units in turn."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach.pipeline import run_group
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_mc", argv=sys.argv[1:], variant="literal", group="size")

with script_context(snakemake) as log:
    p = snakemake.params
    setup = Setup.from_config(p.approach)
    # a pack (rules approach_mc_pack*): its units in turn; otherwise the job's own unit
    units = [tuple(u) for u in p.units] if hasattr(p, "units") else [(snakemake.wildcards.variant,
                                                                      snakemake.wildcards.group)]
    outs = iter(snakemake.output)
    for variant, group in units:
        shared = {}  # the schemes share the simulation, the theta = 0 filter and a mode's bounds
        for scheme, out in zip(p.schemes, outs):
            mode, _, method = scheme.rpartition("-")  # "growing-squarem" -> growing windows, SQUAREM
            res = run_group(setup, variant, group, method, mode or "sliding", log=log, shared=shared)
            Path(out).parent.mkdir(parents=True, exist_ok=True)
            save_pickle(out, res)
