"""A-X6 figure: the stars study (beyond the paper) against attitude knowledge and magnitude limit.

Plotting only (numbers from :func:`opnav.approach.summaries.stars_frame`).
"""

from __future__ import annotations

import numpy as np

from opnav.core import figures


def stars_figure(frame, target_arcsec: float):
    """Left: the 1-sigma bound of tx (all data, and the star images alone), the floor
    ``hypot(sigma_a / sqrt(images), drift)`` and the RMS error of the EM-EKF (growing windows,
    SQUAREM) against the per-image attitude knowledge; right: the same against the magnitude
    limit, with the stars per image (median along the arc) on a second axis. Dashed: the
    claimed accuracy."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 2.8), layout="constrained")
        for ax, sweep, xlabel in ((axes[0], "attitude_sigma_arcsec", "attitude knowledge per star image, 1-sigma (arcsec)"),
                                  (axes[1], "mag_limit", "magnitude limit")):
            d = frame[frame["sweep"] == sweep].sort_values("value")
            if not len(d):
                ax.set_visible(False)
                continue
            x = d["value"].to_numpy(float)
            ax.plot(x, d["crlb_x_arcsec"], "o-", color="k", lw=1.0, ms=3, label="bound, all data")
            ax.plot(x, d["crlb_stars_only_x_arcsec"], "s--", color="0.5", lw=0.8, ms=3, label="bound, stars alone")
            ax.plot(x, d["floor_arcsec"], ":", color="C1", lw=1.0, label="attitude floor")
            ax.plot(x, d["em_rmse_xy_arcsec"], "^", color=figures.color("growing-squarem"), ms=4,
                    label="EM-EKF (growing, SQUAREM) RMS")
            ax.axhline(target_arcsec, color="C3", lw=0.8, ls="--", label=f"claimed {target_arcsec:g} arcsec")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("arcsec")
            if sweep == "mag_limit":
                ax2 = ax.twinx()
                ax2.step(x, d["stars_per_image_median"], where="mid", color="C0", lw=0.8)
                ax2.set_ylabel("stars per image", color="C0")
                ax2.set_ylim(0, max(1.0, float(np.nanmax(d["stars_per_image_median"]))) * 1.3)
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=3, frameon=False, fontsize="small")
    return fig
