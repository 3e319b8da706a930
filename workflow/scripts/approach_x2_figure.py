"""A-X2 figure: EM-EKF vs augmented EKF vs batch ML, per scenario variant (from the long-form CSV)."""

import sys

import numpy as np
import pandas as pd

from opnav import figures
from opnav.approach.report import METHOD_LABELS
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_x2_figure", argv=sys.argv[1:])


COLORS = {"em_plain": "#0072B2", "em_squarem": "#56B4E9", "augmented": "#D55E00", "batch_ml": "#009E73"}


def per_method(long: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for (v, m), g in long.groupby(["variant", "method"], sort=False):
        h = g[g["case_id"] == "T1-01"]
        rows.append({
            "variant": v, "method": m,
            "bias": float(np.mean(np.abs(np.r_[g["err_x_mean_arcsec"], g["err_y_mean_arcsec"]]))),
            "spread": float(np.median(np.r_[g["err_x_std_arcsec"], g["err_y_std_arcsec"]])),
            "crlb": float(np.median(np.r_[g["crlb_x_arcsec"], g["crlb_y_arcsec"]])),
            "nav_after": float(g["nav_err_after_km"].mean()),
            "nav_before": float(g["nav_err_before_km"].mean()) if "nav_err_before_km" in g else np.nan,
            "data": float(np.nanmedian(g["data_to_converge_samples"]))
            if g["data_to_converge_samples"].notna().any() else np.nan,
            "runtime": float(h["runtime_s_per_seed"].iloc[0]) if len(h) else np.nan,
        })
    return pd.DataFrame(rows)

with script_context(snakemake) as log:
    long = pd.read_csv(snakemake.input.long)
    pm = per_method(long)
    variants = list(dict.fromkeys(pm["variant"]))
    methods = [m for m in METHOD_LABELS if m in set(pm["method"])]
    width = 0.8 / len(methods)
    panels = [("bias", "mean |bias error| (arcsec)", True),
              ("spread", "spread (sd over seeds, arcsec)", True),
              ("nav_after", "nav. error after (km)", False),
              ("data", "data needed (samples)", False),
              ("runtime", "run time (s per seed)", True)]
    with figures.style():
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(2, 3, figsize=(figures.PAGE_WIDTH_IN, 4.4))
        axes = axes.ravel()
        for ax, (col, label, logy) in zip(axes, panels):
            for i, m in enumerate(methods):
                d = pm[pm["method"] == m].set_index("variant").reindex(variants)
                x = np.arange(len(variants)) + (i - (len(methods) - 1) / 2) * width
                vals = d[col].to_numpy(float)
                if logy:  # bars have no natural base on a log axis: markers
                    ax.plot(x, vals, "o", color=COLORS[m], ms=4, label=METHOD_LABELS[m])
                else:
                    ax.bar(x, np.where(np.isfinite(vals), vals, 0.0), width, color=COLORS[m],
                           label=METHOD_LABELS[m])
            if col in ("bias", "spread"):
                cr = pm.groupby("variant", sort=False)["crlb"].first().reindex(variants)
                for j, v in enumerate(cr):
                    ax.hlines(v, j - 0.45, j + 0.45, colors="k", linestyles="--",
                              label="CRLB (median over cases)" if j == 0 else None)
            if col == "nav_after":
                nb = pm[pm["method"].str.startswith("em_")].groupby("variant", sort=False)["nav_before"].first()
                for j, v in enumerate(nb.reindex(variants)):
                    ax.hlines(v, j - 0.45, j + 0.45, colors="0.4", linestyles=":",
                              label="before compensation" if j == 0 else None)
            if logy:
                ax.set_yscale("log")
            ax.set_xticks(np.arange(len(variants)), variants)
            ax.set_ylabel(label)
        handles, labels = [], []
        for ax in axes[:5]:
            for h, lab in zip(*ax.get_legend_handles_labels()):
                if lab not in labels:
                    handles.append(h)
                    labels.append(lab)
        axes[5].axis("off")
        axes[5].legend(handles, labels, loc="center", frameon=False)
        fig.tight_layout()
        figures.save(fig, snakemake.output.fig)
    log.info("A-X2 figure: %d methods x %d variants", len(methods), len(variants))
