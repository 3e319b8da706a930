"""Figures of paper A (A-F4, A-F5, A-F6, A-X1). Plotting only; numbers come from the runs.

Every figure uses the shared style (:func:`opnav.core.figures.style`) and draws
the paper's numbers with ``figures.PUBLISHED_STYLE``, labelled "published".
"""

from __future__ import annotations

import numpy as np

from opnav.approach.cases import CaseRun
from opnav.core import figures



def _plain_log_ticks(ax, which: str = "y"):
    """Log-axis tick labels as plain numbers (:func:`opnav.core.figures.plain_log_labels`)."""
    for axis in (ax.xaxis, ax.yaxis) if which == "both" else (ax.yaxis,):
        figures.plain_log_labels(axis)


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


def run_label(r: CaseRun) -> str:
    """Legend label of one EM run: scheme, and its convergence label from the ML estimate of
    the data it used (seeds per label), with the bound of that data."""
    lab = f"EM ({r.method}{', growing' if r.mode == 'growing' else ''})"
    labels = np.asarray(r.label, str)
    if labels.size:
        counts = [(k, int(np.sum(labels == k))) for k in ("converged", "not converged", "stalled")]
        lab += ", " + ", ".join(f"{k} {n}/{labels.size}" for k, n in counts if n)
    if r.bounds is not None:
        lab += f'; bound {r.bounds.crlb_arcsec[0]:.3g}"'
    return lab


def _color(r: CaseRun) -> str:
    return figures.color(f"growing-{r.method}" if r.mode == "growing" else r.method)


def iteration_axis(r: CaseRun) -> np.ndarray:
    """Data used (samples) at each EM map of a run, maps spread evenly inside their segment
    (index 0: the EM initial value at zero data)."""
    d = np.asarray(r.seg_data_used, float)
    per = r.theta_iter_arcsec.shape[1] // len(d)
    prev = np.r_[0.0, d[:-1]]
    frac = np.arange(1, per + 1) / per
    return np.r_[0.0, (prev[:, None] + frac[None, :] * (d - prev)[:, None]).ravel()]


def fig_bias_estimate(runs: dict, variant: str, pub: dict, N: int, M: int):
    """A-F4: theta estimate vs data used, mean +- 1 sd over seeds, truth lines, and the
    1-sigma bound of the data each segment's estimate used (dotted, around the truth)."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(3, 1, figsize=(figures.PAGE_WIDTH_IN, 5.6), sharex=True, layout="constrained")
        truth = None
        for key, r in runs.items():
            th = r.theta_iter_arcsec
            init = np.broadcast_to(np.asarray(r.case.init_arcsec, float), (th.shape[0], 1, 3))
            th = np.concatenate([init, th], axis=1)  # iteration 0 = the EM initial value
            x = iteration_axis(r)
            truth = r.truth_arcsec
            col = _color(r)
            for i, ax in enumerate(axes):
                _band(ax, x, th[:, :, i], col, run_label(r))
                if i < 2 and r.bounds is not None:
                    b = r.bounds.crlb_seg_arcsec[:, i]
                    d = r.seg_data_used
                    ax.plot(d, truth[i] + b, color=col, ls=":", lw=0.8)
                    ax.plot(d, truth[i] - b, color=col, ls=":", lw=0.8)
        names = ["$\\theta_x$", "$\\theta_y$", "$\\theta_z$"]
        hp = pub["headline"]
        for i, ax in enumerate(axes):
            ax.axhline(truth[i], color="k", lw=0.8, ls="--", label="truth")
            ax.set_ylabel(f"{names[i]} (arcsec)")
            if i < 2:
                val = hp["est_x_arcsec"] if i == 0 else hp["est_y_arcsec"]
                ax.plot([x[-1]], [val], **figures.PUBLISHED_STYLE)
            lo, hi = ax.get_ylim()
            span = max(abs(truth[i]), 5.0) * 3
            ax.set_ylim(max(lo, truth[i] - span), min(hi, truth[i] + span))
        axes[0].plot([], [], color="k", ls=":", lw=0.8, label=r"truth $\pm 1\sigma$ bound of the data used")
        if all(r.tz_unobservable for r in runs.values()):
            axes[2].text(0.01, 0.05, "$\\theta_z$: unobservable (held at its initial value)",
                         transform=axes[2].transAxes, fontsize=7)
        axes[-1].set_xlabel("data used (samples); EM iterations spread over each segment")
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", fontsize=6, ncol=2, frameon=False)
        axes[0].set_title(f"A-F4 bias estimate, variant: {variant}", fontsize=8)
    return fig


def fig_nav_accuracy(runs: dict, variant: str):
    """A-F5: lateral and range position error at each segment end during the estimation
    (median, 16-84 %), each with the filter's own 3-sigma of that component (dotted)."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.0), sharex=True, layout="constrained")
        for key, r in runs.items():
            d = r.seg_data_used
            col = _color(r)
            for ax, err, sig3 in ((axes[0], r.seg_lat_err_km, r.seg_lat_3sig_km),
                                  (axes[1], r.seg_rng_err_km, r.seg_rng_3sig_km)):
                _band_log(ax, d, err, col, f"median error, {run_label(r)}")
                ax.plot(d, sig3.mean(0), color=col, ls=":")
        axes[0].plot([], [], color="k", ls=":", label=r"filter's $3\sigma$ of that component (same colour)")
        for ax, name in zip(axes, ("lateral (across the line of sight)", "range (along it)")):
            ax.set_xlabel("data used (samples)")
            ax.set_ylabel(f"{name.split()[0]} error (km)")
            ax.set_yscale("log")
            _plain_log_ticks(ax)
            ax.set_title(f"A-F5 {name}, {variant}", fontsize=8)
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", fontsize=6, ncol=2, frameon=False)
    return fig


