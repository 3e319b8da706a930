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
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opnav.core.tables import MISSING, is_missing

if TYPE_CHECKING:  # annotations only: pandas is imported where a frame is made
    import pandas as pd

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

    Numbers are formatted by :func:`format_number`; strings become prose (:func:`prose_tex`); lists
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
                out[name] = prose_tex(str(node))

    walk(summary, [])
    return out


def render_macros(macros: Mapping[str, str], header: str = "") -> str:
    """``\\newcommand`` lines, sorted by name for byte-stable output."""
    lines = [f"% {line}" for line in header.splitlines()] if header else []
    lines += [f"\\newcommand{{\\{k}}}{{{v}}}" for k, v in sorted(macros.items())]
    return "\n".join(lines) + "\n"


class CaptionContext:
    """The ``snakemake`` object a caption template sees, as Snakemake's HTML report builds it
    for an output (``snakemake.report.FileRecord.render``): the run's config, the producing
    job's rule name, wildcards and (plain-valued) params. Input, output, threads, resources
    and log are not known when the manuscript is written: a caption that uses them stops
    with the template error (:func:`render_caption`)."""

    def __init__(self, config: Mapping[str, Any], wildcards: Mapping[str, Any] | None = None,
                 rule: str | None = None, params: Mapping[str, Any] | None = None):
        from types import SimpleNamespace

        self.config = config
        self.rule = rule
        self.wildcards = SimpleNamespace(**dict(wildcards or {}))
        self.params = SimpleNamespace(**dict(params or {}))


