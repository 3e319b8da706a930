"""What a reader of the printed manuscript sees: tables legible at print size, and no raw
template code or unfilled placeholder in any generated text.

* :func:`table_sizes` reads the print size of every table float from the LaTeX log, where
  ``paper/print-size.tex`` writes it as the table is typeset (its tabulars' smallest font
  size times any ``\\resizebox``/``\\scalebox`` factor around them);
  :func:`small_tables` lists those under :data:`MIN_TABLE_PT`.
* :func:`raw_text_findings` lists the template code (``{%``, ``{{``, ``snakemake.``) and
  unfilled placeholders left in generated ``.tex``, ``.md`` and ``.csv`` files.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

#: the smallest font size a printed table may be set at, pt
MIN_TABLE_PT = 7.0

_SIZE_LINE = re.compile(r"^opnav-table-size: (\S+) (?:none|([0-9.]+)pt)\s*$", re.MULTILINE)


@dataclass(frozen=True)
class TableSize:
    table: str          #: the table's number in the PDF
    pt: float | None    #: printed font size, pt (None: a float without a tabular)


def table_sizes(log_text: str) -> list[TableSize]:
    """Every table float's printed size, in the order of the PDF, from a LaTeX log."""
    return [TableSize(m.group(1), None if m.group(2) is None else float(m.group(2)))
            for m in _SIZE_LINE.finditer(log_text)]


def small_tables(sizes: list[TableSize], min_pt: float = MIN_TABLE_PT) -> list[TableSize]:
    """The tables printed under ``min_pt`` (to 0.05 pt: TeX's arithmetic is in scaled points)."""
    return [s for s in sizes if s.pt is not None and s.pt < min_pt - 0.05]


# ------------------------------------------------------------ raw text in generated files
#: template code as Jinja writes it, or as LaTeX-escaped text shows it (\{\%, \{\{)
_TEMPLATE = re.compile(r"\{%|%\}|\{\{|\}\}|\bsnakemake\.")
#: a format field left unfilled: {name}, {a.b}, {0}, %(name)s, ${name}; or a macro the
#: manuscript asked for and no rule wrote ([Name?], see paper/main.tex's \R)
_PLACEHOLDER = re.compile(r"(?<![\\$^_])\{[A-Za-z_][A-Za-z0-9_.]*\}|\{\d+\}|%\([A-Za-z_]\w*\)[sdfr]"
                          r"|\$\{[A-Za-z_]\w*\}|\[[A-Z][A-Za-z]+\?\]")
_TEX_COMMENT = re.compile(r"(?<!\\)%.*$", re.MULTILINE)
_TEX_ESCAPES = [(r"\textbackslash{}", "\\"), (r"\%", "%"), (r"\_", "_"), (r"\#", "#"), (r"\$", "$"),
                (r"\&", "&")]


def _tex_as_text(tex: str) -> str:
    """LaTeX source as the text it prints, for the patterns above: comments dropped (so
    ``{%`` ending a line is not template code), escapes undone (``\\{\\%`` is ``{%``),
    commands' own brace groups dropped (``\\texttt{x}`` keeps ``x``, and ``\\newcommand{\\A}{1}``
    does not read as a field ``{A}``)."""
    text = _TEX_COMMENT.sub("", tex)
    text = text.replace(r"\{", "\x02").replace(r"\}", "\x03")   # an escaped brace is text
    for esc, plain in _TEX_ESCAPES:
        text = text.replace(esc, plain)
    text = re.sub(r"\\[A-Za-z@]+\*?", " ", text)               # command names
    text = re.sub(r"[{}]", " ", text)                          # LaTeX's own groups
    return text.replace("\x02", "{").replace("\x03", "}")


def raw_text_findings(root: str | Path, suffixes: tuple[str, ...] = (".tex", ".md", ".csv")) -> list[str]:
    """``file: excerpt`` for every template fragment or unfilled placeholder in the generated
    files under ``root`` (recursively), in file order. ``[]`` when every text is rendered."""
    out = []
    for p in sorted(Path(root).rglob("*")):
        if p.suffix not in suffixes or not p.is_file():
            continue
        raw = p.read_text(errors="replace")
        text = _tex_as_text(raw) if p.suffix == ".tex" else raw
        for pat in (_TEMPLATE, _PLACEHOLDER):
            for m in pat.finditer(text):
                a, b = max(0, m.start() - 30), min(len(text), m.end() + 30)
                out.append(f"{p}: ...{' '.join(text[a:b].split())}...")
    return out