def chi2_band(dof: int, n_runs: int, p: float = 0.95) -> tuple[float, float]:
    """Two-sided ``p`` interval of the mean of ``n_runs`` chi-square(dof) values
    (``chi2(dof n_runs) / n_runs``): the consistency band of a seed-averaged NEES/NIS."""
    from scipy.special import gammaincinv  # chi2.ppf(q, k) = 2 gammaincinv(k / 2, q), as scipy.stats

    a = (1.0 - p) / 2.0
    k = dof * n_runs
    return 2 * gammaincinv(k / 2, a) / n_runs, 2 * gammaincinv(k / 2, 1.0 - a) / n_runs


def fig_consistency(runs: dict, variant: str):
    """A-X4: position NEES and NIS over time, mean over seeds (initial error drawn from the
    prior), for the theta = 0 filter and the filter with each scheme's estimate (and, NEES, the
    Schmidt filter carrying its covariance), beside the reference: the NEES of the filter given
    the true theta on the same runs (issue 54: the truth has no process noise while the filters'
    Q > 0, so a consistent compensation shows that filter's NEES, not 3). The 95 % chi-square
    band of the seed average (3 dof) is what a truth with the filters' Q would give."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.0), sharex=True, layout="constrained")
        first = True
        n = 1
        for key, r in runs.items():
            smp = r.sampled
            if not smp:
                continue
            t = r.t_s
            n = smp.theta_final_arcsec.shape[0]
            ct = smp.consistency_t
            for ax, q in zip(axes, ("nees_pos", "nis")):
                if first:
                    ax.plot(t, np.nanmean(getattr(ct.before, q), 0), color="k", ls="--", label=r"$\theta = 0$")
                    if q == "nees_pos":
                        ax.plot(t, np.nanmean(ct.true_theta.nees_pos, 0), color="0.35", ls=":", lw=1.4, zorder=3,
                                label=r"true $\theta$, same runs (the reference)")
                ax.plot(t, np.nanmean(getattr(ct.after, q), 0), color=_color(r),
                        label=rf"$\theta = \hat\theta$, {run_label(r)}")
                if q == "nees_pos":
                    ax.plot(t, np.nanmean(ct.consider.nees_pos, 0), color=_color(r), ls="-.", lw=0.8,
                            label=rf"Schmidt filter, {run_label(r)}")
            first = False
        lo, hi = chi2_band(3, n)
        for ax, name in zip(axes, ("position NEES (3 dof)", "NIS (3 dof)")):
            ax.axhspan(lo, hi, color="0.6", alpha=0.35, lw=0,
                       label=f"95 % $\\chi^2$ band of the mean of {n} seeds (a truth with the filters' Q)")
            ax.set_yscale("log")
            _plain_log_ticks(ax)
            ax.set_xlabel("time (s)")
            ax.set_ylabel(name)
            ax.set_title(f"A-X4 {name}, {variant}", fontsize=8)
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", fontsize=6, ncol=2, frameon=False)
    return fig


def fig_compensation(runs: dict, variant: str, pub: dict):
    """A-F6: position error over time before (theta = 0) and after compensation, mean over seeds:
    |r error| and its lateral (across the line of sight) and range (along it) parts, with the
    filter given the true theta (diagnostic floor) beside them."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(1, 3, figsize=(figures.PAGE_WIDTH_IN, 3.1), sharey=True, layout="constrained")
        first = True
        for method, r in runs.items():
            t = r.t_s
            split = r.err_split_t_km
            if first:
                axes[0].plot(t, r.err_before_t_km.mean(0), color="k", ls="--", lw=1.2, zorder=3,
                             label=r"before ($\theta = 0$)")
                lat, rng = split.true_theta
                axes[0].plot(t, np.hypot(lat, rng).mean(0), color="0.5", ls=":", lw=1.2, zorder=3,
                             label=r"true $\theta$ (diagnostic floor)")
                for j, ax in enumerate(axes[1:]):
                    ax.plot(t, split.before[j].mean(0), color="k", ls="--", lw=1.2, zorder=3)
                    ax.plot(t, split.true_theta[j].mean(0), color="0.5", ls=":", lw=1.2, zorder=3)
                first = False
            axes[0].plot(t, r.err_after_t_km.mean(0), color=_color(r), label=f"after, {run_label(r)}")
            for j, ax in enumerate(axes[1:]):
                ax.plot(t, split.after[j].mean(0), color=_color(r))
        hp = pub["headline"]
        axes[0].plot([t[-1]], [hp["nav_err_before_km"]], **{**figures.PUBLISHED_STYLE, "label": "published before/after"})
        axes[0].plot([t[-1]], [hp["nav_err_after_km"]], **{**figures.PUBLISHED_STYLE, "label": None})
        for ax, name in zip(axes, ("|r error|", "lateral (across line of sight)", "range (along line of sight)")):
            ax.set_yscale("log")
            _plain_log_ticks(ax)
            ax.set_xlabel("time (s)")
            ax.set_title(name, fontsize=7)
        axes[0].set_ylabel("position error (km)")
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", fontsize=6, ncol=2, frameon=False)
        fig.suptitle(f"A-F6 before vs after compensation, {variant}", fontsize=8)
    return fig