def render_caption(text: str, snakemake: CaptionContext, source: str = "caption") -> str:
    """A caption's reStructuredText with its Jinja template code rendered, as Snakemake's
    report renders it (same environment options: ``trim_blocks``, ``lstrip_blocks``), so the
    PDF and the HTML report print the same words. An undefined name stops with a one-line
    error naming the caption file (the HTML report would print it as empty text)."""
    import jinja2

    env = jinja2.Environment(trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    try:
        return env.from_string(text).render(snakemake=snakemake)
    except jinja2.TemplateError as exc:
        raise ValueError(f"{source}: cannot render its template code: {exc}") from None


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
            lead, tail = " " if p[:1].isspace() else "", " " if p[-1:].isspace() else ""
            out.append(lead + prose_tex(p) + tail if p.strip() else p)
    return "".join(out)


def output_id(path: str | Path) -> str:
    """The SPEC id of an output from its file name: ``A-F4_bias_estimate_roll.pdf`` -> ``A-F4``."""
    return Path(path).stem.split("_", 1)[0]


def output_variant(path: str | Path) -> str:
    """The free-text rest of an output's stem, for the caption suffix."""
    stem = Path(path).stem
    return stem.split("_", 1)[1].replace("_", " ") if "_" in stem else ""


def caption_path(path: str | Path, captions_dir: str | Path) -> Path | None:
    """The caption file of an output in ``captions_dir``, the most specific that exists: a
    table's own ``<ID>.table.rst`` where a figure shares its id; ``<ID>.<part>.rst`` for a part
    of the file name after the id (``B-F7_overhead_interior.pdf`` -> ``B-F7.overhead.rst``, the
    caption its rule gives the HTML report); else ``<ID>.rst``. None when none exists."""
    p, captions_dir = Path(path), Path(captions_dir)
    cid = output_id(p)
    names = ([f"{cid}.table.rst"] if p.suffix == ".tex" else []) + [
        f"{cid}.{part}.rst" for part in p.stem.split("_")[1:] if part and part != "table"] + [f"{cid}.rst"]
    return next((captions_dir / n for n in names if (captions_dir / n).is_file()), None)


def caption_file(path: str | Path, captions_dir: str | Path) -> Path:
    """The caption of an output: :func:`caption_path` in ``captions_dir``, else a caption
    generated beside the output (a parameter study's ``<ID>.rst``)."""
    p = Path(path)
    cap = caption_path(p, captions_dir) or caption_path(p, p.parent)
    if cap is None:
        raise FileNotFoundError(f"no caption file {Path(captions_dir) / f'{output_id(p)}.rst'} for {p}")
    return cap


def float_block(paths: Iterable[str | Path], captions_dir: str | Path, relative_to: str | Path,
                width: str | None = None, captions: Mapping[str, str] | None = None) -> str:
    """Figure floats for PDFs and table floats for ``.tex`` tables, in the given order.

    Every caption is rendered before it becomes LaTeX (:func:`render_caption`): ``captions``
    holds, by path as given, the caption rendered with its job's context (rule paper_floats
    renders them when the workflow is parsed, from the run's config and each output's
    wildcards); any other caption file is rendered here with an empty context, so one whose
    template code needs the config stops with its error instead of printing as code.

    Figures keep their natural size (the shared style draws them at column
    or page width, so fonts read at 8 pt), shrunk only if wider than the text;
    ``width`` forces a width instead.
    ``relative_to`` is the directory LaTeX resolves paths from; paths are
    written relative to it with forward slashes, so the output does not depend
    on where the checkout lives.
    """
    import os

    blocks = []
    for p in map(Path, paths):
        cid = output_id(p)
        rendered = (captions or {}).get(str(p))
        if rendered is None:
            cap_file = caption_file(p, captions_dir)
            rendered = render_caption(cap_file.read_text(), CaptionContext({}), source=str(cap_file))
        caption = rst_to_latex(rendered)
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
            # set at \footnotesize (legible_latex fits its tables to that line); shrunk only if
            # still wider, which paper/print-size.tex measures and rule paper_pdf reports
            blocks.append(
                "\\begin{table}[htbp]\n  \\centering\n"
                f"  \\caption[{short}]{{\\textbf{{{short}.}} {caption}}}\n"
                f"  \\label{{tab:{label}}}\n"
                "  {\\footnotesize\\setlength{\\tabcolsep}{4pt}"
                "\\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}"
                f"{{\\input{{{rel}}}}}\\par}}\n\\end{{table}}\n"
            )
        else:
            raise ValueError(f"{p}: only .pdf figures and .tex tables go into the manuscript")
    return "\n".join(blocks)


# ------------------------------------------------------------ compact tables
#: Manuscript views of tables too wide for a page, by SPEC id: each paper's report module
#: holds its own (opnav.report.approach_views, opnav.report.landing.summary).
def _compact_views() -> dict:
    from opnav.report.landing import summary as b_report
    from opnav.report import approach_views

    return {**approach_views.COMPACT_VIEWS, **b_report.COMPACT_VIEWS}


COMPACT_VIEWS = _compact_views()


# ------------------------------------------------------------ prose typography
_PROSE = [
    (re.compile(r"\brho\*theta\b"), r"$\\rho\\theta$"),
    (re.compile(r"(?<=\d) ?arcsec\b"), r"\\arcsec{}"),
    (re.compile(r"\+-"), r"$\\pm$"),
    (re.compile(r"(?<= )->(?= )"), r"$\\to$"),
    (re.compile(r"(?<!\\)\btheta\\_([xyz])\b"), r"$\\theta_\1$"),
    (re.compile(r"(?<!\\)\btheta\b"), r"$\\theta$"),
    (re.compile(r"(?<!\\)\brho\b"), r"$\\rho$"),
    (re.compile(r"\bsigma\\_r\b"), r"$\\sigma_r$"),
    (re.compile(r"\bt([xyz])\b"), r"$t_\1$"),
    (re.compile(r"\b1e\+0?(\d+)\b"), r"$10^{\1}$"),
    (re.compile(r"(?<=\d)e\+0?(\d+)\b"), r"$\\times10^{\1}$"),
    (re.compile(r"(?<=\d) %"), r"\\,\\%"),
    (re.compile(r"\\\^\{\}(-?[0-9.]*[0-9])"), r"$^{\1}$"),
    (re.compile(r"\bus\b"), r"\\textmu s"),
]


def prose_tex(text: str) -> str:
    """Generated plain text as LaTeX prose: escaped, with typography (``+-`` as ±,
    ``theta`` as θ, ``1e+06`` as 10⁶, ``tx`` as t_x, ``10 arcsec`` as 10″)."""
    out = latex_escape(no_nan_text(" ".join(str(text).split())))
    out = out.replace(r"\%", "%")
    for pat, rep in _PROSE:
        out = pat.sub(rep, out)
    out = re.sub(r"(?<!\\)%", r"\\%", out)
    return out


# ------------------------------------------------------------ paper A, Table 1 on one page
#: the A-T1 variants shown as column groups (those present, in this order); the CSV has all
TABLE1_GROUPS = ("literal", "roll", "roll+squarem", "roll+growing+squarem")


#: at most this many column groups (published and each variant: t_x, t_y, error after) side by
#: side; more are stacked in a second panel below, so the table prints at its own size
TABLE1_GROUPS_PER_PANEL = 3


def table1_grouped_latex(t1: pd.DataFrame, groups: Iterable[str] = TABLE1_GROUPS,
                         per_panel: int = TABLE1_GROUPS_PER_PANEL) -> str:
    """Paper A's Table 1 as LaTeX: a row per case, the published values and each variant as a
    column group (t_x, t_y in arcsec, navigation error after compensation in km); a variant's
    cell is marked where its run did not converge (the A-T1 label). Groups beyond
    ``per_panel`` go into further panels stacked below, each repeating the case and truth
    columns, so the table keeps its font size instead of being shrunk to the page."""
    import pandas as pd

    groups = [g for g in groups if (t1["variant"] == g).any()]
    cases = list(dict.fromkeys(t1.loc[t1["variant"] == groups[0], "case_id"])) if groups else []
    by = {(r["variant"], r["case_id"]): r for _, r in t1.iterrows()}

    def num(x, f="{:.1f}"):
        if x is None or pd.isna(x):
            return MISSING
        t = f.format(float(x))
        return t[1:] if t.startswith("-") and float(t) == 0 else t  # no "-0.0"

    def cells(group, c):
        if group is None:  # published
            p = by[(groups[0], c)]
            return [num(p["pub_est_x_mean"], "{:g}"), num(p["pub_est_y_mean"], "{:g}"),
                    num(p["pub_nav_err_after_km"], "{:g}")]
        r = by.get((group, c))
        if r is None:
            return [MISSING] * 3
        lab = str(r.get("label", "converged" if str(r.get("stalled")).lower() != "true" else "stalled"))
        mark = "" if lab == "converged" else r"$^\dagger$"
        return [num(r["est_x_mean"]) + mark, num(r["est_y_mean"]) + mark, num(r["nav_err_after_km"])]

    blocks = [None, *groups]
    panels = [blocks[i:i + per_panel] for i in range(0, len(blocks), per_panel)] or [[None]]
    out = []
    for panel in panels:
        cols = "ll" + "rrr" * len(panel)
        names = ["published" if g is None else latex_escape(g) for g in panel]
        head1 = ["", ""] + [rf"\multicolumn{{3}}{{c}}{{{n}}}" for n in names]
        rules = "".join(rf"\cmidrule(lr){{{3 + 3 * i}-{5 + 3 * i}}}" for i in range(len(panel)))
        head2 = ["case", "truth"] + [r"$t_x$", r"$t_y$", "after"] * len(panel)
        lines = [rf"\begin{{tabular}}{{@{{}}{cols}@{{}}}}", r"\toprule", " & ".join(head1) + r" \\", rules,
                 " & ".join(head2) + r" \\", r"\midrule"]
        for c in cases:
            p = by[(groups[0], c)]
            row = [c, f"{num(p['truth_x_arcsec'], '{:g}')}, {num(p['truth_y_arcsec'], '{:g}')}"]
            for g in panel:
                row += cells(g, c)
            lines.append(" & ".join(row) + r" \\")
        lines += [r"\bottomrule", r"\end{tabular}"]
        out.append("\n".join(lines))
    return "\n\n\\medskip\n".join(out) + "\n"


def in_pdf(path: str | Path, drop_variants: Iterable[str]) -> bool:
    """Whether a generated float goes into the PDF: not the variants listed (their outputs
    stay in results/ and the HTML report), not a parameter study's table (its figure
    shows it; the CSV holds the numbers), not A-T1 (shown as one grouped table)."""
    p = Path(path)
    stem = p.stem
    if output_id(p) == "A-T1":
        return False
    if p.suffix == ".tex" and "studies" in p.parts:
        return False
    if "studies" in p.parts:  # a study's name is not a variant (the "prior" study)
        return True
    return not any(stem.endswith("_" + v) for v in drop_variants)


def format_sci(x: float) -> str:
    """A number for prose in scientific form: ``1e6`` -> ``$10^{6}$``, ``2.5e5`` -> ``$2.5\\times10^{5}$``."""
    x = float(x)
    if x == 0 or not math.isfinite(x):
        return format_number(x)
    e = math.floor(math.log10(abs(x)))
    m = x / 10 ** e
    ms = f"{m:.3g}"
    return f"$10^{{{e}}}$" if ms == "1" else f"${ms}\\times10^{{{e}}}$"


# ------------------------------------------------------------ the claims table in LaTeX

def claims_glance_latex(df: pd.DataFrame) -> str:
    """The at-a-glance table as a LaTeX tabular (wrapping text columns, one row per claim)."""
    from opnav.report.claims import VERDICT_SHORT

    lines = [(r"\begin{tabular}{@{}l>{\raggedright\arraybackslash}p{0.38\linewidth}"
             r">{\raggedright\arraybackslash}p{0.16\linewidth}>{\raggedright\arraybackslash}p{0.25\linewidth}"
             r">{\raggedright\arraybackslash}p{0.1\linewidth}@{}}"), r"\toprule",
             r"id & claim & published & ours, as written & verdict \\", r"\midrule"]
    for i, r in enumerate(df.itertuples()):
        if i and r.paper != df.iloc[i - 1]["paper"]:
            lines.append(r"\midrule")
        lines.append(" & ".join([r.claim_id, prose_tex(r.claim), prose_tex(r.published), prose_tex(r.ours_as_written),
                                 r"\textit{" + prose_tex(VERDICT_SHORT[r.verdict]) + "}"]) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines) + "\n"


#: the claims table's columns in the PDF's words (Table 1 and Appendix A), for readers of the
#: HTML report and of the landing page; a column not named here reads with spaces for "_"
CLAIM_COLUMN_WORDS = {
    "paper": "paper", "claim_id": "id", "claim": "claim", "published": "published",
    "ours_as_written": "ours, as written", "ours_best": "ours, best faithful variant",
    "best_variant": "best faithful variant", "bound": "bound", "ours_replication": "ours, replication sample",
    "verdict": "verdict", "verdict_replication": "verdict, replication sample", "flags": "flags",
    "named": "the addition or choice", "would_take": "what it would take", "cause": "cause",
    "evidence": "evidence", "sample": "sample",
}


def claims_for_readers(df: pd.DataFrame) -> pd.DataFrame:
    """The claims table in the PDF's words: its column names as Table 1 and Appendix A say
    them and every verdict (any column whose name starts with ``verdict``) as Table 1 prints
    it (``not_reproducible`` -> ``not reproducible``); cells otherwise unchanged."""
    from opnav.report.claims import VERDICT_SHORT

    out = df.copy()
    for c in out.columns:
        if str(c).startswith("verdict"):
            out[c] = out[c].map(lambda v: VERDICT_SHORT.get(v, v) if isinstance(v, str) else v)
    return out.rename(columns=lambda c: CLAIM_COLUMN_WORDS.get(str(c), str(c).replace("_", " ")))


def claims_detail_latex(df: pd.DataFrame) -> str:
    """Every claim with all its columns, as a LaTeX description list (the claims table in full)."""
    from opnav.report.claims import VERDICT_TEXT

    out = [r"\begin{description}\setlength{\itemsep}{2pt}"]
    for r in df.itertuples():
        parts = [rf"\item[{r.claim_id}] {prose_tex(r.claim)}. \textit{{{prose_tex(sentence(VERDICT_TEXT[r.verdict])[:-1])}}}"
                 + (f" ({prose_tex(r.named)})" if r.named else "") + "."]
        # one short sentence each (issue 55 item 4): published, ours, the best reading, the bound
        parts.append(f"Published: {prose_tex(r.published)}. Ours as written: {prose_tex(r.ours_as_written) or '--'}.")
        if r.best_variant:
            parts.append(f"Best faithful reading, {prose_tex(r.best_variant)}: {prose_tex(r.ours_best)}.")
        if r.bound:
            parts.append(f"Bound: {prose_tex(r.bound)}.")
        parts.append(prose_tex(r.cause) + f" \\emph{{Evidence:}} {prose_tex(r.evidence)}.")
        out.append(" ".join(parts))
    out.append(r"\end{description}")
    return "\n".join(out) + "\n"


# ------------------------------------------------------------ sentences from table cells
# (also used by opnav.report.claims_prose and opnav.report.readme)
def cell_text(r: Mapping, key: str) -> str:
    """A claims-table cell as text: stripped, '' for a missing key, None or NaN."""
    v = r.get(key, "")
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) or str(v) == "nan" else str(v).strip()


