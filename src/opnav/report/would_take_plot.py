"""What a claim would take, as a figure: the swept quantity against the swept choice.

One figure per claim whose plan entry sweeps a choice (``would_take: sweep``; A-C1 and A-C4:
the roll rate, A-C7: the arc length, B-C2: the convergence threshold, B-C4: the per-call
overhead shared by both methods): each swept method and scope as a line (with its interval
where the evidence has one), the test's boundary as a dashed line, and the value where the
verdict flips marked. Plotting only: the points, the boundary and the flip are the scorer's
(:func:`opnav.report.scorer.would_take`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opnav.core import figures
from opnav.report import approach_claims, landing_claims  # noqa: F401  (their quantities' names)

if TYPE_CHECKING:
    from opnav.report.scorer import Sweep


_UNITS = (("_deg_s", "deg/s"), ("_arcsec", "arcsec"), ("_km", "km"), ("_us", "us"), ("_m", "m"), ("_s", "s"))


def setting_label(name: str) -> str:
    """'roll_rate_deg_s' -> 'roll rate (deg/s)', 'arc_s' -> 'arc (s)'."""
    for suf, unit in _UNITS:
        if name.endswith(suf):
            return f"{name[: -len(suf)].replace('_', ' ')} ({unit})"
    return name.replace("_", " ")


def plot(claim_id: str, sweeps: "Iterable[Sweep]", path: str | Path, names: Mapping[str, str] | None = None):
    """Save the would_take figure of ``claim_id`` (``sweeps``: the scorer's sweeps of that
    claim) to ``path`` (a stem: PDF and PNG); a claim without sweep evidence in this build gets
    a figure that says so."""
    import matplotlib.pyplot as plt

    names = dict(names or {})
    sw = [s for s in sweeps if s.claim_id == claim_id]
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH_IN, 2.4))
        if not sw:
            ax.text(0.5, 0.5, f"{claim_id}: no swept evidence in this build", ha="center", va="center",
                    transform=ax.transAxes)
            ax.set_axis_off()
            return figures.save(fig, path)
        s0 = sw[0]
        styles, markers = ["-", "--", ":", "-."], ["o", "s", "^", "D"]   # per scope (camera, case)
        scopes = list(dict.fromkeys(s.scope for s in sw))
        for s in sw:
            xs = [p[0] for p in s.points]
            ys = [p[1] for p in s.points]
            lab = names.get(s.method, s.method) + (f", {s.scope}" if len(sw) > 1 and s.scope else "")
            c = figures.color(s.method.split("+")[0])
            k = scopes.index(s.scope)
            ax.plot(xs, ys, marker=markers[k % len(markers)], ms=3, color=c, label=lab, ls=styles[k % len(styles)])
            lo = [p[2] for p in s.points]
            hi = [p[3] for p in s.points]
            if all(math.isfinite(v) for v in lo + hi):
                ax.fill_between(xs, lo, hi, color=c, alpha=0.2, lw=0)
            if s.flip is not None:
                ax.axvline(s.flip, color=c, ls=":", lw=1)
        lim = s0.limit
        band = [x for x in s0.band or () if math.isfinite(x)]
        if len(band) == 2:
            ax.axhspan(band[0], band[1], color="0.85", zorder=0, label=f"test: {s0.threshold}")
        elif lim is not None and math.isfinite(lim):
            ax.axhline(lim, color="0.3", ls="--", lw=1, label=f"test: {s0.threshold}")
        tgt = s0.target
        if tgt is not None and math.isfinite(tgt):
            ax.axhline(tgt, color="0.3", ls="--", lw=1, label=f"published {tgt:g}")
        from opnav.report.evidence import QUANTITIES

        unit = s0.unit
        q = QUANTITIES.get(s0.quantity)
        ax.set_xlabel(setting_label(s0.setting))
        import textwrap

        ylab = q.text if q is not None else s0.quantity.replace("_", " ")
        if s0.versus and "diff" in s0.quantity:   # a paired difference: say which minus which
            ylab += f", {names.get(s0.method, s0.method)} minus {names.get(s0.versus, s0.versus)}"
        ylab += f" ({unit})" if unit else ""
        ax.set_ylabel("\n".join(textwrap.wrap(ylab, 28)))
        xs_all = [p[0] for s in sw for p in s.points]
        ys_all = [p[1] for s in sw for p in s.points] + ([lim] if lim is not None and math.isfinite(lim) else [])
        if xs_all and min(xs_all) > 0 and max(xs_all) / min(xs_all) > 8:
            ax.set_xscale("log")
            figures.plain_log_labels(ax.xaxis)
            swept = sorted(set(xs_all))
            if len(swept) <= 8:   # few swept values: a tick at each, so the ends are labelled too
                from matplotlib.ticker import NullLocator

                ax.set_xticks(swept, [f"{x:,.4g}" for x in swept])
                ax.xaxis.set_minor_locator(NullLocator())
            if ys_all and min(ys_all) > 0 and max(ys_all) / min(ys_all) > 8:
                ax.set_yscale("log")     # a power law is a line, as the flip is interpolated
                figures.plain_log_labels(ax.yaxis)
        ax.set_title(f"{claim_id}: what it would take", fontsize="small")
        figures.place_legend(ax, fontsize="x-small")
        return figures.save(fig, path)


def caption(claim_id: str, sweeps: "Iterable[Sweep]", row: Mapping[str, Any] | None = None,
            names: Mapping[str, str] | None = None) -> str:
    """The figure's caption (plain text, every sentence short): which claim, what is drawn
    against what, how the test and the flip are marked, and what the claims table says it
    would take (``row``: the claim's row of the claims table)."""
    from opnav.core import wording
    from opnav.report.evidence import QUANTITIES

    names = dict(names or {})
    row = dict(row or {})
    title = str(row.get("claim", "")).split(" (")[0].strip()
    out = [f"{claim_id}" + (f", {title[0].lower() + title[1:]}" if title else "") + ": what it would take."]
    sw = [s for s in sweeps if s.claim_id == claim_id]
    if not sw:
        return " ".join(out + [f"This build has no swept evidence for {claim_id}."])
    s0 = sw[0]
    q = QUANTITIES.get(s0.quantity)
    what = q.text if q is not None else s0.quantity.replace("_", " ")
    if s0.versus:
        how = "minus" if "diff" in s0.quantity else "against"
        what += f" of {names.get(s0.method, s0.method)} {how} {names.get(s0.versus, s0.versus)}"
    lines = wording.join([names.get(s.method, s.method) + (f" ({s.scope})" if s.scope else "") for s in sw])
    out.append(f"The {what} against the {setting_label(s0.setting)}, for {lines}.")
    marks = []
    if len([x for x in s0.band or () if math.isfinite(x)]) == 2:
        marks.append(f"the grey band is the test ({s0.threshold})")
    elif s0.limit is not None and math.isfinite(s0.limit):
        marks.append(f"the dashed line is the test ({s0.threshold})")
    if s0.target is not None and math.isfinite(s0.target):
        marks.append(f"the dashed line marks the published {wording.num(s0.target)}")
    if any(s.flip is not None for s in sw):
        marks.append("a dotted line marks where the verdict flips")
    if marks:
        out.append(wording.join(marks).capitalize() + ".")
    take = str(row.get("would_take", "")).strip()
    if take:
        take = "; ".join(dict.fromkeys(t.strip() for t in take.split("; ")))
        out.append("The claims table reads: " + wording.shorten(take, wording.MAX_SENTENCE_WORDS - 4) + ".")
    return " ".join(out)


def latex(claim_ids: Iterable[str], sweeps: "Iterable[Sweep]", rows: Mapping[str, Mapping[str, Any]],
          directory: str = r"\results/paper/would_take", names: Mapping[str, str] | None = None) -> str:
    """The manuscript's would_take figures (an appendix block of figure floats, one per swept
    claim, each with its :func:`caption`); ``directory``: where LaTeX finds ``<claim>.pdf``."""
    from opnav.report.manuscript import prose_tex

    sweeps = list(sweeps)
    blocks = []
    for cid in claim_ids:
        cap = prose_tex(caption(cid, sweeps, rows.get(cid), names))
        blocks.append("\\begin{figure}[htbp]\n  \\centering\n"
                      f"  \\includegraphics{{{directory}/{cid}.pdf}}\n"
                      f"  \\caption[{cid}: what it would take]{{{cap}}}\n"
                      f"  \\label{{fig:would-take-{cid}}}\n\\end{{figure}}\n")
    return "\n".join(blocks)
