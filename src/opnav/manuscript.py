"""Generated pieces of the reproduction manuscript (``paper/main.tex``).

* :func:`macros_from_summary` turns a results summary (nested dict of numbers,
  read from ``*-summary.json``) into LaTeX ``\\newcommand`` definitions, one per
  number, so no result in the text is typed by hand.
* :func:`float_block` writes the figure/table floats for a list of generated
  outputs, with captions taken from ``workflow/report/<ID>.rst`` (the same
  captions the Snakemake report shows).
"""

from __future__ import annotations

import math
import numbers
import re
from pathlib import Path
from typing import Any, Iterable, Mapping

from opnav.tables import MISSING, is_missing  # noqa: F401 (re-exported)

_DIGITS = ["Zero", "One", "Two", "Three", "Four", "Five", "Six", "Seven", "Eight", "Nine"]


def np_bool_types() -> tuple:
    try:
        import numpy as np

        return (np.bool_,)
    except ImportError:  # pragma: no cover
        return ()


def macro_name(parts: Iterable[str]) -> str:
    """A LaTeX-safe macro name (letters only) from key parts: ``("A", "literal", "est_x")`` -> ``ALiteralEstX``."""
    words: list[str] = []
    for part in parts:
        for w in re.split(r"[^0-9A-Za-z]+", str(part)):
            if not w:
                continue
            w = "".join(_DIGITS[int(c)] if c.isdigit() else c for c in w)
            words.append(w[0].upper() + w[1:])
    name = "".join(words)
    if not name.isalpha():  # pragma: no cover - guarded by construction
        raise ValueError(f"cannot form a macro name from {parts!r}")
    return name


_NAN_WORD = re.compile(r"(?<![A-Za-z])(?:nan|<NA>|NaT)(?![A-Za-z])", re.IGNORECASE)


def no_nan_text(text: str) -> str:
    """``text`` with every standalone ``nan`` / ``<NA>`` / ``NaT`` token replaced by
    :data:`MISSING` (a last guard for strings formatted upstream)."""
    return _NAN_WORD.sub(MISSING, text)


def format_number(x: float) -> str:
    """Numbers as a reader wants them in running text: 4 significant digits, no
    exponent above 1e-3; a missing value (None, NaN) reads as :data:`MISSING`."""
    if isinstance(x, (bool, np_bool_types())):
        return "yes" if x else "no"
    if isinstance(x, numbers.Integral):
        return f"{int(x):,}".replace(",", "{,}")
    if is_missing(x):
        return MISSING
    x = float(x)
    if math.isinf(x):
        return r"$\infty$" if x > 0 else r"$-\infty$"
    ax = abs(x)
    if ax >= 1000:
        return f"{x:,.0f}".replace(",", "{,}")
    if ax == 0:
        return "0"
    if ax >= 1e-3:
        return f"{x:.4g}"
    m, e = f"{x:.2e}".split("e")
    return rf"{m}\times10^{{{int(e)}}}"


def latex_escape(text: str) -> str:
    """Escape LaTeX special characters in plain text."""
    repl = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
            "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\^{}"}
    return "".join(repl.get(c, c) for c in text)


def macros_from_summary(summary: Mapping[str, Any], prefix: str) -> dict[str, str]:
    """Flatten a nested summary into ``{macro name: LaTeX text}``.

    Numbers are formatted by :func:`format_number`; strings are escaped; lists
    are indexed (``One``, ``Two``...). Keys that would collide raise ``ValueError``.
    """
    out: dict[str, str] = {}

    def walk(node: Any, parts: list[str]) -> None:
        if isinstance(node, Mapping):
            for k, v in node.items():
                walk(v, parts + [str(k)])
        elif isinstance(node, (list, tuple)):
            for i, v in enumerate(node):
                walk(v, parts + [str(i + 1)])
        else:
            name = macro_name([prefix, *parts])
            if name in out:
                raise ValueError(f"macro {name} defined twice")
            if node is None or isinstance(node, (numbers.Real, bool, *np_bool_types())):
                out[name] = format_number(node)
            else:
                out[name] = no_nan_text(latex_escape(str(node)))

    walk(summary, [])
    return out