def sentence(text: str) -> str:
    """``text`` as one sentence: white space folded, a capital first letter, one closing period."""
    text = " ".join(text.split()).rstrip(" .;")
    return (text[0].upper() + text[1:] + ".") if text else ""


# ------------------------------------------------------------ page 1: the run's cost
def snakemake_jobs(metadata_dir: str | Path, results_dir: str | Path,
                   workdir: str | Path = ".") -> list[tuple[str, float, float]]:
    """``(rule, start, end)`` (Unix seconds) of every finished job that wrote a file under
    ``results_dir`` that is still there (paths relative to ``workdir``), from Snakemake's own
    records (``.snakemake/metadata``: one JSON per output, named by the output's path in URL-safe
    base64, cut into ``@``-prefixed parts when long). A job with several outputs counts once;
    unreadable records are skipped."""
    import base64
    import json

    root = Path(metadata_dir)
    prefix = Path(results_dir).as_posix().rstrip("/") + "/"
    jobs: dict[tuple, tuple[str, float, float]] = {}
    if not root.is_dir():
        return []
    for f in root.rglob("*"):
        if not f.is_file():
            continue
        try:
            name = "".join(part.lstrip("@") for part in f.relative_to(root).parts)
            path = base64.urlsafe_b64decode(name.encode()).decode()
            rec = json.loads(f.read_text())
        except (ValueError, UnicodeDecodeError, OSError):
            continue
        start, end = rec.get("starttime"), rec.get("endtime")
        if not path.startswith(prefix) or rec.get("incomplete") or start is None or end is None:
            continue
        if not (Path(workdir) / path).exists():  # a record of a file this build no longer makes
            continue
        # one job's outputs share its hash and end time (their start times differ by microseconds)
        key = (str(rec.get("rule", "")), rec.get("job_hash"), round(float(end), 3))
        old = jobs.get(key)
        jobs[key] = (key[0], min(float(start), old[1]) if old else float(start), float(end))
    return sorted(jobs.values(), key=lambda j: (j[1], j[0]))


