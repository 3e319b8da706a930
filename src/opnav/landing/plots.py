"""Figures of paper B (B-F4 to B-F7), drawn from computed results only.

Every function takes arrays computed elsewhere, draws under the shared style
(``opnav.figures.style``) and returns the figure; the workflow scripts save it
with ``opnav.figures.save``. Units are on every axis.
"""

from __future__ import annotations

import math

import numpy as np

from opnav import figures

__all__ = ["fig_true_states", "fig_depth_error_map", "fig_nav_error_envelopes",
           "fig_planning_time", "METHOD_COLORS"]

METHOD_COLORS = {"depth": "C0", "svd": "C1", "gdop": "C2", "cond": "C3", "logdet": "C4",
                 "mineig": "C5", "random": "C6", "center": "C7"}
METHOD_LABELS = {"depth": "depth error", "svd": "SVD", "gdop": "GDOP", "cond": "cond. number",
                 "logdet": "log-det", "mineig": "min. eigenvalue"}


def _color(m, i):
    return METHOD_COLORS.get(m, f"C{i % 10}")


def _label(m):
    return METHOD_LABELS.get(m, m)


def fig_true_states(t, r, v, rpy_deg):
    """B-F4: true position (m), velocity (m/s) and attitude (deg) vs time (s)."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axs = plt.subplots(1, 3, figsize=(figures.PAGE_WIDTH_IN, 2.3), constrained_layout=True)
        for ax, data, lab, unit, names in (
                (axs[0], r, "position", "m", ("x", "y", "z")),
                (axs[1], v, "velocity", "m/s", ("x", "y", "z")),
                (axs[2], rpy_deg, "attitude", "deg", ("roll", "pitch", "yaw"))):
            for k in range(3):
                ax.plot(t, data[:, k], label=names[k])
            ax.set_xlabel("time (s)")
            ax.set_ylabel(f"{lab} ({unit})")
            ax.legend(loc="best")
        return fig


def fig_depth_error_map(uv_px, dr_m, best_idx, half_px, curve_beta_deg, curve_dr, interval_deg,
                        opt_beta_deg, opt_uv_px=None):
    """B-F5: depth error of the visible landmarks in the image (a), the single
    optimum marked, and along the velocity's vertical plane vs beta (b)."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    with figures.style():
        fig, axs = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.0), constrained_layout=True,
                                gridspec_kw={"width_ratios": [1.15, 1]})
        ax = axs[0]
        fin = np.isfinite(dr_m)
        sc = ax.scatter(uv_px[fin, 0], uv_px[fin, 1], c=dr_m[fin], s=3, cmap="viridis",
                        norm=LogNorm(vmin=np.nanmin(dr_m[fin]), vmax=np.nanpercentile(dr_m[fin], 99)),
                        rasterized=True)
        ax.plot(*uv_px[best_idx], marker="*", ms=12, mfc="red", mec="k", ls="none", zorder=5,
                clip_on=False, label=f"optimum ({dr_m[best_idx]:.0f} m)")
        if opt_uv_px is not None and np.all(np.isfinite(opt_uv_px)):
            ax.plot(*opt_uv_px, marker="+", ms=12, mew=2.0, color="red", ls="none", zorder=5,
                    clip_on=False, label="golden-section direction")
        ax.plot([-half_px, half_px, half_px, -half_px, -half_px],
                [-half_px, -half_px, half_px, half_px, -half_px], color="k", lw=0.6)
        ax.set_xlim(-1.06 * half_px, 1.06 * half_px)
        ax.set_ylim(1.06 * half_px, -1.06 * half_px)
        ax.set_aspect("equal")
        ax.set_xlabel("image u (px)")
        ax.set_ylabel("image v (px)")
        ax.legend(loc="upper left", fontsize="small")
        fig.colorbar(sc, ax=ax, label="depth estimation error (m)")
        ax = axs[1]
        ax.semilogy(curve_beta_deg, curve_dr, color="C0")
        for lo, hi in interval_deg:
            ax.axvspan(lo, hi, color="0.9", zorder=0)
        ax.axvline(opt_beta_deg, color="k", ls="--", lw=0.8,
                   label=f"golden-section optimum {opt_beta_deg:.1f} deg")
        ax.set_xlabel("signed beta (deg); grey: visible")
        ax.set_ylabel("in-plane depth error (m)")
        ax.legend(loc="upper right", fontsize="small")
        return fig


