"""Figures of paper B (B-F4 to B-F7), drawn from computed results only.

Every function takes arrays computed elsewhere, draws under the shared style
(``opnav.core.figures.style``) and returns the figure; the workflow scripts save it
with ``opnav.core.figures.save``. Units are on every axis.
"""

from __future__ import annotations


import numpy as np

from typing import TYPE_CHECKING

from opnav.core import figures

if TYPE_CHECKING:
    from opnav.landing.records import Replay

__all__ = ["fig_true_states", "fig_depth_error_map", "fig_nav_error_envelopes",
           "fig_planning_time"]

METHOD_LABELS = {"depth": "depth error", "svd": "SVD", "gdop": "GDOP", "cond": "cond. number",
                 "logdet": "log-det", "mineig": "min. eigenvalue", "svd_w": "SVD (whitened)",
                 "gdop_w": "GDOP (whitened)", "cond_w": "cond. (whitened)",
                 "logdet_nav": "log-det (planned, nav.)", "closest": "closest (range)"}


def _label(m, labels=None):
    """A method's legend name: ``labels`` (a user's own method's, landing.custom_methods), then
    :data:`METHOD_LABELS`, then the name."""
    return (labels or {}).get(m) or METHOD_LABELS.get(m, m)


def _color(m, colors=None):
    """A method's colour: ``colors`` (a user's own method's), then the palette's."""
    return (colors or {}).get(m) or figures.color(m)


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
            figures.place_legend(ax)
        return fig


