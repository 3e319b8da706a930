"""Generated manuscript pieces: macro names, number formatting, floats, captions."""

from pathlib import Path

from hypothesis import given, strategies as st

from opnav.report.manuscript import (float_block, format_number, macro_name, macros_from_summary,
                              render_macros, rst_to_latex)


@given(st.lists(st.text(min_size=1, max_size=12), min_size=1, max_size=4))
def test_macro_names_are_letters_only(parts):
    parts = ["A"] + parts
    assert macro_name(parts).isalpha()


def test_macros_flatten_and_format():
    m = macros_from_summary({"literal": {"est_x": 11.4321, "n_seeds": 20, "note": "a_b"},
                             "crlb": [1.5, 250.0]}, "A")
    assert m["ALiteralEstX"] == "11.43"
    assert m["ALiteralNSeeds"] == "20"
    assert m["ALiteralNote"] == r"a\_b"
    assert m["ACrlbOne"] == "1.5" and m["ACrlbTwo"] == "250"
    text = render_macros(m)
    assert text.splitlines() == sorted(text.splitlines())
    assert r"\newcommand{\ALiteralEstX}{11.43}" in text


def test_format_number_ranges():
    assert format_number(79.06) == "79.06"
    assert format_number(18.43) == "18.43"
    assert format_number(50.0) == "50"
    assert format_number(1234.5) == "1{,}234"
    assert format_number(0.0123) == "0.0123"
    assert format_number(2.5e-6) == r"2.50\times10^{-6}"
    assert format_number(float("nan")) == "--"


def test_rst_caption_to_latex():
    assert rst_to_latex("Error in *km*, ``theta_x`` 50%") == r"Error in \emph{km}, \texttt{theta\_x} 50\%"


def test_float_block_uses_caption_and_relative_path(tmp_path: Path):
    caps = tmp_path / "report"
    caps.mkdir()
    (caps / "A-F4.rst").write_text("Bias estimate vs iteration, arcsec.\n")
    fig = tmp_path / "results" / "approach" / "A-F4_bias_estimate_roll.pdf"
    tex = float_block([fig], caps, relative_to=tmp_path / "paper")
    assert "../results/approach/A-F4_bias_estimate_roll.pdf" in tex
    assert "Bias estimate vs iteration, arcsec." in tex
    assert "A-F4 (bias estimate roll)" in tex


def test_every_file_the_manuscript_names_exists():
    """Paths in \\texttt{...} are files of the repository (or of results/,
    which the pipeline writes): no pointer to a file a reader cannot open."""
    import re

    from conftest import REPO

    named = set()
    for tex in (REPO / "paper").rglob("*.tex"):
        named |= set(re.findall(r"\\texttt\{([^}\\]*/[^}\\]*|[^}\\]*\.(?:md|py|yaml|lock|cff))\}",
                                tex.read_text()))
    assert named, "no file names found: the pattern is broken"
    missing = [n for n in sorted(named) if not n.startswith("results/") and not (REPO / n).exists()]
    assert missing == []


def test_no_nan_text_reaches_the_manuscript():
    """Missing values read as a dash, whatever their type: macros, compact views, tables."""
    import re

    import numpy as np
    import pandas as pd

    from opnav.report.manuscript import COMPACT_VIEWS, macros_from_summary, render_macros
    from opnav.core.tables import to_latex, to_markdown

    nanword = re.compile(r"(?<![A-Za-z])(nan|inf|<NA>)(?![A-Za-z])", re.IGNORECASE)
    summary = {"a": float("nan"), "b": np.float32("nan"), "c": "nan", "d": [None, np.nan],
               "e": "best: nan m", "f": np.float64(2.5), "g": np.int64(3), "h": float("inf")}
    text = render_macros(macros_from_summary(summary, "T"))
    assert not nanword.search(text), text
    assert r"\newcommand{\TF}{2.5}" in text and r"\newcommand{\TG}{3}" in text
    row = {"method": "depth", "rank_accuracy": 1, "rank_time": np.nan, "rms_pos_err_m_mean": np.nan,
           "rms_pos_err_m_3sigma": np.nan, "final_pos_err_m_mean": 3.0, "final_pos_err_m_3sigma": np.inf,
           "mean_nees_pos": pd.NA, "median_plan_time_us": np.float32("nan")}
    for _, df in COMPACT_VIEWS["B-X1"](pd.DataFrame([row])):
        for out in (to_latex(df), to_markdown(df)):
            assert not nanword.search(out), out
    df = pd.DataFrame({"x": [1.0, np.nan, np.inf], "s": ["a", None, "b"]})
    for out in (to_latex(df), to_markdown(df)):
        assert not nanword.search(out), out


