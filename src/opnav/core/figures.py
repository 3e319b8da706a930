"""The shared figure style, the one colour palette, and deterministic figure saving.

Every plot of the pipeline is drawn by a plots module (:mod:`opnav.report.approach.plots`,
:mod:`opnav.report.approach.peer_plots`, :mod:`opnav.report.landing.plots`,
:mod:`opnav.report.study_plots`) under :func:`style` (one matplotlib style file,
``opnav.mplstyle``, sized for a journal column), coloured by :func:`color` (one
colour per method and per scenario variant, the same in every figure of both
papers: :data:`PALETTE`), and written by :func:`save`, which produces PDF and PNG
without creation dates or software stamps, so the same data give byte-identical
files. ``workflow/scripts`` only call these functions; estimators and simulations
never import a plots module or this one.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Iterable, Iterator

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import zlib  # noqa: E402

import numpy as np  # noqa: E402

from opnav.core.tables import atomic_target  # noqa: E402

STYLE = Path(__file__).resolve().parents[1] / "opnav.mplstyle"

#: Column and full-page widths (inches) for the manuscript.
COLUMN_WIDTH_IN = 3.5
PAGE_WIDTH_IN = 7.0

#: Colour/marker used everywhere for the papers' published values.
PUBLISHED_STYLE = dict(color="0.35", marker="x", linestyle="none", label="published")

#: The one palette: every method and scenario variant of both papers -> its colour, used
#: by every figure (a figure that shows variants and estimators together colours one
#: and draws the other with line styles). Paper A's variants and estimators, and paper
#: B's planning methods, have distinct colours within their paper.
PALETTE: dict[str, str] = {
    # paper A: scenario variants (approach.variants)
    "literal": "C0", "prior": "C1", "roll": "C2", "reference-start": "C3",
    # paper A: estimators (EM schemes, growing windows, A-X2 alternatives, study names)
    "plain": "#0072B2", "squarem": "#56B4E9", "em": "#332288",
    "growing-plain": "#8C510A", "growing-squarem": "#E69F00",
    "augmented": "#D55E00", "batch_ml": "#009E73",
    # paper B: planning methods (landing.mc.methods, landing.extra.methods)
    "depth": "C0", "svd": "C1", "gdop": "C2", "cond": "C3", "logdet": "C4", "mineig": "C5",
    "random": "C6", "center": "C7", "svd_w": "C8", "gdop_w": "C9", "cond_w": "k",
    "closest": "#B8860B", "logdet_nav": "#6A3D9A", "svd_lapack": "#D95F02",  # svd_lapack: SVD's darker shade
}
#: Other spellings of the same method (table labels, study estimator names).
ALIASES: dict[str, str] = {
    "em_plain": "plain", "em_squarem": "squarem", "em_growing_squarem": "growing-squarem", "EM-EKF (plain)": "plain",
    "EM-EKF (SQUAREM)": "squarem", "augmented EKF": "augmented", "batch ML (IPOPT)": "batch_ml",
    "em_growing_plain": "growing-plain", "EM-EKF (growing windows, plain)": "growing-plain",
    "EM-EKF (growing windows, SQUAREM)": "growing-squarem",
}


def color(label: str) -> str:
    """The colour of a method or scenario variant (:data:`PALETTE`, through
    :data:`ALIASES`); a label outside the palette (a new planning method) gets a
    colour from its name alone, so it too is the same in every figure."""
    key = ALIASES.get(label, label)
    if key in PALETTE:
        return PALETTE[key]
    return f"C{zlib.crc32(key.encode()) % 10}"


#: colours for a user's own method without one (landing.custom_methods, approach.custom_estimators):
#: none of them in :data:`PALETTE`, so an own method never takes a built-in method's colour
OWN_COLORS = ("#117733", "#AA3377", "#44AA99", "#882255", "#999933", "#CC6677", "#88CCEE", "#DDCC77")


def own_colors(names, given: dict | None = None) -> dict[str, str]:
    """name -> colour of a user's own methods: the config's (``given``), else one of
    :data:`OWN_COLORS` in registration order (none twice while they last)."""
    given = {k: v for k, v in (given or {}).items() if v}
    free = [c for c in OWN_COLORS if c not in given.values()]
    out = {}
    for i, n in enumerate(n for n in names if n not in given):
        out[n] = free[i % len(free)] if free else OWN_COLORS[i % len(OWN_COLORS)]
    return {n: given.get(n) or out[n] for n in names}


def _save_settings() -> dict:
    """The style file's ``savefig.*`` settings as ``savefig`` keywords. They are passed
    explicitly because a figure is often saved after the :func:`style` context has
    closed, where matplotlib's defaults (100 dpi, no tight box) would apply instead."""
    rc = matplotlib.rc_params_from_file(str(STYLE), use_default_template=False)
    return {"dpi": float(rc["savefig.dpi"]), "bbox_inches": rc["savefig.bbox"],
            "pad_inches": float(rc["savefig.pad_inches"])}


