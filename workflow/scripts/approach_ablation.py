"""A-X3 ablation (pixel noise or segment length): table and figure of estimate spread vs CRLB."""

import numpy as np

from opnav import figures
from opnav.approach.ablation import run_sweep
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_table

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(
        output={"table": [f"results/approach/A-X3_ablation_pixel.{e}" for e in ("csv", "tex", "md")],
                "fig": ["results/approach/A-X3_ablation_pixel.pdf", "results/approach/A-X3_ablation_pixel.png"]})
    snakemake.params = type("P", (), {"approach": snakemake.config["approach"], "sweep": "pixel"})()

XLABEL = {"pixel": "centroid pixel error, 3-sigma (px)", "segment": "EM segment length N (samples)"}
TITLE = {"pixel": "pixel noise", "segment": "segment length"}

with script_context(snakemake) as log:
    cfg = snakemake.params.approach
    sweep = snakemake.params.sweep
    df = run_sweep(cfg, sweep, log=log)
    write_table(df, snakemake.output.table,
                caption=f"A-X3: {TITLE[sweep]} ablation of the headline case; spread = sd over seeds (arcsec), "
                        "RMSE and 1-sigma CRLB in arcsec.")
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
                        label=f"{v}: CRLB")
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
