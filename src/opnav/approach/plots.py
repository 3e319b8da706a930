"""Figures of paper A (A-F4, A-F5, A-F6, A-X1). Plotting only; numbers come from the runs.

Every figure uses the shared style (:func:`opnav.figures.style`) and draws
the paper's numbers with ``figures.PUBLISHED_STYLE``, labelled "published".
"""

from __future__ import annotations

import numpy as np

from opnav import figures

COLORS = {"plain": "C0", "squarem": "C3"}
VCOLORS = {"literal": "C0", "prior": "C1", "roll": "C2", "reference-start": "C3"}


def _plain_log_ticks(ax):
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.yaxis.set_minor_formatter(NullFormatter())


def _band(ax, x, y, color, label, ls="-"):
    """Mean and +-1 sd over seeds (linear axes)."""
    m, s = y.mean(0), y.std(0)
    ax.plot(x, m, color=color, ls=ls, label=label)
    ax.fill_between(x, m - s, m + s, color=color, alpha=0.2, lw=0)


def _band_log(ax, x, y, color, label, ls="-"):
    """Median and 16-84 % band over seeds (log axes: stays positive)."""
    lo, med, hi = np.percentile(y, [16, 50, 84], axis=0)
    ax.plot(x, med, color=color, ls=ls, label=label)
    ax.fill_between(x, lo, hi, color=color, alpha=0.2, lw=0)


def fig_bias_estimate(runs: dict, variant: str, pub: dict, N: int, M: int):
    """A-F4: theta estimate vs cumulative EM iterations, mean +- 1 sd over seeds, truth lines."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(3, 1, figsize=(figures.PAGE_WIDTH_IN, 5.2), sharex=True)
        truth = None
        for method, r in runs.items():
            th = r["theta_iter_arcsec"]
            init = np.broadcast_to(np.asarray(r["case"].init_arcsec, float), (th.shape[0], 1, 3))
            th = np.concatenate([init, th], axis=1)  # iteration 0 = the EM initial value
            L = len(r["seg_data_used"])
            per = (th.shape[1] - 1) // L  # EM maps per segment
            # EM maps spread evenly inside their segment: x = data used when the map runs
            x = np.r_[0.0, (np.repeat(np.arange(L), per) + np.tile(np.arange(1, per + 1) / per, L)) * N]
            truth = r["truth_arcsec"]
            for i, ax in enumerate(axes):
                _band(ax, x, th[:, :, i], COLORS[method], f"EM ({method})")
        names = ["$\\theta_x$", "$\\theta_y$", "$\\theta_z$"]
        hp = pub["headline"]
        for i, ax in enumerate(axes):
            ax.axhline(truth[i], color="k", lw=0.8, ls="--", label="truth")
            ax.set_ylabel(f"{names[i]} (arcsec)")
            if i < 2:
                val = hp["est_x_arcsec"] if i == 0 else hp["est_y_arcsec"]
                ax.plot([x[-1]], [val], **figures.PUBLISHED_STYLE)
        axes[2].text(0.01, 0.05, "$\\theta_z$: unobservable (held at its initial value)",
                     transform=axes[2].transAxes, fontsize=7)
        axes[-1].set_xlabel(f"data used (samples); EM iterations spread over each {N}-sample segment")
        axes[0].legend(loc="best", fontsize=7, ncol=4)
        axes[0].set_title(f"A-F4 bias estimate, variant: {variant}", fontsize=8)
        fig.tight_layout()
    return fig


def fig_nav_accuracy(runs: dict, variant: str):
    """A-F5: position error at each segment end during the estimation (median, 16-84 %) and filter 3-sigma."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 2.6))
        for method, r in runs.items():
            d = r["seg_data_used"]
            _band_log(ax, d, r["seg_pos_err_km"], COLORS[method], f"|r error| median, EM ({method})")
            ax.plot(d, r["seg_pos_3sig_km"].mean(0), color=COLORS[method], ls=":", label=f"3-sigma ({method})")
        ax.set_xlabel("data used (samples)")
        ax.set_ylabel("position error (km)")
        ax.set_yscale("log")
        _plain_log_ticks(ax)
        ax.legend(fontsize=6)
        ax.set_title(f"A-F5 navigation during estimation, {variant}", fontsize=8)
        fig.tight_layout()
    return fig