#: ``savefig`` keywords of every saved figure (dpi >= 200, tight bounding box)
SAVE_KW = _save_settings()


@contextlib.contextmanager
def style() -> Iterator[None]:
    """Context in which figures use the project style."""
    with plt.style.context(str(STYLE)):
        yield


def save(fig: "matplotlib.figure.Figure", paths: Iterable[str | Path] | str | Path) -> list[Path]:
    """Save ``fig`` to every path (PDF/PNG by suffix) deterministically; close it.

    A stem without suffix writes ``stem.pdf`` and ``stem.png``. Files are written
    to a temporary name and renamed, so a failed save leaves nothing behind.
    """
    if isinstance(paths, (str, Path)):
        p = Path(paths)
        paths = [p.with_suffix(".pdf"), p.with_suffix(".png")] if p.suffix == "" else [p]
    paths = [Path(p) for p in paths]
    out = []
    try:
        box = _final_layout_and_box(fig)
        for p in paths:
            p.parent.mkdir(parents=True, exist_ok=True)
            fmt = p.suffix.lstrip(".").lower()
            if fmt == "pdf":
                meta = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
            elif fmt == "png":
                meta = {"Software": None}
            else:
                meta = {}
            with atomic_target(p) as tmp:
                fig.savefig(tmp, format=fmt, metadata=meta, dpi=SAVE_KW["dpi"], bbox_inches=box)
            out.append(p)
    finally:
        plt.close(fig)
    return out


def _final_layout_and_box(fig) -> "matplotlib.transforms.Bbox | str | None":
    """Fix ``fig``'s layout and return the ``bbox_inches`` every format is saved with.

    ``savefig`` would, for each format, run the layout engine in a dry draw, then draw
    once more (drawing disabled) to find the tight bounding box, then draw the file. Here
    the layout engine is run once (its positions are in figure coordinates, the same for
    every format) and removed, and the tight box (padded by ``SAVE_KW``'s pad) is found
    once, by the dry draw ``savefig`` makes for a PNG (the Agg renderer at the saved dpi),
    so each format is drawn once: a layout and 3 draws a figure (PNG and PDF) instead of
    a layout and 4 draws (approach_figures' 20 figures: 15.8 -> 12.0 CPU-s,
    docs/performance.md). The PNG is the file ``savefig(bbox_inches="tight")`` writes
    (tests/test_figure_save.py); the PDF's page is that box, where the PDF renderer's own
    text metrics moved its edge by up to 0.2 pt."""
    engine = fig.get_layout_engine()
    if engine is not None:
        engine.execute(fig)  # what a draw does first; the positions stay once the engine is removed
        with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
            fig.set_layout_engine(None)
    if SAVE_KW["bbox_inches"] != "tight":
        return SAVE_KW["bbox_inches"]
    dpi = fig.dpi
    fig.dpi = SAVE_KW["dpi"]
    try:
        fig.draw_without_rendering()  # the Agg renderer at the saved dpi, as savefig's PNG dry draw
        box = fig.get_tightbbox(fig.canvas.get_renderer())
    finally:
        fig.dpi = dpi
    return box.padded(SAVE_KW["pad_inches"])