def busy_wall_s(jobs: Iterable[tuple[str, float, float]]) -> float:
    """The wall time during which at least one of ``jobs`` ran: the length of the union of
    their [start, end] intervals, so a pause between two invocations of a build counts
    nothing and jobs that ran side by side count once."""
    total, cur = 0.0, None
    for _, a, b in sorted(jobs, key=lambda j: j[1]):
        if cur is None or a > cur[1]:
            total += (cur[1] - cur[0]) if cur else 0.0
            cur = [a, b]
        else:
            cur[1] = max(cur[1], b)
    return total + ((cur[1] - cur[0]) if cur else 0.0)


def machine_text() -> str:
    """This machine in a few words: CPU model (Linux's /proc/cpuinfo, else the platform's
    processor name), logical cores and memory."""
    import os
    import platform

    model = ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    model = " ".join((model or platform.processor() or platform.machine() or "unknown CPU").split())
    cores = os.cpu_count()
    try:
        mem_gb = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2 ** 30
    except (ValueError, OSError, AttributeError):
        mem_gb = float("nan")
    parts = [f"{cores} logical cores" if cores else "", f"{mem_gb:.0f} GB memory" if math.isfinite(mem_gb) else ""]
    return f"{model} ({', '.join(p for p in parts if p)})" if any(parts) else model