def fig_compensation(runs: dict, variant: str, pub: dict):
    """A-F6: |r error| over time before (theta = 0) and after compensation, mean over seeds."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 2.6))
        first = True
        for method, r in runs.items():
            t = r["t_s"]
            if first:
                ax.plot(t, r["err_before_t_km"].mean(0), color="k", ls="--", lw=1.2, zorder=3,
                        label="before (theta = 0)")
                first = False
            ax.plot(t, r["err_after_t_km"].mean(0), color=COLORS[method], label=f"after, EM ({method})")
        hp = pub["headline"]
        ax.plot([t[-1]], [hp["nav_err_before_km"]], **{**figures.PUBLISHED_STYLE, "label": "published before/after"})
        ax.plot([t[-1]], [hp["nav_err_after_km"]], **{**figures.PUBLISHED_STYLE, "label": None})
        ax.set_yscale("log")
        _plain_log_ticks(ax)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("position error (km)")
        ax.legend(fontsize=6)
        ax.set_title(f"A-F6 before vs after compensation, {variant}", fontsize=8)
        fig.tight_layout()
    return fig


def fig_crlb(curves: dict, conv: dict, x1, target: float, N0: int):
    """A-X1: CRLB of tx vs data per variant with the EM estimates; EM distance to the MLE vs maps."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 2.8))
        for v, c in curves.items():
            d = np.arange(len(c))
            col = VCOLORS.get(v, "k")
            lab = v + (" (diagnostic)" if v == "reference-start" else "")
            a1.plot(d[1:], c[1:, 0], color=col, label=f"CRLB tx, {lab}")
            row = x1[x1["variant"] == v]
            if len(row):
                r = row.iloc[0]
                if "em_plain_rmse_x_arcsec" in r and not np.isnan(r["em_plain_rmse_x_arcsec"]):
                    a1.plot([r["total_samples"]], [r["em_plain_rmse_x_arcsec"]], "o", color=col, mfc="none")
                if "mle_rmse_x_arcsec" in r and not np.isnan(r["mle_rmse_x_arcsec"]):
                    a1.plot([r["mle_samples"]], [r["mle_rmse_x_arcsec"]], "s", color=col)
        a1.axhline(target, **{**figures.PUBLISHED_STYLE, "linestyle": "--", "marker": None,
                              "label": f"published accuracy claim ({target:g} arcsec)"})
        a1.plot([], [], "o", color="k", mfc="none", label="RMS error, plain EM (segments)")
        a1.plot([], [], "s", color="k", label="RMS error, ML (SQUAREM, one window)")
        a1.set_xscale("log")
        a1.set_yscale("log")
        a1.set_xlabel(f"data used after N0 = {N0} (samples)")
        a1.set_ylabel("1-sigma bound / RMS error (arcsec)")
        a1.legend(fontsize=5.5)
        for v, c in conv.items():
            col = VCOLORS.get(v, "k")
            for method, ls in (("plain", "-"), ("squarem", "--")):
                dist = np.median(c[method]["dist_arcsec"], axis=0)
                a2.plot(np.arange(1, len(dist) + 1), np.maximum(dist, 1e-6), color=col, ls=ls,
                        label=f"{v}, {method}")
        a2.set_yscale("log")
        a2.set_xlabel("EM map evaluations")
        a2.set_ylabel("|theta - theta_ML| (arcsec), median")
        a2.legend(fontsize=5.5, ncol=2)
        fig.tight_layout()
    return fig
