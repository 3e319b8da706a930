"""Paper A's typed boundary to the report layer (issue 41 item 4): the report reads
A-summary.json's headline rows (HeadlineSummary) and A-X2 per method (MethodSummary) by
meaning, and makes the words (scheme, column names, method labels) itself."""

import math

import numpy as np
import pandas as pd
import pytest
from test_approach_pipeline import TARGET, _summary_row, approach_setup

from opnav.approach.alternatives_summary import (
    method_summaries,
    summary_json,
)
from opnav.approach.summaries import HeadlineSummary
from opnav.core import published
from opnav.report import approach_text
from opnav.report.approach_scorecard import rows_paper_a
from opnav.report.approach.text import METHOD_LABELS
from opnav.report.approach_views import x2_table


def _row(scenario, method="plain", mode="sliding", label="converged"):
    return {**_summary_row(scenario, (1.0, 2.0), 3.0, label), "method": method, "mode": mode}


def test_headline_rows_are_read_by_scenario_method_and_mode_not_by_their_key():
    """The scheme words come from method and mode, the paper's rows from
    ``as_written_scheme``: keys that say nothing change no sentence but the row's own.
    Mutation: findings parsing the scheme from the key (k[len(scenario):]) or picking
    the paper's rows by key == scenario fails."""
    summ = {"prior_bound_arcsec": 21.0, "variants": {
        "row-a": _row("literal"), "row-b": _row("literal", "squarem", "growing", label="stalled"),
        "row-c": _row("roll", "squarem")}}
    hs = HeadlineSummary.from_json(summ)
    assert [r.key for r in hs.rows] == ["row-a", "row-b", "row-c"]
    assert [r.as_written_scheme for r in hs.rows] == [True, False, False]
    txt = approach_text.findings(approach_setup(), hs, published.paper_a()["headline"], TARGET)
    assert "Plain EM, sliding windows: converged in literal. Growing squarem: stalled in literal. " \
           "Squarem: converged in roll." in txt["stall"]
    assert "3 arcsec (literal), against" in txt["bound"]  # the paper's scheme only
    assert {k for k in txt if k.startswith("headline_")} == {"headline_row-a", "headline_row-b", "headline_row-c"}


def test_the_report_refuses_an_untyped_summary():
    """Mutation: accepting the dict again (the label-keyed boundary) fails."""
    with pytest.raises(TypeError, match="HeadlineSummary"):
        approach_text.findings(approach_setup(), {"variants": {}}, {}, TARGET)
    with pytest.raises(TypeError, match="HeadlineSummary"):
        rows_paper_a(pd.DataFrame(), {}, {})


def test_a_x2_per_method_numbers_and_the_reports_table():
    """A-X2 per variant and method: headline-case values from T1-01 (NaN and no label
    without it), aggregates over every case; the page table and A-X2-summary.json read the
    same fields. Mutation: the RMS over cases as a mean, or sd and mean swapped, fails."""
    rows = []
    for case, rmse, sd in (("T1-01", 3.0, 0.5), ("T1-02", 4.0, 1.5)):
        for m in ("em_plain", "augmented"):
            if m == "augmented" and case == "T1-01":
                continue
            rows.append({"variant": "literal", "method": m, "case_id": case, "n_seeds": 4,
                         "err_x_mean_arcsec": 1.0, "err_x_std_arcsec": sd, "err_y_mean_arcsec": 2.0,
                         "err_y_std_arcsec": sd, "rmse_xy_arcsec": rmse, "crlb_x_arcsec": 5.0, "crlb_y_arcsec": 6.0,
                         "crlb_q0_x_arcsec": 4.0, "crlb_all_x_arcsec": 0.5, "nav_err_after_km": 10.0,
                         "data_to_converge_samples": 250.0, "runtime_s_per_seed": 0.1,
                         "label": "converged" if m == "em_plain" else math.nan})
    long = pd.DataFrame(rows)
    ms = method_summaries(long)
    em, aug = ms
    assert (em.method, em.n_cases, em.head_err_x_sd_arcsec, em.head_label) == ("em_plain", 2, 0.5, "converged")
    assert em.rmse_xy_all_arcsec == pytest.approx(math.sqrt((9 + 16) / 2))
    assert em.median_sd_all_arcsec == 1.0 and em.median_crlb_all_arcsec == 5.5
    assert math.isnan(aug.head_err_x_mean_arcsec) and aug.head_label == "" and aug.n_cases == 1
    table = x2_table(ms)
    assert list(table["method"]) == [METHOD_LABELS["em_plain"], METHOD_LABELS["augmented"]]
    assert table.loc[0, "T1-01 err_x sd"] == 0.5 and table.loc[0, "T1-01 err_x mean"] == 1.0
    summ = summary_json(long, ms, approach_setup())
    assert summ.variants["literal"]["em_plain"].rmse_xy_all_cases_arcsec == em.rmse_xy_all_arcsec
    assert np.isnan(summ.variants["literal"]["augmented"].err_x_mean_arcsec)
