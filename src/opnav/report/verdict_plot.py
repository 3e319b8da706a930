"""The verdict figure of page 1: one row per claim of either paper, the published value
beside ours (as written, best faithful variant) and the verdict as a coloured cell (and
the replication sample's verdict, where the claims table has one).

Plotting only: every text comes from the claims table (``results/paper/claims.csv``).
"""

from __future__ import annotations

import textwrap

from opnav.core import figures

#: verdict -> (cell colour, text colour); colour-blind-safe (Okabe-Ito) and distinct in grey
VERDICT_COLORS = {
    "reproduced": ("#009E73", "white"),
    "reproduced_with_addition": ("#8FD3BE", "black"),
    "not_reproduced": ("#D55E00", "white"),
    "not_reproducible": ("#7A1F3D", "white"),
    "depends_on_choice": ("#E69F00", "black"),
    "not_tested": ("#BBBBBB", "black"),
    "unstable": ("#F0E442", "black"),
    "suspect": ("#000000", "white"),
}
VERDICT_WORDS = {
    "reproduced": "reproduced", "reproduced_with_addition": "with an addition",
    "not_reproduced": "not reproduced", "not_reproducible": "not reproducible",
    "depends_on_choice": "depends on a choice", "not_tested": "not tested", "unstable": "unstable",
    "suspect": "suspect",
}


def _cell(text: object, width: int, lines: int = 2) -> str:
    """``text`` wrapped to ``width`` characters, at most ``lines`` lines (an ellipsis marks a cut)."""
    s = " ".join(str(text if text is not None else "").split())
    if s in ("nan", "None"):
        s = ""
    w = textwrap.wrap(s, width) or [""]
    if len(w) > lines:
        w = w[:lines]
        w[-1] = w[-1][: max(0, width - 1)].rstrip() + "…"
    return "\n".join(w)


def short_claim(claim: str) -> str:
    """The claim up to its first parenthesis (where the table's claim names its source)."""
    return str(claim).split(" (")[0].strip()


def fig_verdicts(df):
    """One row per claim: id, claim, published, ours as written, ours best (variant), verdict
    (coloured) and, where present, the replication's verdict. Missing columns are left out."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    cols = [("claim_id", "id", 0.06, 8), ("claim", "claim", 0.27, 40), ("published", "published", 0.16, 22),
            ("ours_as_written", "ours, as written", 0.18, 26), ("ours_best", "ours, best variant", 0.18, 26)]
    cols = [c for c in cols if c[0] in df.columns]
    verdict_cols = [c for c in ("verdict", "verdict_replication") if c in df.columns
                    and df[c].astype(str).str.strip().replace("nan", "").ne("").any()]
    vw = 0.13
    total = sum(c[2] for c in cols) + vw * len(verdict_cols)
    scale = 1.0 / total
    n = len(df)
    row_h = 0.26  # inches
    with figures.style():
        fig = plt.figure(figsize=(figures.PAGE_WIDTH_IN, row_h * (n + 1.6)))
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(0, 1)
        ax.set_ylim(n + 1.6, 0)
        ax.axis("off")
        x = 0.0
        heads = [(c[1], c[2] * scale) for c in cols] + \
                [("verdict" if v == "verdict" else "replication", vw * scale) for v in verdict_cols]
        for name, w in heads:
            ax.text(x + 0.005, 0.5, name, ha="left", va="center", fontsize=7, fontweight="bold")
            x += w
        ax.axhline(1.0, color="k", lw=0.6)
        prev_paper = None
        for i, r in enumerate(df.itertuples(index=False)):
            y = i + 1.0
            rd = r._asdict()
            if prev_paper is not None and rd.get("paper") != prev_paper:
                ax.axhline(y, color="k", lw=0.4)
            prev_paper = rd.get("paper")
            x = 0.0
            for key, _, w, chars in cols:
                text = rd.get(key, "")
                if key == "claim":
                    text = short_claim(text)
                if key == "ours_best" and rd.get("best_variant") not in (None, "", "nan") and str(text) not in ("", "nan"):
                    text = f"{text} ({rd['best_variant']})"
                ax.text(x + 0.005, y + 0.5, _cell(text, chars), ha="left", va="center", fontsize=5.6,
                        linespacing=1.0)
                x += w * scale
            for v in verdict_cols:
                val = str(rd.get(v, "") or "")
                face, ink = VERDICT_COLORS.get(val, ("white", "black"))
                ax.add_patch(Rectangle((x + 0.003, y + 0.08), vw * scale - 0.006, 0.84, facecolor=face,
                                       edgecolor="0.3", lw=0.3))
                ax.text(x + vw * scale / 2, y + 0.5, VERDICT_WORDS.get(val, val.replace("_", " ")),
                        ha="center", va="center", fontsize=5.6, color=ink)
                x += vw * scale
        ax.axhline(n + 1.0, color="k", lw=0.6)
        flags = [f"{r.claim_id}: {r.flags}" for r in df.itertuples()
                 if "flags" in df.columns and str(getattr(r, "flags", "") or "").strip() not in ("", "nan")]
        note = "flags: " + "; ".join(flags) if flags else ""
        if note:
            ax.text(0.005, n + 1.3, _cell(note, 170, 1), ha="left", va="center", fontsize=5.2, color="0.3")
    return fig
