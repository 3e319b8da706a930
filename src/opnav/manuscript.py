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


#: What a missing value reads as in the manuscript (never "nan").
MISSING = "--"
_NAN_WORD = re.compile(r"(?<![A-Za-z])(?:nan|<NA>|NaT)(?![A-Za-z])", re.IGNORECASE)


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
def _pm(mean: float, spread: float, fmt: str = "{:.3g}") -> str:
    if is_missing(mean) or not math.isfinite(float(mean)):
        return MISSING
    if is_missing(spread) or not math.isfinite(float(spread)):
        return fmt.format(mean)
    return f"{fmt.format(mean)} ± {fmt.format(spread)}"


def _num(x: float, fmt: str = "{:.4g}") -> str:
    if is_missing(x) or (isinstance(x, numbers.Real) and not math.isfinite(float(x))):
        return MISSING
    return fmt.format(x)


def _stall_or(r, text: str) -> str:
    """'stalled (k/n)' for a row the stall rule flags (SPEC A.3c), else ``text``."""
    st = r.get("stalled")
    if isinstance(st, str):
        st = st.strip().lower() == "true"
    if st:
        return f"stalled ({_num(r.get('stalled_seeds'), '{:.0f}')}/{_num(r.get('n_seeds'), '{:.0f}')})"
    return text


def compact_a_t1(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """A-T1 for the page: one table per scenario variant, ours beside published.

    Estimates are mean ± standard deviation over the noise seeds (arcsec);
    navigation errors before / after compensation in km.
    """
    import pandas as pd

    out = []
    for variant, g in df.groupby("variant", sort=False):
        rows = []
        for _, r in g.iterrows():
            rows.append({
                "group": r.get("group", ""),
                "case": r["case_id"],
                'truth x, y (")': f"{_num(r['truth_x_arcsec'], '{:g}')}, {_num(r['truth_y_arcsec'], '{:g}')}",
                'est. x (")': _pm(r["est_x_mean"], r.get("est_x_std")),
                'est. y (")': _pm(r["est_y_mean"], r.get("est_y_std")),
                'CRLB x, y, data used (")': f"{_num(r['crlb_x_arcsec'], '{:.3g}')}, {_num(r['crlb_y_arcsec'], '{:.3g}')}",
                "data (samples)": _stall_or(r, _num(r["data_to_converge_samples"], "{:.0f}")),
                'to ML (")': _num(r.get("dist_to_ml_arcsec"), "{:.3g}"),
                "nav. before / after (km)": f"{_num(r['nav_err_before_km'], '{:.1f}')} / {_num(r['nav_err_after_km'], '{:.1f}')}",
                'published est. x, y (")': f"{_num(r.get('pub_est_x_mean'), '{:g}')}, {_num(r.get('pub_est_y_mean'), '{:g}')}",
                "published data": _num(r.get("pub_data_to_converge_samples"), "{:.0f}"),
                "published nav. (km)": f"{_num(r.get('pub_nav_err_before_km'), '{:g}')} / {_num(r.get('pub_nav_err_after_km'), '{:g}')}",
            })
        out.append((str(variant), pd.DataFrame(rows)))
    return out


def compact_b_t3(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """B-T3 for the page: per method final/RMS errors (mean, 3-sigma), NEES, timing."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        row = {"method": r["method"]}
        for q, unit in (("pos", "m"), ("vel", "mps"), ("att", "deg")):
            u = {"mps": "m/s"}.get(unit, unit)
            row[f"final {q} ({u})"] = _pm(r[f"final_{q}_err_{unit}_mean"], r[f"final_{q}_err_{unit}_3sigma"])
            row[f"RMS {q} ({u})"] = _pm(r[f"rms_{q}_err_{unit}_mean"], r[f"rms_{q}_err_{unit}_3sigma"])
        if "mean_nees_pos" in df.columns:
            row["NEES pos, vel"] = f"{_num(r['mean_nees_pos'], '{:.2f}')}, {_num(r.get('mean_nees_vel'), '{:.2f}')}"
        row["median plan (µs)"] = _num(r["median_plan_time_us"], "{:.0f}")
        if "metric_evals_per_call" in df.columns:
            row["evals/call"] = _num(r["metric_evals_per_call"], "{:.0f}")
        red = r.get("time_reduction_vs_svd_pct")
        row["time vs SVD (%)"] = "--" if red is None or pd.isna(red) else f"{-float(red):+.1f}"
        rows.append(row)
    return [("", pd.DataFrame(rows))]


#: Manuscript views of tables too wide for a page, by SPEC id.
COMPACT_VIEWS = {"A-T1": compact_a_t1, "B-T3": compact_b_t3}


def compact_a_x1(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """A-X1 for the page: CRLB per variant beside the EM and ML estimates' RMS error."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"],
            'CRLB x, 1 segment (")': _num(r.get("crlb_x_window_arcsec"), "{:.3g}"),
            'CRLB x, all data (")': _num(r.get("crlb_x_total_arcsec"), "{:.3g}"),
            "reaches 2\"": "yes" if bool(r.get("bound_reaches_target")) else "no",
            'EM plain RMSE x (")': _num(r.get("em_plain_rmse_x_arcsec"), "{:.3g}"),
            'EM SQUAREM RMSE x (")': _num(r.get("em_squarem_rmse_x_arcsec"), "{:.3g}"),
            'ML RMSE x (")': _num(r.get("mle_rmse_x_arcsec"), "{:.3g}"),
            "EM maps plain / SQUAREM": f"{_num(r.get('maps_plain_median'), '{:.0f}')} / {_num(r.get('maps_squarem_median'), '{:.0f}')}",
        })
    return [("", pd.DataFrame(rows))]


