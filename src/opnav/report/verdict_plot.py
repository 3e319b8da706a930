"""The verdict figure of page 1: a grid of the claims of both papers (rows, by paper) by
verdict (columns), a dot for the main sample's verdict and a diamond for the
replication sample's, with a count per paper and verdict. The published values and ours are Table 1's.

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


def short_claim(claim: str) -> str:
    """The claim up to its first parenthesis (where the table's claim names its source)."""
    return str(claim).split(" (")[0].strip()


def _verdict_order(df) -> list[str]:
    """The verdicts the table uses (main or replication), in the claims engine's order."""
    try:
        from opnav.report.claims import VERDICTS
    except ImportError:  # pragma: no cover - an older claims module
        VERDICTS = list(VERDICT_COLORS)
    used = [str(v) for c in ("verdict", "verdict_replication") if c in df.columns for v in df[c]]
    used = [v for v in dict.fromkeys(used) if v.strip() and v != "nan"]
    return [v for v in VERDICTS if v in used] + [v for v in used if v not in VERDICTS]


def verdict_word(code: str) -> str:
    """A verdict as the PDF says it in short (the claims engine's words where it has them)."""
    try:
        from opnav.report.claims import VERDICT_SHORT
    except ImportError:  # pragma: no cover
        VERDICT_SHORT = {}
    return VERDICT_SHORT.get(code, VERDICT_WORDS.get(code, str(code).replace("_", " ")))


def _present(x) -> bool:
    return str(x if x is not None else "").strip() not in ("", "nan", "None")


#: figure layout, inches and points: the text width of the manuscript's page (A4, 2 cm margins),
#: so the figure prints at its own size; the fonts; a column's padding either side of its text
FIG_WIDTH_IN = 6.7
LABEL_PT = 7.0
HEAD_PT = 6.5
PAD_IN = 0.025
LINE_IN = 0.118       # one text line of a row at LABEL_PT (leading 1.2)
ROW_PAD_IN = 0.036
#: the claim column is never narrower than this (the verdict columns' heads give way first)
MIN_LABEL_IN = 2.4
#: a verdict column is never narrower than this (a dot and a diamond side by side)
MIN_COL_IN = 0.42
#: the mark of each sample's verdict: a dot for the main sample, a diamond for the replication
MARKERS = {"verdict": {"marker": "o", "ms": 6.5}, "verdict_replication": {"marker": "D", "ms": 5.5}}


def _width_in(text: str, pt: float, weight: str = "normal") -> float:
    """The printed width of one line of ``text`` at ``pt`` in the current style's font, inches."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    prop = FontProperties(size=pt, weight=weight)
    return TextToPath().get_text_width_height_descent(text, prop, ismath=False)[0] / 72.0


def wrap_to_width(text: str, width_in: float, pt: float) -> list[str]:
    """``text`` wrapped onto lines no wider than ``width_in`` at ``pt`` (measured, not counted);
    a word wider than the line keeps a line of its own: nothing is cut."""
    lines: list[str] = []
    for word in str(text).split():
        if lines and _width_in(f"{lines[-1]} {word}", pt) <= width_in:
            lines[-1] += f" {word}"
        else:
            lines.append(word)
    return lines or [""]


def fig_verdicts(df):
    """The verdicts at a glance: a grid of claims (rows, by paper) by verdict (columns, in the
    verdict's colour), a dot for the main sample's verdict and a diamond for the
    replication sample's where it was flown; a count per paper and verdict closes each block.
    The claims carry their id and short name only (wrapped, never cut): the published values
    and ours are Table 1's (Section 1)."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    verdicts = _verdict_order(df)
    has_rep = "verdict_replication" in df.columns and df["verdict_replication"].map(_present).any()
    width = FIG_WIDTH_IN
    with figures.style():
        # each verdict column as wide as its own head (the verdict's words on at most two
        # lines; wide enough for the two marks), the claim column the rest
        head_pt = HEAD_PT
        heads = [textwrap.wrap(verdict_word(v), 11, break_long_words=False) or [""] for v in verdicts]
        while True:
            col_ws = [max(max(_width_in(line, head_pt) for line in h) + 2 * PAD_IN + 0.04, MIN_COL_IN) for h in heads]
            if width - sum(col_ws) >= MIN_LABEL_IN or head_pt <= 5.0:
                break
            head_pt -= 0.25
        label_w = width - sum(col_ws)
        col_x = [label_w + sum(col_ws[:j]) for j in range(len(col_ws))]  # each column's left edge
        col_c = [x + w / 2 for x, w in zip(col_x, col_ws)]               # and its centre
        ids = [str(r.get("claim_id", "")) for r in df.to_dict("records")]
        id_w = max([_width_in(i, LABEL_PT, "bold") for i in ids] + [0.0]) + 3 * PAD_IN
        rows = []  # (kind, paper, record or block, claim name lines)
        papers = list(dict.fromkeys(df["paper"])) if "paper" in df.columns else [None]
        for paper in papers:
            sub = df[df["paper"] == paper] if paper is not None else df
            for r in sub.to_dict("records"):
                name = short_claim(r.get("claim", ""))
                rows.append(("claim", paper, r, wrap_to_width(name, label_w - id_w - PAD_IN, LABEL_PT)))
            rows.append(("count", paper, sub, [""]))
        heights = [len(lines) * LINE_IN + ROW_PAD_IN for _, _, _, lines in rows]
        head_h = max(2, *(len(h) for h in heads)) * 0.105 + 0.1
        total_h = head_h + sum(heights) + 0.02
        fig = plt.figure(figsize=(width, total_h))
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(0, width)
        ax.set_ylim(total_h, 0)
        ax.axis("off")
        # column heads: the verdict's words on its colour
        for j, (v, head) in enumerate(zip(verdicts, heads)):
            face, ink = VERDICT_COLORS.get(v, ("white", "black"))
            ax.add_patch(Rectangle((col_x[j] + 0.012, 0.02), col_ws[j] - 0.024, head_h - 0.06, facecolor=face,
                                   edgecolor="0.3", lw=0.3))
            ax.text(col_c[j], head_h / 2 - 0.01, "\n".join(head),
                    ha="center", va="center", fontsize=head_pt, color=ink, linespacing=1.0)
        # the claim column's head, and the key under it: which mark is which sample
        ax.text(PAD_IN, head_h * 0.3, "claim", ha="left", va="center", fontsize=LABEL_PT, fontweight="bold")
        ky, kx = head_h * 0.72, PAD_IN + 0.05
        for key, words in (("verdict", "main sample"), ("verdict_replication", "replication sample")):
            if key == "verdict_replication" and not has_rep:
                continue
            ax.plot([kx], [ky], ls="none", mfc="0.6", mec="0.15", mew=0.6, **MARKERS[key])
            ax.text(kx + 0.08, ky, words, ha="left", va="center", fontsize=HEAD_PT)
            kx += 0.08 + _width_in(words, HEAD_PT) + 0.2
        y = head_h
        for (kind, paper, r, lines), h in zip(rows, heights):
            if kind == "claim":
                ax.text(PAD_IN, y + h / 2, str(r.get("claim_id", "")), ha="left", va="center", fontsize=LABEL_PT,
                        fontweight="bold")
                ax.text(id_w, y + h / 2, "\n".join(lines), ha="left", va="center", fontsize=LABEL_PT,
                        linespacing=1.05)
                ax.plot([0, width], [y + h, y + h], color="0.85", lw=0.3)
                for key, dx in (("verdict", -0.09 if has_rep else 0.0), ("verdict_replication", 0.09)):
                    v = str(r.get(key, "") or "")
                    if v in verdicts:
                        cx = col_c[verdicts.index(v)] + dx
                        face = VERDICT_COLORS.get(v, ("0.5", "black"))[0]
                        ax.plot([cx], [y + h / 2], ls="none", mfc=face, mec="0.15", mew=0.6, **MARKERS[key])
            else:
                counts = r["verdict"].value_counts() if "verdict" in r.columns else {}
                ax.text(PAD_IN, y + h / 2, f"paper {paper}: claims per verdict (main sample)" if paper else "claims per verdict (main sample)",
                        ha="left", va="center", fontsize=LABEL_PT - 0.5, style="italic", color="0.25")
                for j, v in enumerate(verdicts):
                    n = int(counts.get(v, 0))
                    ax.text(col_c[j], y + h / 2, str(n) if n else "", ha="center", va="center",
                            fontsize=LABEL_PT, fontweight="bold")
                ax.plot([0, width], [y + h, y + h], color="k", lw=0.6)
            y += h
        ax.plot([0, width], [head_h, head_h], color="k", lw=0.6)
    return fig
