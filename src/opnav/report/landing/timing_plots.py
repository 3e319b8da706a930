"""B-F7's overhead curve: how a planning call's shared part sets the time reduction a timing
claim reads (issue 53). Drawn from the planning-time evidence
(``timing_summary.planning_time_evidence``), never from a replay directly; no numbers are
computed here beyond placing them.
"""

from __future__ import annotations

import math

from typing import TYPE_CHECKING

from opnav.core import figures

if TYPE_CHECKING:
    from opnav.landing.timing_summary import PlanningTimeEvidence


def fig_overhead_curve(ev: "PlanningTimeEvidence", camera: str = ""):
    """Depth's planning-time reduction against SVD (%) as a function of the part of a compiled
    call both share (us: dispatch, argument unpacking, the search's own steps), each method's
    evaluations held at their measured cost (``ev.overhead_curve``); each independent replay's
    reading at its own measured shared part (points), the published reduction (dashed) and the
    shared part at which it would hold (``shared_us_at_published``, dotted; absent if none would)."""
    import matplotlib.pyplot as plt

    c = ev.overhead_curve
    pub = float(ev.published_pct)
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 2.6), constrained_layout=True)
        if c.shared_us:
            ax.plot(c.shared_us, c.reduction_pct, color=figures.color(c.a),
                    label="shared part varied")
            ax.plot(c.replay_shared_us, c.replay_reduction_pct, "o", color=figures.color(c.b),
                    markersize=4, label=f"{len(c.replay_shared_us)} replays")
        ax.axhline(pub, **{**figures.PUBLISHED_STYLE, "marker": None, "linestyle": "--",
                           "label": "published"})
        s = ev.shared_us_at_published
        if s is not None and math.isfinite(s):
            ax.axvline(s, color="0.35", linestyle=":", label=f"published at {s:.2f} µs")
        ax.set_xlabel("shared part of a call (µs, thread CPU)")
        ax.set_ylabel(f"{c.a} vs {c.b}: time reduction (%)")
        if camera:
            ax.set_title(f"{camera} camera, {ev.eval_path or ev.path} path; published {pub:.2f} %",
                         fontsize="x-small")
        figures.place_legend(ax, fontsize="xx-small", framealpha=0.9)
        return fig
