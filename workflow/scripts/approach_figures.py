"""A-F4, A-F5, A-F6 and A-X4 for the headline case (T1-01) of every scenario variant."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here


import sys

from opnav.core import figures, published
from opnav.report.approach import plots
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_figures", argv=sys.argv[1:])

with script_context(snakemake) as log:
    seg = snakemake.params.segments["segments"]
    pub = published.paper_a()
    out = snakemake.output
    for v in snakemake.params.variants:
        runs = {}
        for p in snakemake.input[f"mc_{v}"]:
            for r in load_pickle(p):
                if r.case_id == "T1-01":
                    runs[f"{r.mode}-{r.method}"] = r
        figures.save(plots.fig_bias_estimate(runs, v, pub, seg["N"], seg["M"]), out[f"f4_{v}"])
        figures.save(plots.fig_nav_accuracy(runs, v), out[f"f5_{v}"])
        figures.save(plots.fig_compensation(runs, v, pub), out[f"f6_{v}"])
        figures.save(plots.fig_consistency(runs, v), out[f"x4_{v}"])
        log.info("figures for %s", v)