def test_prose_typography():
    from opnav.report.manuscript import prose_tex

    t = prose_tex("tx = 1.2 +- 0.3 arcsec, theta from 1e+06 km, rho*theta, 29 % less, 5 us, rate^-0.99, a_b")
    assert r"$t_x$" in t and r"$\pm$" in t and r"1.2" in t and r"0.3\arcsec{}" in t
    assert r"$\theta$" in t and r"$10^{6}$" in t and r"$\rho\theta$" in t
    assert r"29\,\%" in t and r"\textmu s" in t and r"$^{-0.99}$" in t and r"a\_b" in t
    assert "+-" not in t and "theta" not in t.replace(r"\theta", "")
    # a component subscript stays a subscript (the plan's "theta_x" printed as theta\_x)
    assert prose_tex("larger of theta_x and theta_y") == r"larger of $\theta_x$ and $\theta_y$"


def test_table1_grouped_has_one_column_group_per_variant_and_marks_unconverged():
    import pandas as pd

    from opnav.report.manuscript import table1_grouped_latex

    rows = []
    for v, lab in (("literal", "converged"), ("roll", "stalled")):
        for c in ("T1-01", "T1-02"):
            rows.append({"variant": v, "case_id": c, "truth_x_arcsec": 10, "truth_y_arcsec": 20,
                         "pub_est_x_mean": 11.43, "pub_est_y_mean": 21.21, "pub_nav_err_after_km": 18.43,
                         "est_x_mean": -0.01, "est_y_mean": 19.9, "nav_err_after_km": 100.0, "label": lab})
    tex = table1_grouped_latex(pd.DataFrame(rows), groups=("literal", "roll", "absent"))
    assert r"\multicolumn{3}{c}{literal}" in tex and r"\multicolumn{3}{c}{roll}" in tex and "absent" not in tex
    body = [line for line in tex.splitlines() if line.startswith("T1-01")][0]
    assert body.count(r"$^\dagger$") == 2  # roll's t_x and t_y, not literal's
    assert "-0.0" not in tex and "11.43" in tex


def test_table1_stacks_groups_in_panels_that_repeat_the_case_columns():
    """Issue 55 item 2: paper A's Table 1 with four variants beside the published values (15
    number columns, printed at 4.2 pt when shrunk to the page) is set as panels of at most
    three groups, each repeating the case and truth: it prints at its own size."""
    import pandas as pd

    from opnav.report.manuscript import TABLE1_GROUPS, table1_grouped_latex

    rows = [{"variant": v, "case_id": c, "truth_x_arcsec": 10, "truth_y_arcsec": 20, "pub_est_x_mean": 11.43,
             "pub_est_y_mean": 21.21, "pub_nav_err_after_km": 18.43, "est_x_mean": 1.0, "est_y_mean": 2.0,
             "nav_err_after_km": 100.0, "label": "converged"} for v in TABLE1_GROUPS for c in ("T1-01", "T1-02")]
    tex = table1_grouped_latex(pd.DataFrame(rows))
    panels = tex.split(r"\begin{tabular}")[1:]
    assert len(panels) == 2
    for p in panels:
        assert p.count(r"\multicolumn{3}") <= 3 and "case & truth" in p and "T1-02 & 10, 20" in p
    assert all(rf"\multicolumn{{3}}{{c}}{{{g}}}" in tex for g in ("published", *TABLE1_GROUPS))


def test_pdf_selection_drops_variants_not_studies():
    from opnav.report.manuscript import in_pdf

    drop = ["prior", "reference-start"]
    assert in_pdf("results/approach/A-F4_bias_estimate_literal.pdf", drop)
    assert not in_pdf("results/approach/A-F4_bias_estimate_prior.pdf", drop)
    assert in_pdf("results/studies/prior/A-X5_prior.pdf", drop)       # the 'prior' study stays
    assert not in_pdf("results/studies/prior/A-X5_prior.tex", drop)   # a study's table: CSV only
    assert not in_pdf("results/approach/A-T1_table1.tex", drop)       # shown grouped


