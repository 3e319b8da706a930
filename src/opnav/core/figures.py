"""The shared figure style, the one colour palette, and deterministic figure saving.

Every plot of the pipeline is drawn by a plots module (:mod:`opnav.approach.plots`,
:mod:`opnav.approach.peer_plots`, :mod:`opnav.landing.plots`,
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
    "closest": "#B8860B", "logdet_nav": "#6A3D9A",
}
#: Other spellings of the same method (table labels, study estimator names).
ALIASES: dict[str, str] = {
    "em_plain": "plain", "em_squarem": "squarem", "EM-EKF (plain)": "plain",
    "EM-EKF (SQUAREM)": "squarem", "augmented EKF": "augmented", "batch ML (IPOPT)": "batch_ml",
}


def color(label: str) -> str:
    """The colour of a method or scenario variant (:data:`PALETTE`, through
    :data:`ALIASES`); a label outside the palette (a new planning method) gets a
    colour from its name alone, so it too is the same in every figure."""
    key = ALIASES.get(label, label)
    if key in PALETTE:
        return PALETTE[key]
    return f"C{zlib.crc32(key.encode()) % 10}"


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
        if fig.get_layout_engine() is not None:
            # One layout for every format: savefig runs the layout engine in a dry draw
            # before each format's own draw (constrained layout: about half of a save's
            # time, measured). Solve it once, then remove the engine (positions stay), so
            # each format is drawn once. The layout is in figure coordinates. Done for a
            # single format too, so the tight bounding box (SAVE_KW) sees the same layout
            # whatever formats are saved together.
            fig.draw_without_rendering()
            with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
                fig.set_layout_engine(None)
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
                fig.savefig(tmp, format=fmt, metadata=meta, **SAVE_KW)
            out.append(p)
    finally:
        plt.close(fig)
    return out