def _minutes(s: float) -> str:
    return f"{s / 60:.1f} min" if s >= 60 else f"{s:.0f} s"


def run_info_tex(bench_tables: Iterable[pd.DataFrame], machine: str,
                 jobs: Iterable[tuple[str, float, float]] = ()) -> str:
    r"""``\RunInfo``: where and how long this build ran. The build's wall time is the time at
    least one of its jobs was running (:func:`busy_wall_s` over Snakemake's records of the
    jobs up to the manuscript); the heavy jobs' (Monte Carlos, bounds, timing) job time and
    CPU time are the sums of their Snakemake benchmark files (wall seconds ``s``,
    ``cpu_time``). Job times add up jobs that ran side by side, so they can exceed the wall time."""
    jobs = list(jobs)
    wall = cpu = 0.0
    n = 0
    for t in bench_tables:
        if len(t):
            wall += float(t["s"].iloc[-1])
            cpu += float(t["cpu_time"].iloc[-1]) if "cpu_time" in t else 0.0
            n += 1
    sentences = []
    if jobs:
        sentences.append(f"This build ran on {machine}: its {len(jobs)} jobs up to the manuscript took "
                         f"{_minutes(busy_wall_s(jobs))} of wall time (Snakemake's records; pauses between runs left out).")
    else:
        sentences.append(f"This build ran on {machine}.")
    if n:
        sentences.append(f"The {n} heavy jobs (Monte Carlos, bounds, timing) took {_minutes(wall)} of job time "
                         f"and {cpu / 60:.1f} CPU-min (their benchmark files; jobs side by side add up).")
    sentences.append("Measured times per profile and machine: docs/run-times.md.")
    return "\\newcommand{\\RunInfo}{" + prose_tex(" ".join(sentences)) + "}\n"


