"""A-F4, A-F5, A-F6 for the headline case (T1-01) of one scenario variant."""

import pickle

from opnav import figures, published
from opnav.approach import plots
from opnav.snakeio import script_context

with script_context(snakemake) as log:
    runs = {}
    for p in snakemake.input.mc:
        with open(p, "rb") as fh:
            for r in pickle.load(fh):
                if r["case_id"] == "T1-01":
                    runs[r["method"]] = r
    v = snakemake.wildcards.variant
    seg = snakemake.params.segments["segments"]
    pub = published.paper_a()
    figures.save(plots.fig_bias_estimate(runs, v, pub, seg["N"], seg["M"]), snakemake.output.f4)
    figures.save(plots.fig_nav_accuracy(runs, v), snakemake.output.f5)
    figures.save(plots.fig_compensation(runs, v, pub), snakemake.output.f6)
    log.info("figures for %s", v)