def fig_nav_error_envelopes(t, data: dict[str, dict]):
    """B-F6: 3-sigma envelopes (3 x sample standard deviation over the runs) of
    the position (m), velocity (m/s) and attitude (roll/pitch/yaw, deg) errors
    per axis, one line per method (log scale)."""
    import matplotlib.pyplot as plt

    rows = (("err_r", "position", "m", ("x", "y", "z")),
            ("err_v", "velocity", "m/s", ("x", "y", "z")),
            ("err_rpy_deg", "attitude", "deg", ("roll", "pitch", "yaw")))
    with figures.style():
        fig, axs = plt.subplots(3, 3, figsize=(figures.PAGE_WIDTH_IN, 6.2), sharex=True,
                                constrained_layout=True)
        for i, (key, name, unit, axes) in enumerate(rows):
            for j in range(3):
                ax = axs[i, j]
                for k, (m, d) in enumerate(data.items()):
                    e = d[key][:, :, j]
                    s3 = 3.0 * e.std(axis=0, ddof=1) if e.shape[0] > 1 else np.abs(e[0])
                    ax.plot(t, s3, color=_color(m, k), lw=1.0, label=_label(m),
                            ls=("-", "--", "-.", ":")[k % 4])
                ax.set_yscale("log")
                ax.set_title(f"{name} {axes[j]}", fontsize="medium")
                if j == 0:
                    ax.set_ylabel(f"3-sigma error ({unit})")
                if i == 2:
                    ax.set_xlabel("time (s)")
        axs[0, 0].legend(loc="lower left", fontsize="small")
        return fig


def fig_planning_time(data: dict[str, dict], published_reduction_vs_svd: float | None = None):
    """B-F7: planning-call wall time (us) per method, box = quartiles, whiskers =
    min/max (as the paper's Fig. 7), medians and evaluations per call annotated."""
    import matplotlib.pyplot as plt

    methods = list(data)
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 2.8), constrained_layout=True)
        vals = [np.asarray(data[m]["plan_ns"], float) / 1e3 for m in methods]
        bp = ax.boxplot(vals, whis=(0, 100), showfliers=False, patch_artist=True, widths=0.6)
        for k, (patch, m) in enumerate(zip(bp["boxes"], methods)):
            patch.set_facecolor(_color(m, k))
            patch.set_alpha(0.5)
        ax.set_yscale("log")
        labels = []
        for m, v in zip(methods, vals):
            ev = np.median(data[m]["plan_evals"]) if len(data[m]["plan_evals"]) else math.nan
            labels.append(f"{_label(m)}\n{ev:.0f} evals")
        ax.set_xticks(range(1, len(methods) + 1), labels, fontsize="small")
        for k, v in enumerate(vals, start=1):
            if len(v):
                med = float(np.median(v))
                ax.annotate(f"{med:.0f}", (k, med), xytext=(0, 3), textcoords="offset points",
                            ha="center", va="bottom", fontsize="x-small")
        ax.set_ylabel("planning-call time (us)")
        if published_reduction_vs_svd is not None and "depth" in data and "svd" in data:
            ours = 100 * (1 - np.median(vals[methods.index("depth")]) / np.median(vals[methods.index("svd")]))
            ax.set_title(f"depth vs SVD median: {ours:.1f} % less (published {published_reduction_vs_svd:.2f} %)",
                         fontsize="small")
        return fig
