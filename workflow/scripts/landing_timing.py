"""Planning time by replay of one camera scenario (opnav.landing.timing.replay)."""

import sys

from opnav.landing import timing, timing_summary
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import load
from opnav.core.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_timing", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    methods = list(snakemake.params.methods)
    recorded = {m: load(p) for m, p in zip(methods, snakemake.input.mc)}
    tm = timing.replay(build_scenario(snakemake.params.landing), recorded, methods,
                       int(snakemake.params.max_calls),
                       max_calls_paper=int(snakemake.params.max_calls_paper))
    timing.save(snakemake.output[0], tm)
    log.info("%s", timing_summary.method_text(tm))
    log.info("%s", timing_summary.summary_frame(tm).to_string())