# ------------------------------------------------------------ tables legible at print size
#: a header wraps at this many characters a line; a table wider than TRANSPOSE_COLS columns
#: with fewer than half as many rows is printed transposed (a row per quantity)
HEADER_WRAP = 14
TRANSPOSE_COLS = 9


def _cell_tex(x: Any, float_format: str = "{:.4g}") -> str:
    if isinstance(x, float):
        return MISSING if not math.isfinite(x) else float_format.format(x)
    if is_missing(x):
        return MISSING
    return latex_escape(str(x))


def _header_tex(text: str, width: int = HEADER_WRAP) -> str:
    """A header cell wrapped onto short lines (a narrow column for short numbers)."""
    import textwrap

    lines = textwrap.wrap(str(text), width) or [""]
    if len(lines) == 1:
        return latex_escape(lines[0])
    return r"\begin{tabular}[b]{@{}l@{}}" + r" \\ {}".join(latex_escape(line) for line in lines) + r"\end{tabular}"


def legible_view(df: pd.DataFrame) -> pd.DataFrame:
    """The table as printed: transposed (first column as the header row, a row per
    quantity) when it is much wider than long, else as it is."""
    if df.shape[1] > TRANSPOSE_COLS and len(df) * 2 < df.shape[1] and len(df):
        first = df.columns[0]
        t = df.set_index(first).T.reset_index()
        t.columns = [str(first) if i == 0 else str(c) for i, c in enumerate(t.columns)]
        return t.rename(columns={t.columns[0]: ""})
    return df


def _key_columns(df: pd.DataFrame) -> int:
    """How many leading columns name a row (text columns, at most two): repeated in every part."""
    n = 0
    for c in df.columns[:2]:
        if df[c].map(lambda x: isinstance(x, str)).all():
            n += 1
        else:
            break
    return max(n, 1)


#: the text width a table may take, in characters of the table font (the manuscript's tables
#: are set in \\footnotesize, 8 pt: about 4.1 pt a character, on a 484 pt line) and the
#: space a column adds (\\tabcolsep both sides), in characters
LINE_CHARS = 112
COLUMN_GAP_CHARS = 2


def _cell_lines(x: Any) -> list[str]:
    return _cell_tex(x).split("\x00")


