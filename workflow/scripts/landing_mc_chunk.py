"""One Monte-Carlo job of paper B: runs `params.runs` of `wildcards.method` (scatter)."""

import sys

from opnav.landing.montecarlo import run_chunk, save
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_mc_chunk", argv=sys.argv[1:], bscn="site-tilt", bmethod="depth", bchunk="r0000-0001")

with script_context(snakemake) as log:
    method = snakemake.wildcards.bmethod
    runs = list(snakemake.params.runs)
    data = run_chunk(snakemake.params.landing, method, runs, pick_ratio=bool(snakemake.params.pick_ratio))
    save(snakemake.output[0], data, method)
    log.info("%s: runs %s..%s, %d planning calls", method, runs[0], runs[-1], len(data["plan_index"]))