def fig_depth_error_map(dm: dict):
    """B-F5 from :func:`opnav.landing.depth_map.depth_map`: (a) the detected
    landmarks in the image coloured by depth error, the best one and the
    in-plane golden-section direction marked; (b) the whole field on the
    ground (no image constraint), its best landmark, the unconstrained in-plane
    optimum, the image footprint and the in-plane direction; (c) the in-plane
    depth error vs signed beta with the visible interval."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    uv_px, dr_m, best_idx, half_px = dm.uv_px, dm.dr_m, dm.best, dm.half_px
    with figures.style():
        fig, axs = plt.subplots(1, 3, figsize=(figures.PAGE_WIDTH_IN, 3.4), constrained_layout=True,
                                gridspec_kw={"width_ratios": [1.1, 1.1, 1]})
        fin = np.isfinite(dr_m)
        lo_c = float(min(np.nanmin(dr_m[fin]), dm.field_best_dr))
        norm = LogNorm(vmin=lo_c, vmax=float(np.nanpercentile(dr_m[fin], 99)))
        ax = axs[0]
        sc = ax.scatter(uv_px[fin, 0], uv_px[fin, 1], c=dr_m[fin], s=3, cmap="viridis", norm=norm,
                        rasterized=True)
        ax.plot(*uv_px[best_idx], marker="*", ms=12, mfc="red", mec="k", ls="none", zorder=5,
                clip_on=False, label=f"best detected ({dr_m[best_idx]:.0f} m)")
        opt_uv = dm.opt_uv_px
        if opt_uv is not None and np.all(np.isfinite(opt_uv)):
            ax.plot(*opt_uv, marker="+", ms=12, mew=2.0, color="red", ls="none", zorder=5,
                    clip_on=False, label=f"golden section ({dm.opt_dr:.0f} m)")
        ax.plot([-half_px, half_px, half_px, -half_px, -half_px],
                [-half_px, -half_px, half_px, half_px, -half_px], color="k", lw=0.6)
        ax.set_xlim(-1.06 * half_px, 1.06 * half_px)
        ax.set_ylim(1.06 * half_px, -1.06 * half_px)
        ax.set_aspect("equal")
        ax.set_xlabel("image u (px)")
        ax.set_ylabel("image v (px)")
        ax.set_title("(a) detected landmarks", fontsize="small")
        ax = axs[1]
        fx, fd = dm.field_xy, dm.field_dr
        ax.scatter(fx[:, 0] / 1e3, fx[:, 1] / 1e3, c=fd, s=1, cmap="viridis", norm=norm,
                   rasterized=True)
        fp = np.vstack([dm.footprint_xy, dm.footprint_xy[:1]]) / 1e3
        ax.plot(fp[:, 0], fp[:, 1], color="k", lw=0.8, label="image footprint")
        lx, ly = dm.lander_xy / 1e3
        ax.plot(lx, ly, marker="^", color="k", ls="none", ms=6, label="lander (nadir)")
        ax.plot(*(dm.field_best_xy / 1e3), marker="*", ms=12, mfc="orange", mec="k", ls="none",
                zorder=5, label=f"best in field ({dm.field_best_dr:.0f} m)")
        ug = dm.unconstrained_ground_xy / 1e3
        ax.plot(*ug, marker="x", ms=9, mew=2.0, color="orange", ls="none", zorder=5,
                label=f"unconstrained in-plane opt. ({dm.unconstrained_dr:.0f} m)")
        og = dm.opt_ground_xy
        if og is not None and np.all(np.isfinite(og)):
            ax.plot([lx, og[0] / 1e3], [ly, og[1] / 1e3], color="red", lw=1.0, ls="--",
                    label="golden-section direction")
        # the field's extent (a footprint corner near the horizon reaches far beyond it)
        lo_xy, hi_xy = fx.min(axis=0) / 1e3, fx.max(axis=0) / 1e3
        pad = 0.05 * float(np.max(hi_xy - lo_xy))
        ax.set_xlim(lo_xy[0] - pad, hi_xy[0] + pad)
        ax.set_ylim(lo_xy[1] - pad, hi_xy[1] + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("x (km)")
        ax.set_ylabel("y (km)")
        ax.set_title("(b) whole field, no image constraint", fontsize="small")
        cb = fig.colorbar(sc, ax=axs[:2], label="depth estimation error (m)", shrink=0.7,
                          location="bottom", pad=0.02)
        # a log range of less than a decade gets one major tick: five labelled ones instead
        ticks = np.geomspace(norm.vmin, norm.vmax, 5)
        cb.set_ticks(ticks, labels=[figures.plain_number(x) for x in ticks])
        cb.ax.minorticks_off()
        ax = axs[2]
        ax.semilogy(dm.beta_deg, dm.curve_dr, color="C0")
        figures.plain_log_labels(ax.yaxis)
        for lo, hi in dm.interval_deg:
            ax.axvspan(lo, hi, color="0.9", zorder=0)
        ax.axvline(dm.opt_beta_deg, color="red", ls="--", lw=0.8,
                   label=rf"golden section $\beta$ = {dm.opt_beta_deg:.1f}°")
        ax.axvline(dm.unconstrained_beta_deg, color="orange", ls=":", lw=1.0,
                   label=rf"unconstrained $\beta$ = {dm.unconstrained_beta_deg:.1f}°")
        ax.set_xlabel(r"signed $\beta$ (deg)")
        ax.set_ylabel("in-plane depth error (m)")
        ax.set_title("(c) velocity's plane (grey: visible)", fontsize="small")
        handles, labels = [], []   # one legend for the three panels, below them: clear of the data
        for a in axs:
            for h, lab in zip(*a.get_legend_handles_labels()):
                handles.append(h)
                labels.append(f"({'abc'[list(axs).index(a)]}) {lab}")
        fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize="x-small", frameon=False)
        return fig


def _phase_ends(t, data: dict) -> dict:
    """Median over the runs (of the first method that has them) of the time (s) of
    the last update with a landmark bearing and of the last vision update."""
    from opnav.landing.montecarlo import last_update_index

    for d in data.values():
        if d.lm_updated is not None:
            return {"last landmark update": float(np.median(t[last_update_index(d.lm_updated)])),
                    "last vision update": float(np.median(t[last_update_index(d.updated)]))}
    return {}


def fig_nav_error_envelopes(t, data: dict, labels: dict | None = None, colors: dict | None = None):
    """B-F6 / B-X1: error envelopes over the runs, per axis, of the position (m),
    velocity (m/s) and attitude (roll/pitch/yaw, deg) errors, one line per method
    (log scale): 3 x the RMS about zero over the runs, ``3 sqrt(mean_runs e^2)``,
    which keeps any bias (3 x the standard deviation about the mean would drop
    it). The phases are marked: the median time of the last landmark update
    (after it, site bearings only) and of the last vision update (after it, the
    IMU-only coast). The legend sits below the panels, clear of the curves. ``labels``,
    ``colors``: a user's own methods' legend names and colours (landing.custom_methods)."""
    import matplotlib.pyplot as plt

    rows = (("err_r", "position", "m", ("x", "y", "z")),
            ("err_v", "velocity", "m/s", ("x", "y", "z")),
            ("err_rpy_deg", "attitude", "deg", ("roll", "pitch", "yaw")))
    ends = _phase_ends(np.asarray(t, float), data)
    with figures.style():
        fig, axs = plt.subplots(3, 3, figsize=(figures.PAGE_WIDTH_IN, 6.6),
                                sharex=True, constrained_layout=True)
        for i, (key, name, unit, axes) in enumerate(rows):
            for j in range(3):
                ax = axs[i, j]
                for k, (m, d) in enumerate(data.items()):
                    e = getattr(d, key)[:, :, j]
                    env = 3.0 * np.sqrt(np.mean(e**2, axis=0))
                    ax.plot(t, env, color=_color(m, colors), lw=1.0, label=_label(m, labels),
                            ls=("-", "--", "-.", ":")[k % 4])
                ax.set_yscale("log")
                figures.plain_log_labels(ax.yaxis)
                for (lab, x), ls in zip(ends.items(), (":", "--")):
                    ax.axvline(x, color="0.4", lw=0.7, ls=ls, label=f"{lab} (median, {x:.0f} s)")
                if "last vision update" in ends:
                    ax.axvspan(ends["last vision update"], float(t[-1]), color="0.92", zorder=0)
                ax.set_title(f"{name} {axes[j]}", fontsize="medium")
                if j == 0:
                    ax.set_ylabel(f"$3\\times$ RMS error ({unit})")
                if i == 2:
                    ax.set_xlabel("time (s)")
        h, lab = axs[0, 0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", ncol=min(5, len(lab)), fontsize="x-small")
        fig.suptitle(r"$3\times$ RMS over the runs about zero (bias included); grey: IMU-only coast",
                     fontsize="small")
        return fig


def fig_planning_time(timing: "Replay", methods, published_reduction_vs_svd: float | None = None,
                      labels: dict | None = None, colors: dict | None = None):
    """B-F7: planning-call thread CPU time (us, ``timing_summary.CLOCK``) per method on the replayed planning
    calls (``timing``: ``opnav.landing.timing.replay``, the same calls for every
    method), box = quartiles, whiskers = 5th and 95th percentiles (the paper's
    Fig. 7 draws min/max; a replay's extremes are machine noise),
    medians and evaluations per call annotated. Methods timed on the
    alternative metric evaluation path too get a second, hatched box (on the
    calls timed there: the paper's definition on a subset, ``max_calls_paper``;
    its reduction in the title on the calls timed on both). A user's own method (``labels``,
    ``colors``: landing.custom_methods) has its planning path under its name."""
    import matplotlib
    import matplotlib.pyplot as plt

    from opnav.landing import timing_summary as tsum
    from opnav.report.landing.timing_text import less_time_text

    methods = list(methods)
    # the built-in methods' paths (a user's own method names its own: methods.eval_path)
    paths = {str(p): str(e) for p, e in zip(timing.variant_path, timing.variant_eval_path)
             if not str(e).startswith("custom")}
    own = {str(m): str(e) for m, e in zip(timing.variant_method, timing.variant_eval_path)
           if str(e).startswith("custom")}
    main_name, alt_name = paths.get("main", ""), paths.get("alt", "")
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 3.0), constrained_layout=True)
        pos, vals, cols, hatch = [], [], [], []
        for k, m in enumerate(methods, start=1):
            v = tsum.times_ns(timing, m).astype(float) / 1e3
            va = tsum.times_ns(timing, m, "alt").astype(float) / 1e3
            has_alt = va.size > 0
            pos.append(k - 0.18 if has_alt else k)
            vals.append(v)
            cols.append(_color(m, colors))
            hatch.append("")
            if has_alt:
                pos.append(k + 0.18)
                vals.append(va)
                cols.append(_color(m, colors))
                hatch.append("///")
        # whiskers at the 5th and 95th percentiles: the extremes of a replay are
        # machine noise (a shared machine's 10-130 ms interruptions), not planning work
        bp = ax.boxplot(vals, positions=pos, whis=(5, 95), showfliers=False, patch_artist=True,
                        widths=0.32)
        for patch, c, h in zip(bp["boxes"], cols, hatch):   # the other path: hollow, hatched
            patch.set_facecolor(matplotlib.colors.to_rgba(c, 0.5) if not h else "white")
            patch.set_edgecolor(c if h else "k")
            patch.set_hatch(h)
        ax.set_yscale("log")
        figures.plain_log_labels(ax.yaxis)
        ticks = []
        for m in methods:
            ev = tsum.median_evals(timing, m)
            interp = m in own and "interpreted search" in own[m]     # a plain Python metric of the user's
            name = _label(m, labels) if m not in own else _label(m, labels).replace(" ", "\n")   # own: narrow
            ticks.append(f"{name}\n{ev:.0f} evals" + ("\n(interpreted\nsearch)" if interp else ""))
        ax.set_xticks(range(1, len(methods) + 1), ticks, fontsize="small")
        for p_, v in zip(pos, vals):       # the median, above the upper whisker (clear of the box)
            if len(v):
                med = float(np.median(v))
                ax.annotate(f"{med:.1f}" if med < 100 else f"{med:.0f}", (p_, float(np.percentile(v, 95))),
                            xytext=(0, 2), textcoords="offset points", ha="center", va="bottom",
                            fontsize="xx-small")
        ax.set_ylim(top=ax.get_ylim()[1] * 2.0)   # room for the labels of the tallest boxes
        if any(hatch):                            # which box is which path, where no box is
            from matplotlib.patches import Patch
            figures.place_legend(ax, handles=[Patch(facecolor=(0.5, 0.5, 0.5, 0.5), edgecolor="k", label=main_name),
                                              Patch(facecolor="white", edgecolor="0.3", hatch="///", label=alt_name)],
                                 fontsize="x-small", framealpha=0.9)
        ax.set_ylabel("planning-call time (µs, thread CPU)")
        n_alt = max((tsum.timed_calls(timing, m, "alt") for m in methods), default=0)
        nr = tsum.n_replays(timing)
        ax.set_xlabel(f"replay of {tsum.replay_calls(timing)} recorded calls"
                      + (f" ({nr} replays pooled)" if nr > 1 else "") + "; box: quartiles,\n"
                      f"whiskers: 5-95 %; filled: {main_name}"
                      + (f"; hatched: {alt_name} ({n_alt} of the calls)" if alt_name and n_alt else ""),
                      fontsize="x-small")
        if published_reduction_vs_svd is not None and {"depth", "svd"} <= set(methods):
            ours = tsum.time_reduction(timing, "depth", "svd", n_boot=0)[0]
            title = f"depth vs SVD: {less_time_text(ours)} time ({main_name})"
            if tsum.times_ns(timing, "svd", "alt").size:
                da = "alt" if tsum.times_ns(timing, "depth", "alt").size else "main"   # both on that path
                ours_alt = tsum.time_reduction(timing, "depth", "svd", path_a=da, path_b="alt", n_boot=0)[0]
                title += f", {less_time_text(ours_alt)} ({alt_name})"
            ax.set_title(f"{title}\npublished {published_reduction_vs_svd:.2f} % less", fontsize="x-small")
        return fig