def _wrapped_cell(x: Any, width: int) -> Any:
    """A text cell cut onto lines of at most ``width`` characters (words kept whole), the
    lines joined by a marker :func:`_tabular` sets as stacked lines."""
    import textwrap

    if not isinstance(x, str) or len(x) <= width or " " not in x:
        return x
    return "\x00".join(textwrap.wrap(x, width, break_long_words=False))


def _col_chars(v: pd.DataFrame, c: Any) -> int:
    """A column's printed width in characters: its widest header line or cell line."""
    import textwrap

    def plain(x):  # the cell as printed, before LaTeX escapes
        if isinstance(x, float):
            return MISSING if not math.isfinite(x) else f"{x:.4g}"
        return MISSING if is_missing(x) else str(x)

    head = max((len(line) for line in textwrap.wrap(str(c), HEADER_WRAP)), default=0)
    cells = max((len(line) for x in v[c] for line in plain(x).split("\x00")), default=0)
    return max(head, cells, 1)


def _width_chars(v: pd.DataFrame) -> int:
    return sum(_col_chars(v, c) for c in v.columns) + COLUMN_GAP_CHARS * v.shape[1]


def _prose_cell(x: Any) -> bool:
    """A cell of words (which may wrap), not a number, interval or mean +- spread (which may not)."""
    return isinstance(x, str) and " " in x.strip() and re.search(r"[A-Za-z]{3}", x) is not None


