"""A-F4, A-F5, A-F6 and A-X4 for the headline case (T1-01) of one scenario variant."""


import sys

from opnav import figures, published
from opnav.approach import plots
from opnav.snakeio import load_pickle, mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_figures", argv=sys.argv[1:], variant="literal")

with script_context(snakemake) as log:
    runs = {}
    for p in snakemake.input.mc:
        for r in load_pickle(p):
                if r["case_id"] == "T1-01":
                    runs[f"{r.get('mode', 'sliding')}-{r['method']}"] = r
    v = snakemake.wildcards.variant
    seg = snakemake.params.segments["segments"]
    pub = published.paper_a()
    figures.save(plots.fig_bias_estimate(runs, v, pub, seg["N"], seg["M"]), snakemake.output.f4)
    figures.save(plots.fig_nav_accuracy(runs, v), snakemake.output.f5)
    figures.save(plots.fig_compensation(runs, v, pub), snakemake.output.f6)
    figures.save(plots.fig_consistency(runs, v), snakemake.output.x4)
    log.info("figures for %s", v)
