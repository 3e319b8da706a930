"""Write result tables as CSV, LaTeX (booktabs) and Markdown, deterministically.

Every table of the pipeline goes through :func:`write_table`, so all three
formats carry the same numbers, floats are printed with a fixed format, and a
file is either complete or absent (written to a temporary name, then renamed).
"""

from __future__ import annotations

import math
import numbers

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator

if TYPE_CHECKING:  # pandas is imported where a table is built (scripts that only write files skip it)
    import pandas as pd


def _umask() -> int:
    """The process umask (read by setting and restoring it; there is no getter)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_target(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``.

    A file is either complete or absent. ``tempfile.mkstemp`` creates its file
    with mode 0600 whatever the umask, so before the rename the file gets the
    mode a plain ``open(path, "w")`` would give (``0o666 & ~umask``, e.g. 0644
    under umask 022): colleagues sharing a results folder can read it.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=path.suffix or ".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file and an atomic rename."""
    with atomic_target(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)


def _latex_escape(s: str) -> str:
    for a, b in [("\\", r"\textbackslash{}"), ("&", r"\&"), ("%", r"\%"), ("_", r"\_"),
                 ("#", r"\#"), ("$", r"\$")]:
        s = s.replace(a, b)
    return s


def to_latex(df: pd.DataFrame, caption: str | None = None, label: str | None = None,
             float_format: str = "{:.4g}") -> str:
    """A booktabs tabular (no float environment) for ``\\input`` in the manuscript.

    Column headers and string cells are escaped; the caption, if given, is a
    LaTeX comment on the first line so the file stays a bare tabular that the
    manuscript wraps in its own ``table`` environment.
    """
    body = df.to_latex(
        index=False,
        escape=True,
        float_format=lambda x: float_format.format(x) if math.isfinite(x) else "--",
        na_rep="--",
        column_format="l" * df.shape[1],
    )
    head = []
    if caption:
        head.append("% " + caption.replace("\n", " "))
    if label:
        head.append(f"% label: {label}")
    return "\n".join(head + [body])


def to_markdown(df: pd.DataFrame, caption: str | None = None, float_format: str = "{:.4g}") -> str:
    """A GitHub-flavoured Markdown table with an optional caption line above."""
    import pandas as pd

    fmt = df.copy()
    for c in fmt.columns:
        if pd.api.types.is_float_dtype(fmt[c]):
            fmt[c] = [("--" if not math.isfinite(x) else float_format.format(x)) for x in fmt[c]]
        else:
            fmt[c] = [("--" if x is None or (pd.api.types.is_scalar(x) and pd.isna(x)) else x)
                      for x in fmt[c]]
    md = fmt.to_markdown(index=False)
    return (f"{caption}\n\n{md}\n" if caption else md + "\n")


def write_table(df: pd.DataFrame, paths: Iterable[str | Path] | str | Path,
                caption: str | None = None, float_format: str = "{:.4g}") -> list[Path]:
    """Write ``df`` to every path given, choosing the format by suffix.

    ``paths`` is either a stem (writes ``stem.csv``, ``stem.tex``, ``stem.md``)
    or an explicit list of files ending in .csv/.tex/.md. CSV keeps full
    precision (``%.10g``); LaTeX and Markdown use ``float_format``.
    """
    if isinstance(paths, (str, Path)) and Path(paths).suffix == "":
        paths = [Path(f"{paths}{ext}") for ext in (".csv", ".tex", ".md")]
    elif isinstance(paths, (str, Path)):
        paths = [paths]
    written = []
    for p in map(Path, paths):
        if p.suffix == ".csv":
            text = df.to_csv(index=False, float_format="%.10g", lineterminator="\n")
        elif p.suffix == ".tex":
            text = to_latex(df, caption=caption, float_format=float_format)
        elif p.suffix == ".md":
            text = to_markdown(df, caption=caption, float_format=float_format)
        else:
            raise ValueError(f"unknown table format for {p} (use .csv, .tex or .md)")
        atomic_write_text(p, text)
        if p.suffix == ".csv":
            write_checksum(p, text)
        written.append(p)
    return written