def fit_text_columns(v: pd.DataFrame, line_chars: int = LINE_CHARS, min_wrap: int = 12) -> pd.DataFrame:
    """The table with its widest text columns wrapped onto more lines, widest first, until it
    fits ``line_chars`` or no text column can narrow further (numbers are never wrapped)."""
    v = v.copy()
    while _width_chars(v) > line_chars:
        text = [c for c in v.columns if v[c].map(_prose_cell).any()]
        widths = {c: _col_chars(v, c) for c in text}
        wide = [c for c in text if widths[c] > min_wrap]
        if not wide:
            break
        c = max(wide, key=lambda k: widths[k])
        target = max(min_wrap, widths[c] - (_width_chars(v) - line_chars), (widths[c] * 2) // 3)
        trial = v.copy()
        trial[c] = v[c].map(lambda x: _wrapped_cell(x.replace("\x00", " "), target) if isinstance(x, str) else x)
        if _col_chars(trial, c) >= widths[c]:
            break  # a word as long as the column: it cannot narrow
        v = trial
    return v


def _tabular(v: pd.DataFrame) -> str:
    def cell(x):
        lines = _cell_lines(x)
        if len(lines) == 1:
            return lines[0]
        return r"\begin{tabular}[t]{@{}l@{}}" + r" \\ {}".join(lines) + r"\end{tabular}"  # {}: a line may open with [

    lines = [r"\begin{tabular}{@{}" + "l" * v.shape[1] + "@{}}", r"\toprule",
             " & ".join(_header_tex(c) for c in v.columns) + r" \\", r"\midrule"]
    for row in v.itertuples(index=False):
        lines.append(" & ".join(cell(x) for x in row) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines)


def legible_latex(df: pd.DataFrame, max_cols: int = 7, line_chars: int = LINE_CHARS) -> str:
    """A booktabs tabular for the manuscript that stays legible at print size: headers wrapped
    onto short lines, wide-and-short tables transposed (:func:`legible_view`), long text cells
    wrapped until the table fits the line (:func:`fit_text_columns`), and a table still wider
    than ``max_cols`` columns or than the line split into stacked parts that repeat the
    columns naming a row."""
    v = fit_text_columns(legible_view(df), line_chars)
    if v.shape[1] <= max_cols and _width_chars(v) <= line_chars:
        return _tabular(v) + "\n"
    k = _key_columns(v)
    key, rest = list(v.columns[:k]), list(v.columns[k:])
    parts, cur = [], []
    for c in rest:  # greedy: as many columns a part as fit the line and max_cols
        if cur and (len(key) + len(cur) + 1 > max_cols or _width_chars(v[key + cur + [c]]) > line_chars):
            parts.append(cur)
            cur = []
        cur.append(c)
    parts.append(cur)
    tabs = [_tabular(v[key + p]) for p in parts if p]
    return (r"\begin{tabular}{@{}l@{}}" + "\n" + "\\\\[6pt]\n".join(tabs) + "\n" + r"\end{tabular}" + "\n")


# ------------------------------------------------------------ appendix: the analysis plan and the inputs
_CJK = re.compile(r"[\u2e80-\u9fff\uff00-\uffef\u3000-\u303f]+")


def latin_text(text: str) -> str:
    """A plan sentence for a Latin-script PDF: a Chinese original is replaced by its
    parenthesised English rendering where the plan gives one (else a pointer to the CSV);
    the double prime as arcsec."""
    text = str(text).replace("\u2033", " arcsec")
    if not _CJK.search(text):
        return text
    m = re.search(r"\(([^()]*[A-Za-z][^()]*)\)", text)
    rest = _CJK.sub(" ", text[m.end():] if m else "").strip(" ,;")
    head = m.group(1) if m else "original in Chinese, see analysis_plan.csv"
    return head + (f", {rest}" if rest and _CJK.search(rest) is None else "")


def _margin_reasons(margin: str, reasons: str) -> list[tuple[str, str]]:
    """``[(name = value, reason)]`` from the plan table's ``margin`` ('a = 1; b = 2') and
    ``margin_reason`` ('a: why; b: why') cells."""
    parts = [m.strip() for m in margin.split("; ") if m.strip()]
    names = [m.split(" = ")[0] for m in parts]
    cuts = sorted((reasons.find(f"{n}: "), n) for n in names if reasons.find(f"{n}: ") >= 0)
    why = {}
    for k, (i, n) in enumerate(cuts):
        j = cuts[k + 1][0] if k + 1 < len(cuts) else len(reasons)
        why[n] = reasons[i + len(n) + 2:j].strip().rstrip(";").strip()
    return [(m, why.get(n, "")) for m, n in zip(parts, names)]


def plan_latex(plan: pd.DataFrame) -> str:
    """The analysis plan (results/paper/analysis_plan.csv) as a LaTeX description list, one
    item per claim, in short sentences: the paper's sentence and where, what is compared and
    how, each margin with its reason, the variants and controls, what the verdict depends on."""
    from opnav.core import wording

    def said(text: str) -> str:
        return prose_tex(sentence(wording.shorten(text, wording.MAX_SENTENCE_WORDS)))

    out = [r"\begin{description}\setlength{\itemsep}{2pt}"]
    for r in plan.to_dict("records"):
        c = {k: latin_text(cell_text(r, k)) for k in r}
        where = f" ({c['where']})" if c.get("where") else ""
        s = rf"\item[{latex_escape(c.get('claim_id', ''))}] " + prose_tex(
            sentence(c.get("sentence", "").rstrip(" .") + where))
        parts = [f"Compared: {c.get('quantity', '')}" + (f" ({c['units']})" if c.get("units") else "")
                 + (f", by {c['comparison']}" if c.get("comparison") else "")]
        parts += [f"Margin {m}" + (f": {why}" if why else "") for m, why in
                  _margin_reasons(c.get("margin", ""), c.get("margin_reason", ""))]
        parts += [f"Variants: {c['variants']}" if c.get("variants") else "",
                  f"Controls: {c['controls']}" if c.get("controls") else "",
                  f"Depends on: {c['depends_on']}" if c.get("depends_on") else ""]
        s += " " + " ".join(said(p) for p in parts if p)
        out.append(s)
    out.append(r"\end{description}")
    return "\n".join(out) + "\n"


def inputs_latex(inputs: pd.DataFrame) -> str:
    """The inputs we derive (results/paper/inputs.csv) as a description list."""
    out = [r"\begin{description}\setlength{\itemsep}{2pt}"]
    for r in inputs.to_dict("records"):
        c = {k: latin_text(cell_text(r, k)) for k in r}
        out.append(rf"\item[{prose_tex(c.get('input', ''))}] "
                   + prose_tex(f"Ours {c.get('ours', '')}; published {c.get('published', '')}. "
                               f"How we derive it: {c.get('how_derived', '')}. "
                               f"What would match: {c.get('what_would_match', '')}."))
    out.append(r"\end{description}")
    return "\n".join(out) + "\n"