def fig_crlb(curves: dict, conv: dict, x1, target: float, N0: int):
    """A-X1: CRLB of tx vs data per variant with the EM estimates; EM distance to the MLE vs maps."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.2), layout="constrained")
        for v, c in curves.items():
            d = np.arange(len(c))
            col = figures.color(v)
            lab = v + (" (diagnostic)" if v == "reference-start" else "")
            a1.plot(d[1:], c[1:, 0], color=col, label=f"CRLB $t_x$, {lab}")
            row = x1[x1["variant"] == v]
            if len(row):
                r = row.iloc[0]
                if "em_plain_rmse_x_arcsec" in r and not np.isnan(r["em_plain_rmse_x_arcsec"]):
                    a1.plot([r["total_samples"]], [r["em_plain_rmse_x_arcsec"]], "o", color=col, mfc="none")
                if "mle_rmse_x_arcsec" in r and not np.isnan(r["mle_rmse_x_arcsec"]):
                    a1.plot([r["mle_samples"]], [r["mle_rmse_x_arcsec"]], "s", color=col)
        a1.axhline(target, **{**figures.PUBLISHED_STYLE, "linestyle": "--", "marker": None,
                              "label": f'published accuracy claim ({target:g}")'})
        a1.plot([], [], "o", color="k", mfc="none", label="RMS error, plain EM (segments)")
        a1.plot([], [], "s", color="k", label="RMS error, ML (SQUAREM, one window)")
        a1.set_xscale("log")
        a1.set_yscale("log")
        a1.set_xlabel(f"data used after $N_0$ = {N0} (samples)")
        a1.set_ylabel(r"$1\sigma$ bound / RMS error (arcsec)")
        _plain_log_ticks(a1, "both")
        for v, c in conv.items():
            col = figures.color(v)
            for method, maps, ls in (("plain", c.plain, "-"), ("squarem", c.squarem, "--")):
                dist = np.median(maps.dist_arcsec, axis=0)
                a2.plot(np.arange(1, len(dist) + 1), np.maximum(dist, 1e-6), color=col, ls=ls,
                        label=f"{v}, {method}")
        a2.set_yscale("log")
        a2.set_xlabel("EM map evaluations")
        a2.set_ylabel(r"$|\theta - \theta_{ML}|$ (arcsec), median")
        _plain_log_ticks(a2)
        h1, l1 = a1.get_legend_handles_labels()
        h2, l2 = a2.get_legend_handles_labels()
        fig.legend(h1 + h2, l1 + l2, loc="outside lower center", fontsize=6, ncol=3, frameon=False)
    return fig


#: A-X2 per-method panels: (column of :func:`alternatives_per_method`, y label, log scale)
_X2_PANELS = [("bias", "mean |bias error| (arcsec)", True),
              ("spread", "spread (sd over seeds, arcsec)", True),
              ("nav_after", "nav. error after (km)", False),
              ("data", "data needed (samples)", False),
              ("runtime", "run time (s per seed)", True)]


def alternatives_per_method(long) -> "pd.DataFrame":
    """A-X2 figure data: per variant and method, the mean |bias error| and median spread
    over the Table-1 cases (tx and ty, arcsec), the median CRLB, the mean navigation
    error after (and before) compensation (km), the median data needed (samples) and the
    headline case's run time per seed (s); ``long`` is the per-case A-X2 table."""
    import pandas as pd

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