def render_macros(macros: Mapping[str, str], header: str = "") -> str:
    """``\\newcommand`` lines, sorted by name for byte-stable output."""
    lines = [f"% {line}" for line in header.splitlines()] if header else []
    lines += [f"\\newcommand{{\\{k}}}{{{v}}}" for k, v in sorted(macros.items())]
    return "\n".join(lines) + "\n"


def rst_to_latex(text: str) -> str:
    """Caption text from an ``.rst`` caption file as LaTeX (plain prose subset)."""
    text = " ".join(text.split())
    parts = re.split(r"(``[^`]+``|\*[^*]+\*|:math:`[^`]+`)", text)
    out = []
    for p in parts:
        if p.startswith("``"):
            out.append(r"\texttt{" + latex_escape(p[2:-2]) + "}")
        elif p.startswith(":math:"):
            out.append("$" + p[7:-1] + "$")
        elif p.startswith("*") and p.endswith("*") and len(p) > 2:
            out.append(r"\emph{" + latex_escape(p[1:-1]) + "}")
        else:
            out.append(latex_escape(p))
    return "".join(out)


def output_id(path: str | Path) -> str:
    """The SPEC id of an output from its file name: ``A-F4_bias_estimate_roll.pdf`` -> ``A-F4``."""
    return Path(path).stem.split("_", 1)[0]


def output_variant(path: str | Path) -> str:
    """The free-text rest of an output's stem, for the caption suffix."""
    stem = Path(path).stem
    return stem.split("_", 1)[1].replace("_", " ") if "_" in stem else ""


def float_block(paths: Iterable[str | Path], captions_dir: str | Path, relative_to: str | Path,
                width: str | None = None) -> str:
    """Figure floats for PDFs and table floats for ``.tex`` tables, in the given order.

    Figures keep their natural size (the shared style draws them at column
    or page width, so fonts read at 8 pt), shrunk only if wider than the text;
    ``width`` forces a width instead.
    ``relative_to`` is the directory LaTeX resolves paths from; paths are
    written relative to it with forward slashes, so the output does not depend
    on where the checkout lives.
    """
    import os

    blocks = []
    captions_dir = Path(captions_dir)
    for p in map(Path, paths):
        cid = output_id(p)
        cap_file = captions_dir / f"{cid}.rst"
        if not cap_file.is_file():  # a generated caption beside the output (parameter studies)
            cap_file = p.parent / f"{cid}.rst"
        if not cap_file.is_file():
            raise FileNotFoundError(f"no caption file {captions_dir / f'{cid}.rst'} for {p}")
        caption = rst_to_latex(cap_file.read_text())
        variant = output_variant(p)
        rel = Path(os.path.relpath(p, relative_to)).as_posix()
        label = re.sub(r"[^A-Za-z0-9:-]", "-", p.stem)
        short = latex_escape(f"{cid} ({variant})" if variant else cid)
        if p.suffix == ".pdf":
            blocks.append(
                "\\begin{figure}[htbp]\n  \\centering\n"
                + (f"  \\includegraphics[width={width}]{{{rel}}}\n" if width else
                   "  \\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}"
                   f"{{\\includegraphics{{{rel}}}}}\n")
                + f"  \\caption[{short}]{{\\textbf{{{short}.}} {caption}}}\n"
                f"  \\label{{fig:{label}}}\n\\end{{figure}}\n"
            )
        elif p.suffix == ".tex":
            blocks.append(
                "\\begin{table}[htbp]\n  \\centering\n"
                f"  \\caption[{short}]{{\\textbf{{{short}.}} {caption}}}\n"
                f"  \\label{{tab:{label}}}\n"
                "  \\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}{%\n"
                f"    \\input{{{rel}}}}}\n\\end{{table}}\n"
            )
        else:
            raise ValueError(f"{p}: only .pdf figures and .tex tables go into the manuscript")
    return "\n".join(blocks)


# ------------------------------------------------------------ compact tables
#: Manuscript views of tables too wide for a page, by SPEC id: each paper's report module
#: holds its own (opnav.approach.report, opnav.landing.report).
def _compact_views() -> dict:
    from opnav.approach import report as a_report
    from opnav.landing import report as b_report

    return {**a_report.COMPACT_VIEWS, **b_report.COMPACT_VIEWS}


COMPACT_VIEWS = _compact_views()
