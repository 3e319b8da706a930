"""The convergence figure of a user's own misalignment estimators (``approach.custom_estimators``):
drawn from :func:`opnav.approach.estimator_summary.curves` only (the style of A-F4)."""

from __future__ import annotations

import numpy as np

from opnav.core import figures

__all__ = ["fig_convergence"]


def fig_convergence(curves: dict, colors: dict | None = None):
    """Per variant (rows) and axis tx, ty (columns): each estimator's estimate (arcsec) against the
    data it used (samples after N0), mean over the seeds and a band of one sd; the truth dashed and
    the truth plus and minus the 1-sigma Cramér-Rao bound of that data dotted. ``colors``: name ->
    colour (the config's), else the palette's."""
    import matplotlib.pyplot as plt

    colors = colors or {}
    variants = list(curves)
    with figures.style():
        fig, axs = plt.subplots(len(variants), 2, figsize=(figures.PAGE_WIDTH_IN, 2.3 * len(variants) + 0.6),
                                sharex=True, squeeze=False, constrained_layout=True)
        for i, v in enumerate(variants):
            c = curves[v]
            d = c.data
            for j, ax_name in enumerate(("t_x", "t_y")):
                ax = axs[i, j]
                tr, b = c.truth[j], c.bound[:, j]
                ax.axhline(tr, color="k", ls="--", lw=0.8, label="truth")
                ax.plot(d, tr + b, color="0.4", ls=":", lw=0.8, label=r"truth $\pm$ 1-sigma bound of the data used")
                ax.plot(d, tr - b, color="0.4", ls=":", lw=0.8)
                for n, th in c.estimators.items():
                    col = colors.get(n) or figures.color(n)
                    m = th[:, :, j].mean(axis=0)
                    sd = th[:, :, j].std(axis=0, ddof=1) if th.shape[0] > 1 else np.zeros_like(m)
                    ax.plot(d, m, color=col, lw=1.2, marker="o", ms=2.5, label=c.labels.get(n, n))
                    ax.fill_between(d, m - sd, m + sd, color=col, alpha=0.2, lw=0)
                ax.set_title(f"{v}: ${ax_name}$", fontsize="medium")
                if j == 0:
                    ax.set_ylabel("estimate (arcsec)")
                if i == len(variants) - 1:
                    ax.set_xlabel("data used after N0 (samples)")
        h, lab = axs[0, 0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", ncol=min(4, len(lab)), fontsize="x-small")
        return fig