# ------------------------------------------------------------ legends clear of data and text
#: inside corners tried in this order before a legend goes outside its axes
LEGEND_CORNERS = ("upper right", "upper left", "lower left", "lower right", "center right", "center left",
                  "upper center", "lower center")


def _renderer(fig):
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _texts(fig, renderer) -> list[tuple[str, "Bbox"]]:
    """(name, display box) of every visible tick label, axis label, title and text of ``fig``."""
    out = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for axis, nm in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            for tick in axis._update_ticks():  # the ticks drawn (inside the view), as Axis.draw
                for t in (tick.label1, tick.label2):
                    if t.get_visible() and t.get_text():
                        out.append((f"{nm} tick label {t.get_text()!r}", t.get_window_extent(renderer)))
            lab = axis.label
            if lab.get_visible() and lab.get_text():
                out.append((f"{nm} label {lab.get_text()!r}", lab.get_window_extent(renderer)))
            off = axis.get_offset_text()
            if off.get_visible() and off.get_text():
                out.append((f"{nm} offset text {off.get_text()!r}", off.get_window_extent(renderer)))
        for t in (ax.title, ax._left_title, ax._right_title, *ax.texts):
            if t.get_visible() and t.get_text():
                out.append((f"text {t.get_text()!r}", t.get_window_extent(renderer)))
    for t in fig.texts + ([fig._suptitle] if fig._suptitle is not None else []):
        if t.get_visible() and t.get_text():
            out.append((f"figure text {t.get_text()!r}", t.get_window_extent(renderer)))
    return out


def _data_hits(ax, box, renderer) -> list[str]:
    """The data artists of ``ax`` (lines, spans, bands, markers, bars, images) drawn inside
    ``box`` (display coordinates; only the part of it inside the axes counts, where the
    data are drawn)."""
    from matplotlib.collections import QuadMesh
    from matplotlib.transforms import Bbox

    inter = Bbox.intersection(box, ax.bbox)
    if inter is None or inter.width < 1 or inter.height < 1:
        return []
    region = inter.padded(-1.0)  # touching is not covering
    hits = []
    for line in ax.get_lines():
        if not line.get_visible():
            continue
        path = line.get_transform().transform_path(line.get_path()).cleaned(remove_nans=True)
        covered = False
        if len(path.vertices) >= 2 and line.get_linestyle() not in ("None", "none", "", " "):
            covered = path.intersects_bbox(region, filled=False)
        if not covered and line.get_marker() not in (None, "None", "none", "", " "):
            v = path.vertices
            covered = bool(((v[:, 0] > region.x0) & (v[:, 0] < region.x1)
                            & (v[:, 1] > region.y0) & (v[:, 1] < region.y1)).any())
        if covered:
            hits.append(f"line {line.get_label()!r}")
    for coll in ax.collections:
        if not coll.get_visible():
            continue
        if isinstance(coll, QuadMesh):
            if Bbox.intersection(coll.get_window_extent(renderer), region) is not None:
                hits.append("mesh")
            continue
        offsets = coll.get_offsets()
        if len(offsets) and coll.get_offset_transform() is not None and len(coll.get_paths()) <= 1 + len(offsets) \
                and not coll.get_transform().contains_branch(ax.transData):
            pts = coll.get_offset_transform().transform(offsets)
            pts = pts[np.isfinite(pts).all(1)]
            if ((pts[:, 0] > region.x0) & (pts[:, 0] < region.x1) & (pts[:, 1] > region.y0)
                    & (pts[:, 1] < region.y1)).any():
                hits.append(f"markers {coll.get_label()!r}")
            continue
        for p in coll.get_paths():
            dp = coll.get_transform().transform_path(p).cleaned(remove_nans=True)
            if len(dp.vertices) >= 2 and dp.intersects_bbox(region, filled=True):
                hits.append(f"area {coll.get_label()!r}")
                break
    for patch in ax.patches:
        if not patch.get_visible():
            continue
        dp = patch.get_transform().transform_path(patch.get_path())
        if dp.intersects_bbox(region, filled=patch.get_fill()):
            hits.append(f"patch {patch.get_label()!r}")
    for im in ax.images:
        if im.get_visible() and Bbox.intersection(im.get_window_extent(renderer), region) is not None:
            hits.append("image")
    return hits


