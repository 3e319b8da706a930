"""A-X6 figure: the stars study (beyond the paper) against attitude knowledge and stars per image.

Plotting only (numbers from :func:`opnav.approach.summaries.stars_frame`).
"""

from __future__ import annotations

import numpy as np

from opnav.core import figures

from .plots import _plain_log_ticks


def stars_figure(frame, target_arcsec: float):
    """Left: the 1-sigma bound of tx (all data, and the star images alone), the floor
    ``hypot(sigma_a / sqrt(images), drift)`` and the RMS error of the EM-EKF (growing windows,
    SQUAREM) against the per-image attitude knowledge; right: the same against the stars in
    every image (each count made real by its magnitude limit and field, annotated). Dashed: the
    claimed accuracy."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 2.8), layout="constrained")
        for ax, sweep, xlabel in ((axes[0], "attitude_sigma_arcsec", "attitude knowledge per star image, 1-sigma (arcsec)"),
                                  (axes[1], "per_image", "stars in every image")):
            d = frame[frame["sweep"] == sweep].sort_values("value")
            if not len(d):
                ax.set_visible(False)
                continue
            x = (d["stars_per_image_median"] if sweep == "per_image" else d["value"]).to_numpy(float)
            # the star images alone can leave a direction unobserved (one star per image): such a
            # bound is drawn at the top edge, marked off scale
            top = 5.0 * float(np.nanmax([d["crlb_x_arcsec"].max(), d["em_rmse_xy_arcsec"].max(),
                                         d["floor_arcsec"].max(), target_arcsec]))
            alone = d["crlb_stars_only_x_arcsec"].to_numpy(float)
            ax.plot(x, d["crlb_x_arcsec"], "o-", color="k", lw=1.0, ms=3, label="bound, all data")
            ax.plot(x, np.minimum(alone, top), "s--", color="0.5", lw=0.8, ms=3, label="bound, stars alone")
            for xi in x[alone > top]:
                ax.annotate("stars alone:\noff scale", (xi, top), textcoords="offset points", xytext=(4, -14),
                            fontsize="x-small", color="0.4")
            ax.plot(x, d["floor_arcsec"], ":", color="C1", lw=1.0, label="attitude floor")
            ax.plot(x, d["em_rmse_xy_arcsec"], "^", color=figures.color("growing-squarem"), ms=4,
                    label="EM-EKF (growing, SQUAREM) RMS")
            ax.axhline(target_arcsec, color="C3", lw=0.8, ls="--", label=f"claimed {target_arcsec:g} arcsec")
            ax.set_yscale("log")
            ax.set_ylim(top=top * 1.05)
            _plain_log_ticks(ax)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("arcsec")
            if sweep == "per_image":
                ax.set_xscale("log")
                ax.set_xlim(x.min() / 1.6, x.max() * 1.6)
                _plain_log_ticks(ax, "both")
                for xi, (_, r) in zip(x, d.iterrows()):
                    ax.annotate(f"mag {r['mag_limit']:.3g}\n{r['field_deg']:.2g} deg", (xi, r["crlb_x_arcsec"]),
                                textcoords="offset points", xytext=(0, 6), ha="center", fontsize="x-small")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=3, frameon=False, fontsize="small")
    return fig