def fig_alternatives(long, method_labels: dict):
    """A-X2: EM-EKF vs augmented EKF vs batch ML per scenario variant (five panels of
    :func:`alternatives_per_method`, CRLB and the error before compensation beside)."""
    import matplotlib.pyplot as plt

    pm = alternatives_per_method(long)
    variants = list(dict.fromkeys(pm["variant"]))
    methods = [m for m in method_labels if m in set(pm["method"])]
    width = 0.8 / len(methods)
    with figures.style():
        fig, axes = plt.subplots(2, 3, figsize=(figures.PAGE_WIDTH_IN, 4.4))
        axes = axes.ravel()
        for ax, (col, label, logy) in zip(axes, _X2_PANELS):
            for i, m in enumerate(methods):
                d = pm[pm["method"] == m].set_index("variant").reindex(variants)
                x = np.arange(len(variants)) + (i - (len(methods) - 1) / 2) * width
                vals = d[col].to_numpy(float)
                if logy:  # bars have no natural base on a log axis: markers
                    ax.plot(x, vals, "o", color=figures.color(m), ms=4, label=method_labels[m])
                else:
                    ax.bar(x, np.where(np.isfinite(vals), vals, 0.0), width, color=figures.color(m),
                           label=method_labels[m])
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
                figures.plain_log_labels(ax.yaxis)
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
    return fig


def fig_nav_floor(nf: dict, limit_km: float | None = None):
    """A-X7: navigation error after compensation against arc length (rows of
    :func:`opnav.approach.navfloor.nav_floor_by_arc`), mean over seeds: by the plan's rule (RMS
    over the arc's last part, solid) and at the arc's last sample (dashed), for the compensated
    filter, the filter given the true theta (grey: a filter's floor) and the theta = 0 filter
    (black); ``limit_km`` (the paper's 20 km, from the analysis plan) dotted."""
    import matplotlib.pyplot as plt

    rows = nf.rows
    x = np.array([r.arc_s for r in rows], float)
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.PAGE_WIDTH_IN * 0.7, 3.4), layout="constrained")
        for key, color, name, z in (("true_theta_km", "0.55", r"true $\theta$ (a filter's floor)", 2),
                                    ("nav_err_km", figures.color("growing-squarem"), f"{nf.variant}, compensated", 3),
                                    ("before_km", "k", r"$\theta = 0$", 2)):
            ax.plot(x, [getattr(r, f"{key}_rule") for r in rows], "o-", color=color, lw=1.0 if z == 3 else 1.8, ms=3, zorder=z,
                    label=f"{name}, RMS over the last part")
            ax.plot(x, [getattr(r, f"{key}_last") for r in rows], "s--", color=color, lw=0.8 if z == 3 else 1.6, ms=2.5,
                    zorder=z, label=f"{name}, last sample")
        if limit_km is not None:
            ax.axhline(limit_km, color="C3", lw=0.8, ls=":", label=f"paper's limit {limit_km:g} km")
        ax.set_yscale("log")
        _plain_log_ticks(ax)
        ax.set_xlabel("arc length (s)")
        ax.set_ylabel("position error (km)")
        ax.set_title(f"A-X7 navigation error against arc length, {rows[0].n_seeds} seeds", fontsize=8)
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=5.5, ncol=2, frameon=False)
    return fig