def _crosses_frame(box, frame) -> bool:
    """Whether a legend box lies partly inside and partly outside its axes' frame."""
    inside = box.overlaps(frame.padded(-1.0))
    contained = (box.x0 >= frame.x0 - 1 and box.x1 <= frame.x1 + 1 and box.y0 >= frame.y0 - 1
                 and box.y1 <= frame.y1 + 1)
    return inside and not contained


def legend_collisions(fig) -> list[str]:
    """Every legend of ``fig`` (axes and figure legends) that covers plotted data of any
    axes, or a tick label, axis label, title or text: one line per legend and what it
    covers (empty: every legend is clear). Computed on the drawn figure, as saved."""
    renderer = _renderer(fig)
    legends = [(ax, ax.get_legend()) for ax in fig.axes if ax.get_legend() is not None] + \
              [(None, leg) for leg in fig.legends]
    texts = _texts(fig, renderer)
    out = []
    for owner, leg in legends:
        if not leg.get_visible():
            continue
        box = leg.get_window_extent(renderer)
        name = f"legend of {owner.get_title() or owner.get_ylabel() or 'axes'!r}" if owner else "figure legend"
        hit = [n for n, bb in texts if bb.overlaps(box.padded(-1.0))]
        if owner is not None and _crosses_frame(box, owner.bbox):
            hit.append("the frame of its axes (its ticks)")
        for ax in fig.axes:
            if ax.get_visible() and ax.axison:
                hit += _data_hits(ax, box, renderer)
        if hit:
            out.append(f"{name} covers " + ", ".join(dict.fromkeys(hit)))
    return out


def _clear(leg, fig) -> bool:
    renderer = _renderer(fig)
    box = leg.get_window_extent(renderer)
    if any(bb.overlaps(box.padded(-1.0)) for _, bb in _texts(fig, renderer)):
        return False
    return not any(_data_hits(ax, box, renderer) for ax in fig.axes if ax.get_visible() and ax.axison)


def place_legend(ax, *args, outside: str = "right", **kw):
    """The legend of ``ax`` in the first inside corner (:data:`LEGEND_CORNERS`) where it
    covers no data and no text of the figure as drawn now, else outside the axes
    (``outside``: "right" or "below"). Call it after the figure's content is drawn; a
    figure with constrained layout makes room for an outside legend itself."""
    fig = ax.figure
    for loc in LEGEND_CORNERS:
        leg = ax.legend(*args, loc=loc, **kw)
        if _clear(leg, fig):
            return leg
    if outside == "below":
        return ax.legend(*args, loc="upper center", bbox_to_anchor=(0.5, -0.18), **kw)
    return ax.legend(*args, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, **kw)


def plain_number(x: float) -> str:
    """A tick or colour-bar label as a plain number (no e-notation): 3 significant
    digits, thousands without exponent (12,300), small values as decimals (0.00123)."""
    x = float(x)
    if x == 0 or not np.isfinite(x):
        return f"{x:g}"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    digits = max(0, 2 - int(np.floor(np.log10(abs(x)))))
    return f"{x:.{digits}f}".rstrip("0").rstrip(".") if "." in f"{x:.{digits}f}" else f"{x:.{digits}f}"


def plain_log_labels(axis) -> None:
    """Label a log axis (``ax.xaxis`` / ``ax.yaxis``; call after plotting) with plain numbers
    (0.5, 1, 2, 5, 10, 1,000), no 10^k: 1-2-5 steps over at most 2.5 decades, decades beyond."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    lo, hi = sorted(axis.get_view_interval())
    decades = np.log10(hi / lo) if lo > 0 else np.inf
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0) if decades <= 2.5 else (1.0,)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: plain_number(v)))
    axis.set_minor_formatter(NullFormatter())
