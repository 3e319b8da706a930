"""A-X3 ablation (pixel noise or segment length) and A-X5 sensitivity (prior sigma, range, roll rate):
table and figure of estimate spread vs CRLB (A-X5 also the log-log slopes)."""

import sys

from opnav import figures
from opnav.approach import plots
from opnav.approach.ablation import SLOPE_SWEEPS, loglog_slopes, run_sweep
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_ablation_pixel", argv=sys.argv[1:])


TITLE = {"pixel": "pixel noise", "segment": "segment length", "prior": "prior sigma", "range": "initial range",
         "roll_rate": "roll rate"}

with script_context(snakemake) as log:
    cfg = snakemake.params.approach
    sweep = snakemake.params.sweep
    df = run_sweep(cfg, sweep, log=log)
    tag = "A-X5" if sweep in SLOPE_SWEEPS else "A-X3"
    write_table(df, snakemake.output.table,
                caption=f"{tag}: {TITLE[sweep]} sweep of the headline case (initial error drawn from the prior); "
                        "spread = sd over seeds (arcsec), RMSE and 1-sigma CRLB of the data each estimator used, arcsec.")
    if sweep in SLOPE_SWEEPS:
        slopes = loglog_slopes(df)
        write_table(slopes, snakemake.output.slopes,
                    caption=f"A-X5: log-log slopes against the {TITLE[sweep]} of the bound and of the spread.")
        log.info("A-X5 %s slopes:\n%s", sweep, slopes.to_string())
    figures.save(plots.fig_ablation(df, sweep), snakemake.output.fig)
    log.info("A-X3 %s: %d rows", sweep, len(df))