def test_tables_are_printed_legibly():
    """Issue 45 item 3: a wide, short table is transposed (a row per quantity); a wide, long
    one is split into stacked parts that repeat the columns naming a row; headers wrap."""
    import pandas as pd

    from opnav.report.manuscript import legible_latex

    short = pd.DataFrame({"method": ["depth", "svd"], **{f"quantity number {i} (m)": [1.0, 2.0] for i in range(12)}})
    tex = legible_latex(short)
    head, body = tex.split(r"\midrule")
    assert tex.count(r"\begin{tabular}{@{}lll@{}}") == 1 and "depth & svd" in head  # methods became columns
    assert "quantity number 0 (m) & 1 & 2" in body  # a row per quantity
    long = pd.DataFrame({"variant": ["a"] * 20, "method": [f"m{i}" for i in range(20)],
                         **{f"a rather long header {i}": range(20) for i in range(10)}})
    tex = legible_latex(long, max_cols=7)
    parts = tex.split(r"\toprule")[1:]
    assert len(parts) == 2 and all("variant & method" in p for p in parts)  # key columns in each part
    assert r"\begin{tabular}[b]{@{}l@{}}a rather long \\ {}header 0\end{tabular}" in tex  # a wrapped header


def test_wide_text_tables_wrap_their_words_then_split_by_width():
    """Issue 55 item 2: a table whose text cells are long wraps them (never a number, interval
    or mean +- spread) and, still wider than the line, splits into parts that each fit it."""
    import re

    import pandas as pd

    from opnav.report import manuscript as M

    df = pd.DataFrame({"variant": ["literal", "roll"],
                       "estimator": ["Basilisk pixelLineBiasUKF square-root filter", "augmented EKF"],
                       "run": ["prior mean at the truth (diagnostic)", "headline case"],
                       **{f"quantity {i} (arcsec)": ["0.000364 ± 0.00497", "0.0268 [-0.00848, 0.0551]"]
                          for i in range(4)}})
    tex = M.legible_latex(df)
    assert r"Basilisk \\ {}" in tex or r"Basilisk pixelLineBiasUKF \\ {}" in tex  # words wrapped
    assert "0.0268 [-0.00848, 0.0551]" in tex and "0.000364 ± 0.00497" in tex      # numbers whole
    parts = tex.split(r"\toprule")[1:]
    assert len(parts) >= 2
    fitted = M.fit_text_columns(M.legible_view(df))
    for p in parts:  # each part fits the line
        heads = re.findall(r"quantity \d", p.split(r"\midrule")[0])
        cols = ["variant", "estimator", "run"] + [c for c in df.columns if c[:10] in heads]
        assert M._width_chars(fitted[[c for c in cols if c in fitted.columns]]) <= M.LINE_CHARS, cols


def test_a_float_takes_the_most_specific_caption_its_rule_gives():
    """B-F7's overhead curve printed B-F7's box-plot caption in the final full build's PDF (Fig. 28):
    the float looked up ``<ID>.rst`` only, while its rule gives the HTML report
    ``B-F7.overhead.rst``. Mutation tried once: the ``<ID>.<part>.rst`` candidates removed fails it."""
    from opnav.report.manuscript import caption_file, caption_path

    caps = Path(__file__).resolve().parents[1] / "workflow" / "report"
    assert caption_path("results/landing/B-F7_overhead_interior.pdf", caps).name == "B-F7.overhead.rst"
    assert caption_path("results/landing/B-F7_interior.pdf", caps).name == "B-F7.rst"
    assert caption_path("results/landing/B-X1_ranking_interior.tex", caps).name == "B-X1.table.rst"
    assert caption_path("results/landing/B-X1_envelopes_interior.pdf", caps).name == "B-X1.rst"
    assert caption_path("results/approach/A-F4_bias_estimate_roll.pdf", caps).name == "A-F4.rst"
    assert caption_path("results/studies/Z-X9_nothing.pdf", caps) is None
    assert caption_file("results/landing/B-F7_overhead_site-tilt.pdf", caps).name == "B-F7.overhead.rst"
