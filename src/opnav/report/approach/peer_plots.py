"""A-P1 figure: the peer UKF's misalignment estimate over the arc beside the paper's estimators.

Plotting only (numbers from :mod:`opnav.approach.peers` runs and the A-P1 table).
"""

from __future__ import annotations


from opnav.core import figures

RCOLORS = {"headline": "k", "bias_free": "#CC79A7", "truth_start": "0.55"}


def peer_figure(peer: list[dict], table):
    """Rows tx, ty; one column per variant. Lines: the UKF per run (seed mean) with its own
    3-sigma band; right-hand markers: the paper's estimators' end values (mean +- sd over
    seeds); shaded: truth +- 3 CRLB of the paper's estimators."""
    import matplotlib.pyplot as plt

    from .text import RUN_LABELS

    nv = len(peer)
    with figures.style():
        fig, axes = plt.subplots(2, nv, figsize=(figures.PAGE_WIDTH_IN, 4.6), sharex=True, squeeze=False,
                                 layout="constrained")
        for j, p in enumerate(peer):
            v = p.variant
            tv = table[table["variant"] == v]
            for i, comp in enumerate("xy"):
                ax = axes[i, j]
                t_end = 0.0
                for name, r in p.runs.items():
                    t = r.t_hist_s
                    t_end = max(t_end, t[-1])
                    m = r.theta_hist_arcsec[:, :, i].mean(0)
                    s3 = r.sigma3_hist_arcsec[:, :, i].mean(0)
                    ax.plot(t, m, color=RCOLORS[name], lw=1.0, label=f"UKF: {RUN_LABELS[name]}")
                    ax.fill_between(t, m - s3, m + s3, color=RCOLORS[name], alpha=0.2, lw=0)
                    ax.axhline(r.truth_arcsec[i], color=RCOLORS[name], lw=0.6, ls=":")
                others = tv[tv["estimator"] != "Basilisk pixelLineBiasUKF"]
                if len(others):
                    c3 = others[f"crlb_3sigma_{comp}_arcsec"].iloc[0]
                    tr = others[f"truth_{comp}_arcsec"].iloc[0]
                    ax.axhspan(tr - c3, tr + c3, color="C2", alpha=0.08, lw=0, label=r"truth $\pm 3\times$ CRLB")
                for k, (_, o) in enumerate(others.iterrows()):
                    x = t_end * (1.03 + 0.025 * k)
                    ax.errorbar([x], [o[f"est_{comp}_mean_arcsec"]], yerr=[o[f"est_{comp}_sd_arcsec"]],
                                fmt="o", ms=3, color=figures.color(o["estimator"]), label=o["estimator"])
                ax.set_ylabel(f"$t_{comp}$ (arcsec)")
                if i == 0:
                    ax.set_title(v)
                if i == 1:
                    ax.set_xlabel("time from $t_0$ (s)")
        handles, labels = [], []
        for ax in axes.ravel():
            for h, lab in zip(*ax.get_legend_handles_labels()):
                if lab not in labels:
                    handles.append(h)
                    labels.append(lab)
        fig.legend(handles, labels, loc="outside lower center", ncol=3, frameon=False, fontsize="small")
    return fig
