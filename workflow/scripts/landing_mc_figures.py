"""B-F6 (navigation-error 3-sigma envelopes) and B-F7 (planning-time box plots)."""

import sys

from opnav import figures, published
from opnav.landing import plots, timing
from opnav.landing.montecarlo import load
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_mc_figures", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    data = {m: load(p) for m, p in zip(snakemake.params.methods, snakemake.input.mc)}
    t = next(iter(data.values()))["t"]
    figures.save(plots.fig_nav_error_envelopes(t, data), snakemake.output.f6)
    pub = published.paper_b()["depth_time_reduction_vs_svd_pct"]
    tm = timing.load(snakemake.input.timing)     # planning times by replay, not the descents'
    figures.save(plots.fig_planning_time(tm, list(data), pub), snakemake.output.f7)
    log.info("B-F6, B-F7 from %s", list(data))
