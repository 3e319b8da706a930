"""A-X3 ablation (pixel noise or segment length) and A-X5 sensitivity (prior sigma, range, roll rate):
table and figure of estimate spread vs CRLB (A-X5 also the log-log slopes)."""

import sys

import numpy as np

from opnav import figures
from opnav.approach.ablation import SLOPE_SWEEPS, loglog_slopes, run_sweep
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_ablation_pixel", argv=sys.argv[1:])


XLABEL = {"pixel": "centroid pixel error, 3-sigma (px)", "segment": "EM segment length N (samples)",
          "prior": "prior 1-sigma / configured prior 1-sigma", "range": "initial range (km)",
          "roll_rate": "roll rate (deg/s)"}
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
    with figures.style():
        import matplotlib.pyplot as plt

        variants = list(dict.fromkeys(df["variant"]))
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.6), sharex=True)
        for ax, axis in zip(axes, ("x", "y")):
            for i, v in enumerate(variants):
                d = df[df["variant"] == v]
                col = f"C{i}"
                em = d[d["estimator"].str.startswith("EM-EKF")]
                au = d[d["estimator"] == "augmented EKF"]
                ax.plot(em["value"], em[f"sd_{axis}_arcsec"], "o-", color=col, label=f"{v}: EM-EKF spread")
                ax.plot(em["value"], em[f"rmse_{axis}_arcsec"], "o:", color=col, mfc="none",
                        label=f"{v}: EM-EKF RMSE")
                ax.plot(au["value"], au[f"sd_{axis}_arcsec"], "s--", color=col, ms=3,
                        label=f"{v}: augmented EKF spread")
                ax.plot(au["value"], au[f"rmse_{axis}_arcsec"], "s:", color=col, ms=4, mfc="none",
                        label=f"{v}: augmented EKF RMSE")
                ax.plot(em["value"], em[f"crlb_{axis}_arcsec"], "-", color="k" if i == 0 else "0.55", lw=1.5,
                        label=f"{v}: CRLB of the data EM-EKF used")
                ax.plot(au["value"], au[f"crlb_{axis}_arcsec"], "--", color="k" if i == 0 else "0.55", lw=1.0,
                        label=f"{v}: CRLB of all data")
            ax.set_yscale("log")
            if np.all(df["value"] > 0):
                ax.set_xscale("log")
            ax.set_xlabel(XLABEL[sweep])
            ax.set_ylabel(f"t{axis}: spread, RMSE, CRLB (arcsec)")
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="lower center", ncol=len(variants) * 2 if len(variants) < 3 else 5,
                   fontsize="x-small", frameon=False)
        fig.tight_layout(rect=(0, 0.2, 1, 1))
        figures.save(fig, snakemake.output.fig)
    log.info("A-X3 %s: %d rows", sweep, len(df))
