"""One Monte-Carlo job of paper B: runs `params.runs` of `wildcards.method` (scatter), or of
each of `params.methods` in turn (rules landing_mc_pack*, landing.mc.methods_per_job)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import hashlib
import sys
from pathlib import Path

from opnav.landing.montecarlo import run_chunk_reusing, save
from opnav.landing.setup import Setup
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.studies.values import config_digest

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_mc_chunk", argv=sys.argv[1:], bscn="site-tilt", bmethod="depth", bchunk="r0000-0001")

with script_context(snakemake) as log:
    if hasattr(snakemake.params, "methods"):   # a pack: its outputs in the order of its methods
        methods, pick_ratios = list(snakemake.params.methods), [bool(p) for p in snakemake.params.pick_ratio]
    else:
        methods, pick_ratios = [snakemake.wildcards.bmethod], [bool(snakemake.params.pick_ratio)]
    runs = list(snakemake.params.runs)
    # runs of an earlier, smaller chunk beside this one are taken over, not flown again,
    # when flown with the same simulation, method, diagnostics and source code (the
    # rule's inputs are the src modules): the reuse key
    setup = Setup.from_config(snakemake.params.landing)    # the edge: paper B's config parsed once
    code = sorted(hashlib.sha256(Path(p).read_bytes()).hexdigest() for p in snakemake.input)
    for method, pick_ratio, out in zip(methods, pick_ratios, snakemake.output, strict=True):
        key = config_digest({"landing": snakemake.params.landing, "method": method, "pick_ratio": pick_ratio,
                             "code": code})
        data, flown = run_chunk_reusing(out, key, setup, method, runs,
                                        pick_ratio=pick_ratio, batch_size=int(snakemake.params.batch_size))
        save(out, data, method)
        log.info("%s: runs %s..%s (%d flown, %d taken from earlier chunks), %d planning calls", method,
                 runs[0], runs[-1], len(flown), len(runs) - len(flown), len(data.plan_index))
