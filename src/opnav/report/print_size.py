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


# ------------------------------------------------------------ sentences a reader can follow
#: LaTeX environments that hold table cells, not sentences
_TABULAR = re.compile(r"\\begin\{(tabular\*?|tabularx|longtable)\}(?:(?!\\begin\{(?:tabular|tabularx|longtable)).)*?"
                      r"\\end\{\1\}", re.S)
_TEX_DROP = re.compile(r"\\(?:label|input|includegraphics|ref|cite|href|url|setlength|resizebox|scalebox|hypersetup)"
                       r"\s*(?:\[[^\]]*\])?(?:\{[^{}]*\})?(?:\{[^{}]*\})?")
_MACRO_DEF = re.compile(r"^\\newcommand\{\\([A-Za-z]+)\}\{(.*)\}\s*$", re.MULTILINE)


def tex_prose(tex: str) -> str:
    """The running text of a LaTeX fragment, for cutting into sentences: comments, tables
    (tabular, longtable: cells are not sentences), a caption's short form, labels, inputs,
    graphics and references dropped; a description item's label opens its own paragraph
    ('A-C1: ...'); inline math is one word; command names and braces dropped, their text kept."""
    t = _TEX_COMMENT.sub("", tex)
    while True:  # innermost tables first (a cell may hold a tabular)
        n = _TABULAR.sub("\n\n", t)
        if n == t:
            break
        t = n
    t = re.sub(r"\\caption\[[^\]]*\]", r"\\caption", t)
    t = _TEX_DROP.sub(" ", t)
    t = re.sub(r"\\item\[([^\]]*)\]", "\n\n\\1: ", t)
    t = re.sub(r"\\(?:par|paragraph)\b", "\n\n", t)
    t = re.sub(r"(?<!\\)\$[^$]*\$", "x", t)
    t = re.sub(r"\\[,;:! ]", " ", t)   # TeX's spaces (28.5\,\% is '28.5 %')
    for esc, plain in _TEX_ESCAPES:
        t = t.replace(esc, plain)
    t = re.sub(r"\\[A-Za-z@]+\*?", " ", t)
    return re.sub(r"[{}\\]", " ", t).replace("~", " ")


def manuscript_macros(manuscript_dir: str | Path) -> set[str]:
    """The macros the hand-written manuscript uses (``\\R{Name}`` and ``\\Name`` in
    ``paper/main.tex`` and ``paper/sections/*.tex``): the generated macros a reader reads."""
    root = Path(manuscript_dir)
    text = " ".join(p.read_text(errors="replace") for p in [root / "main.tex", *sorted((root / "sections").glob("*.tex"))]
                    if p.is_file())
    return set(re.findall(r"\\R\{([A-Za-z]+)\}", text)) | set(re.findall(r"\\([A-Za-z]+)", text))


def prose_fragments(results: str | Path, used_macros: set[str] | None = None) -> list[tuple[str, str]]:
    """``(where, plain text)`` of every generated text a reader reads under a build's results
    folder: the LaTeX fragments of ``paper/`` (each macro of ``macros.tex`` that
    ``used_macros`` names, every other ``.tex`` file whole: captions, appendix lists, the
    abstract, the conclusion; tables dropped), every Markdown file (table rows and headings
    dropped) and every generated caption (``.rst``)."""
    root = Path(results)
    out: list[tuple[str, str]] = []
    for p in sorted(root.rglob("*")):
        if not p.is_file() or {"logs", "build", "work", ".snakemake"} & set(p.relative_to(root).parts):
            continue
        rel = str(p.relative_to(root))
        if p.suffix == ".tex" and p.parent.name == "paper" or (p.suffix == ".tex" and "paper" in p.parts):
            raw = p.read_text(errors="replace")
            if p.name == "macros.tex":
                for m in _MACRO_DEF.finditer(raw):
                    if used_macros is None or m.group(1) in used_macros:
                        out.append((f"{rel}: \\{m.group(1)}", tex_prose(m.group(2))))
            else:
                out.append((rel, tex_prose(raw)))
        elif p.suffix in (".md", ".rst"):
            lines = [ln for ln in p.read_text(errors="replace").splitlines()
                     if not ln.lstrip().startswith(("|", "#", ".. ", ":"))]
            out.append((rel, "\n".join(lines)))
    return out


def long_sentence_findings(results: str | Path, used_macros: set[str] | None = None,
                           max_words: int | None = None) -> list[str]:
    """``where (N words): sentence`` for every generated sentence longer than ``max_words``
    (:data:`opnav.core.wording.MAX_SENTENCE_WORDS`) under ``results``; ``[]`` when every
    sentence a reader meets is short enough to follow."""
    from opnav.core import wording

    limit = wording.MAX_SENTENCE_WORDS if max_words is None else max_words
    out = []
    for where, text in prose_fragments(results, used_macros):
        for s in wording.sentences(text):
            n = wording.word_count(s)
            if n > limit:
                out.append(f"{where} ({n} words): {s[:160]}{'...' if len(s) > 160 else ''}")
    return out


#: slips of generated numbers a reader trips over: a plural after 1 ('1 maps', '1 stars per
#: image'), a signed zero change ('-0 % lower'), a ratio or change printed as a bare 1 or 0
_SLIPS = [
    (re.compile(r"(?<![\d.,\-])1 (maps|stars|runs|seeds|samples|cases|images|calls|landmarks|iterations|claims|"
                r"replays|variants|ratios|windows|segments)\b"), "a plural after 1"),
    (re.compile(r"(?<![\d.])[-\u2212]0(?:\.0+)? ?%"), "a signed zero percentage"),
    (re.compile(r"(?<![\d.\-\u2212])0(?:\.0+)? ?% (?:lower|higher|less|more)\b"), "a zero change said as a number"),
]


def slip_findings(results: str | Path, used_macros: set[str] | None = None) -> list[str]:
    """``where: excerpt (what)`` for every number slip (:data:`_SLIPS`) in the generated text a
    reader reads under ``results`` (:func:`prose_fragments`)."""
    out = []
    for where, text in prose_fragments(results, used_macros):
        flat = " ".join(text.split())
        for pat, what in _SLIPS:
            for m in pat.finditer(flat):
                out.append(f"{where}: ...{flat[max(0, m.start() - 40):m.end() + 20]}... ({what})")
    return out