COMPACT_VIEWS["A-X1"] = compact_a_x1


def compact_a_x2(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """A-X2 for the page: EM-EKF vs augmented EKF vs batch ML, headline case and all cases."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"], "method": r["method"],
            'T1-01 error x (")': _pm(r.get("T1-01 err_x mean"), r.get("T1-01 err_x sd")),
            'T1-01 error y (")': _pm(r.get("T1-01 err_y mean"), r.get("T1-01 err_y sd")),
            'CRLB x (")': _num(r.get("T1-01 CRLB_x"), "{:.3g}"),
            'RMSE all cases (")': _num(r.get("RMSE_xy all cases"), "{:.3g}"),
            "nav. after (km)": _num(r.get("nav err after km (T1-01)"), "{:.1f}"),
            "data (samples)": _num(r.get("data needed (T1-01)"), "{:.0f}"),
            "time (s/seed)": _num(r.get("run time s/seed (T1-01)"), "{:.3f}"),
        })
    return [("", pd.DataFrame(rows))]


def compact_a_x3(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """A-X3 for the page: estimate spread and error against the CRLB over the swept value."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"], str(r.get("sweep", "value")): _num(r["value"], "{:g}"),
            "estimator": r["estimator"],
            'sd x (")': _num(r.get("sd_x_arcsec"), "{:.3g}"),
            'RMSE x (")': _num(r.get("rmse_x_arcsec"), "{:.3g}"),
            'CRLB x (")': _num(r.get("crlb_x_arcsec"), "{:.3g}"),
            "sd / CRLB": _num(r.get("sd_over_crlb_x"), "{:.3g}"),
        })
    return [("", pd.DataFrame(rows))]


def compact_b_x1(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """B-X1 for the page: every selection rule ranked, paired difference against depth."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        lo, hi = r.get("d_rms_pos_vs_ref_boot_lo"), r.get("d_rms_pos_vs_ref_boot_hi")
        rows.append({
            "method": r["method"],
            "rank acc., time": f"{_num(r.get('rank_accuracy'), '{:.0f}')}, {_num(r.get('rank_time'), '{:.0f}')}",
            "RMS pos (m)": _pm(r.get("rms_pos_err_m_mean"), r.get("rms_pos_err_m_3sigma")),
            "final pos (m)": _pm(r.get("final_pos_err_m_mean"), r.get("final_pos_err_m_3sigma")),
            "final vel (m/s)": _pm(r.get("final_vel_err_mps_mean"), r.get("final_vel_err_mps_3sigma")),
            "NEES pos": _num(r.get("mean_nees_pos"), "{:.2f}"),
            "median plan (µs)": _num(r.get("median_plan_time_us"), "{:.0f}"),
            "RMS pos minus depth (m), 95 % CI": f"{_num(r.get('d_rms_pos_vs_ref_mean'), '{:.3g}')} [{_num(lo, '{:.3g}')}, {_num(hi, '{:.3g}')}]",
            "same pick (%)": _num(r.get("same_pick_as_ref_pct"), "{:.1f}"),
        })
    return [("", pd.DataFrame(rows))]


COMPACT_VIEWS.update({"A-X2": compact_a_x2, "A-X3": compact_a_x3, "B-X1": compact_b_x1})


def compact_a_p1(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """A-P1 for the page: the peer UKF beside the paper's estimators, estimate, own 3-sigma, bound."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"], "estimator": r["estimator"], "run": r["run"],
            'tx (")': _pm(r.get("est_x_mean_arcsec"), r.get("est_x_sd_arcsec")),
            'ty (")': _pm(r.get("est_y_mean_arcsec"), r.get("est_y_sd_arcsec")),
            'own 3-sigma x (")': _num(r.get("own_3sigma_x_arcsec"), "{:.3g}"),
            "truth in own 3-sigma": str(r.get("within_own_3sigma_text", "--")),
            '3 CRLB x (")': _num(r.get("crlb_3sigma_x_arcsec"), "{:.3g}"),
        })
    return [("", pd.DataFrame(rows))]


COMPACT_VIEWS["A-P1"] = compact_a_p1