#: Suffix of the checksum sidecar of a CSV table or JSON summary (``A-T1_table1.csv.sha256``),
#: which :func:`opnav.core.snakeio.load_table` and :func:`~opnav.core.snakeio.load_json` check.
CHECKSUM_SUFFIX = ".sha256"


def checksum_path(path: str | Path) -> Path:
    """The checksum sidecar of ``path``."""
    p = Path(path)
    return p.with_name(p.name + CHECKSUM_SUFFIX)


def write_checksum(path: str | Path, text: str) -> None:
    """Write the sidecar of ``path`` whose contents are ``text``: SHA-256 and byte count."""
    import hashlib

    data = text.encode("utf-8")
    atomic_write_text(checksum_path(path), f"sha256={hashlib.sha256(data).hexdigest()} bytes={len(data)}\n")


#: dataclass field metadata for :func:`json_ready`: ``omit_none`` leaves the key out while the
#: value is None (an optional part of a document), ``json_key`` writes the field under another key
#: (one that is no Python name, e.g. ``A-F5``), ``json_skip`` never writes it (a number the
#: record carries for its words, not part of the document)
OMIT_NONE = {"omit_none": True}
JSON_SKIP = {"json_skip": True}


def json_key(key: str, omit_none: bool = False) -> dict:
    """Field metadata writing a dataclass field under ``key`` in JSON (:func:`json_ready`)."""
    return {"json_key": key, "omit_none": omit_none}


def json_ready(x, nan_as_none: bool = True):
    """``x`` with numpy scalars as Python numbers and NaN/inf as ``None`` (valid JSON;
    ``nan_as_none=False`` keeps them: the document in memory); a dataclass (a typed record) as the
    mapping of its fields (metadata: :data:`OMIT_NONE`, :func:`json_key`, :data:`JSON_SKIP`,
    ``json_flatten``: a mapping field whose items are written into the record's own object)."""
    import dataclasses
    import math

    import numpy as np

    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        out = {}
        for f in dataclasses.fields(x):
            v = getattr(x, f.name)
            if f.metadata.get("json_skip") or (f.metadata.get("omit_none") and v is None):
                continue
            if f.metadata.get("json_flatten"):
                out.update(json_ready(v, nan_as_none))
            else:
                out[f.metadata.get("json_key", f.name)] = json_ready(v, nan_as_none)
        return out
    if isinstance(x, dict):
        return {str(k): json_ready(v, nan_as_none) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_ready(v, nan_as_none) for v in x]
    if isinstance(x, np.ndarray):
        return json_ready(x.tolist(), nan_as_none)
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) or not nan_as_none else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def write_json(path: str | Path, obj) -> None:
    """Write ``obj`` as sorted, indented JSON (via :func:`json_ready`), atomically, with its
    checksum sidecar (:func:`write_checksum`)."""
    import json

    text = json.dumps(json_ready(obj), indent=2, sort_keys=True) + "\n"
    atomic_write_text(path, text)
    write_checksum(path, text)


# ------------------------------------------------------------ table cells
#: What a missing value reads as in the manuscript (never "nan").
MISSING = "--"


def is_missing(x: Any) -> bool:
    """None, NaN (any float type), pandas' NA/NaT, or the text ``nan``."""
    if x is None:
        return True
    if isinstance(x, str):
        return x.strip().lower() in ("nan", "<na>", "nat", "none", "")
    if isinstance(x, numbers.Real) and not isinstance(x, bool):
        return math.isnan(float(x))
    try:
        import pandas as pd

        return bool(pd.isna(x)) if pd.api.types.is_scalar(x) else False
    except (ImportError, TypeError, ValueError):
        return False


def cell_pm(mean: float, spread: float, fmt: str = "{:.3g}") -> str:
    """A page-table cell 'mean ± spread' (the mean alone without a spread; missing: MISSING)."""
    if is_missing(mean) or not math.isfinite(float(mean)):
        return MISSING
    if is_missing(spread) or not math.isfinite(float(spread)):
        return fmt.format(mean)
    return f"{fmt.format(mean)} ± {fmt.format(spread)}"


def cell_num(x: float, fmt: str = "{:.4g}") -> str:
    """A page-table cell for one number (missing or non-finite: MISSING)."""
    if is_missing(x) or (isinstance(x, numbers.Real) and not math.isfinite(float(x))):
        return MISSING
    return fmt.format(x)
