"""The shared figure style and deterministic figure saving.

Every plot of the pipeline is made under :func:`style` (one matplotlib style
file, ``opnav.mplstyle``, sized for a journal column) and written by
:func:`save`, which produces PDF and PNG without creation dates or software
stamps, so the same data give byte-identical files. Estimators never import
this module: plotting lives in ``workflow/scripts`` and here only.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Iterable, Iterator

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from opnav.tables import atomic_target  # noqa: E402

STYLE = Path(__file__).with_name("opnav.mplstyle")

#: Column and full-page widths (inches) for the manuscript.
COLUMN_WIDTH_IN = 3.5
PAGE_WIDTH_IN = 7.0

#: Colour/marker used everywhere for the papers' published values.
PUBLISHED_STYLE = dict(color="0.35", marker="x", linestyle="none", label="published")


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
    out = []
    try:
        for p in map(Path, paths):
            p.parent.mkdir(parents=True, exist_ok=True)
            fmt = p.suffix.lstrip(".").lower()
            if fmt == "pdf":
                meta = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
            elif fmt == "png":
                meta = {"Software": None}
            else:
                meta = {}
            with atomic_target(p) as tmp:
                fig.savefig(tmp, format=fmt, metadata=meta)
            out.append(p)
    finally:
        plt.close(fig)
    return out
