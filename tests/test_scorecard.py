"""The scorecard's tolerance rule, checked on hand-made cases."""

import math

from hypothesis import given, strategies as st

from opnav.report.scorecard import (NOT_REPRODUCED, NOT_REPRODUCIBLE, REPRODUCED, judge, score_rows,
                             tolerance)


def test_within_spread_is_reproduced():
    assert judge(11.43, 11.0, spread=0.5).verdict == REPRODUCED        # 0.43 <= 2*0.5


def test_outside_band_is_not_reproduced():
    v = judge(18.43, 40.0, spread=2.0, unit="km")
    assert v.verdict == NOT_REPRODUCED and "km" in v.reason


def test_published_accuracy_below_crlb_is_not_reproducible():
    # truth 10", published 11.43" (error 1.43"), our CRLB 1-sigma 30": no estimator can promise that
    v = judge(11.43, 25.0, spread=30.0 / 10, truth=10.0, crlb=30.0, unit="arcsec")
    assert v.verdict == NOT_REPRODUCIBLE


def test_relative_floor():
    assert math.isclose(tolerance(100.0, 0.0), 10.0)
    assert judge(100.0, 109.0, spread=0.0).verdict == REPRODUCED
    assert judge(100.0, 111.0, spread=0.0).verdict == NOT_REPRODUCED


@given(st.floats(-1e3, 1e3), st.floats(0, 1e2), st.floats(0, 1e2))
def test_verdict_is_symmetric_in_the_difference(pub, spread, delta):
    a = judge(pub, pub + delta, spread=spread).verdict
    b = judge(pub, pub - delta, spread=spread).verdict
    assert a == b


def test_score_rows_keeps_prejudged_claims():
    df = score_rows([
        {"paper": "B", "item": "claim", "published": float("nan"), "ours": float("nan"),
         "verdict": REPRODUCED, "reason": "depth within 10 % of best baseline"},
        {"paper": "A", "item": "x", "published": 1.0, "ours": 1.05, "spread": 0.0},
    ])
    assert list(df["verdict"]) == [REPRODUCED, REPRODUCED]
    assert math.isclose(df.loc[1, "difference"], 0.05)


def test_rows_paper_a_pairs_pub_columns_and_uses_crlb():
    import pandas as pd

    from opnav.approach.summaries import HeadlineSummary
    from opnav.report.approach_scorecard import rows_paper_a

    t1 = pd.DataFrame([{
        "variant": "literal", "case_id": "T1-01", "truth_x_arcsec": 10.0, "truth_y_arcsec": 20.0,
        "est_x_mean": 0.1, "est_x_std": 0.2, "est_y_mean": 19.0, "est_y_std": 1.5,
        "crlb_x_arcsec": 20.0, "crlb_y_arcsec": 20.0, "nav_err_after_km": 18.0, "nav_err_after_km_std": 1.0,
        "tz_observable": False,
        "pub_est_x_mean": 11.43, "pub_est_y_mean": 21.21, "pub_nav_err_after_km": 18.43,
    }])
    df = score_rows(rows_paper_a(t1, HeadlineSummary.from_json({}), {"headline": {"tz_estimable": False}}))
    v = dict(zip(df["item"], df["verdict"]))
    assert v["T1 literal T1-01: est_x"] == NOT_REPRODUCIBLE   # 1.43" published error < CRLB 20"
    assert v["T1 literal T1-01: est_y"] == REPRODUCED         # |19 - 21.21| = 2.21 <= 2 * 1.5
    assert v["T1 literal T1-01: nav_err_after_km"] == REPRODUCED
    assert v["claim: tz (roll about the boresight) cannot be estimated"] == REPRODUCED


def test_rows_paper_b_timing():
    import pandas as pd

    from opnav.landing.bsummary import BSummary
    from opnav.report.landing.summary import rows_paper_b

    t3 = pd.DataFrame([
        {"method": "depth", "time_reduction_vs_svd_pct": 80.0, "rms_pos_err_m_mean": 100.0},
        {"method": "svd", "time_reduction_vs_svd_pct": float("nan"), "rms_pos_err_m_mean": 130.0},
    ])
    df = score_rows(rows_paper_b(t3, BSummary.from_json({}), {"depth_time_reduction_vs_svd_pct": 29.03}))
    assert df.loc[0, "verdict"] == NOT_REPRODUCED                 # 80 % vs 29.03 %


def test_wide_band_does_not_count_as_reproduced():
    # 30.9 +- 11.9 "contains" 11.43 only because the runs scatter widely
    v = judge(11.43, 30.94, spread=11.93, unit="arcsec")
    assert v.verdict == NOT_REPRODUCED and "wide" in v.reason


def test_rows_paper_b_per_scenario_from_the_summary():
    import pandas as pd

    from opnav.landing.bsummary import BSummary
    from opnav.report.landing.summary import rows_paper_b

    def methods(pick):
        return {"depth": {"method": "depth", "time_reduction_vs_svd_pct": 30.0, "rms_pos_err_m_mean": 100.0,
                          "rms_vel_err_mps_mean": 1.0, "d_rms_pos_vs_svd_lo_m": -5.0,
                          "d_rms_pos_vs_svd_hi_m": 4.0},
                "svd": {"method": "svd", "time_reduction_vs_svd_pct": float("nan"),
                        "rms_pos_err_m_mean": 101.0, "rms_vel_err_mps_mean": 1.0,
                        "same_pick_as_depth_pct": pick}}

    def accuracy(pick, ctrl_ok):
        eq = {"reference": "svd", "margin_rel": 0.1,
              "metrics": {q: {"margin": 0.5} for q in ("lastlm_pos_err_m", "lmrms_pos_err_m")},
              "methods": {"depth": {"equivalent": True, "verdict": "equivalent", "same_pick_pct": pick,
                                    "text": "depth vs svd: equivalent", "lastlm_pos_err_m": {"mean": 0.1}},
                          "random": {"equivalent": ctrl_ok, "verdict": "equivalent" if ctrl_ok else "not equivalent"}}}
        return {"equivalence": eq, "controls": ["random"], "controls_equivalent": ["random"] if ctrl_ok else [],
                "same_pick_max_pct": 90.0,
                "converges_faster": {"depth": {"mean_s": -1.5, "verdict": "faster", "text": "faster",
                                               "min_difference_s": 1.0}}}

    summary = {"scenarios": {"site-tilt": {"methods": methods(99.9), **accuracy(99.9, False)},
                             "interior": {"methods": methods(40.0), **accuracy(40.0, False)},
                             "open": {"methods": methods(40.0), **accuracy(40.0, True)}},
               "initial_tilt_deg": 9.2, "initial_azimuth_deg": 16.5}
    pub = {"depth_time_reduction_vs_svd_pct": 29.03, "table1_initial_state": {"att_deg": [-25.7, -9.8, 0.0]}}
    df = score_rows(rows_paper_b(pd.DataFrame(), BSummary.from_json(summary), pub)).set_index("item")
    item = "depth vs svd: 'almost the same' accuracy (paired equivalence, negative controls)"
    assert df.loc[f"[site-tilt] {item}", "verdict"] == NOT_REPRODUCED     # the same picks: not tested
    assert df.loc[f"[interior] {item}", "verdict"] == REPRODUCED
    # a control passes too: the claim holds, the test cannot credit the metric (as the claims table)
    assert df.loc[f"[open] {item}", "verdict"] == REPRODUCED
    assert "cannot credit the metric" in df.loc[f"[open] {item}", "reason"]
    assert df.loc["[interior] position error converges a bit faster with depth than svd", "verdict"] == REPRODUCED
    assert df.loc["initial thrust tilt from the vertical (paper: -pitch)", "verdict"] == REPRODUCED
    assert df.loc["initial thrust azimuth (paper: -yaw)", "verdict"] == NOT_REPRODUCED


def test_a_stalled_em_row_says_so_in_the_reason_and_never_converged():
    import pandas as pd

    from opnav.report.approach.text import reading_text
    from opnav.approach.summaries import HeadlineSummary
    from opnav.report.approach_scorecard import rows_paper_a

    base = {"variant": "roll", "case_id": "T1-01", "truth_x_arcsec": 10.0, "truth_y_arcsec": 20.0,
            "est_x_mean": 0.02, "est_x_std": 0.002, "crlb_x_arcsec": 8.2, "crlb_y_arcsec": 8.2,
            "data_to_converge_samples": float("nan"), "dist_to_ml_arcsec": 16.6, "n_seeds": 20,
            "pub_est_x_mean": 11.43, "pub_data_to_converge_samples": 250.0}
    for label in ("stalled", "converged"):
        reading = reading_text(label, {label: 20}, 20, 8.2, 2.0, 16.6 if label == "stalled" else 0.0, 0.999)
        t1 = pd.DataFrame([{**base, "label": label, "stalled": label == "stalled", "reading": reading}])
        df = score_rows(rows_paper_a(t1, HeadlineSummary.from_json({}), {}))
        reasons = dict(zip(df["item"], df["reason"]))
        stalled = label == "stalled"
        assert ("stalled (20/20)" in reasons["T1 roll T1-01: est_x"]) is stalled
        assert ("16.6 arcsec from the ML" in reasons["T1 roll T1-01: data_to_converge_samples"]) is stalled
        assert ("not identifiable from this data (bound 8.2 arcsec)" in reasons["T1 roll T1-01: est_x"]) is not stalled
        assert dict(zip(df["item"], df["verdict"]))["T1 roll T1-01: data_to_converge_samples"] != REPRODUCED


def test_timing_rows_take_the_plans_band():
    """Paper B's timing rows are judged with the band the workflow passes (the analysis
    plan's B-C4 rel_tol / spread_k / max_band_rel), not only the module's defaults: a
    reduction 4 points off 29.03 % fails with 10 % and passes with 20 % (dropping the band
    in score_rows fails this: tried once)."""
    import pandas as pd

    from opnav.landing.bsummary import BSummary
    from opnav.report.landing.summary import rows_paper_b
    from opnav.report.claims import load_plan

    t3 = pd.DataFrame([{"method": "depth", "time_reduction_vs_svd_pct": 25.0, "time_reduction_vs_svd_pct_std": 0.5}])
    pub = {"depth_time_reduction_vs_svd_pct": 29.03}
    plan = load_plan()
    band = {"rel_tol": plan.margin("B-C4", "rel_tol"), "k_spread": plan.margin("B-C4", "spread_k"),
            "max_band_rel": plan.margin("B-C4", "max_band_rel")}
    item = "median planning time, depth vs SVD: reduction"
    assert score_rows(rows_paper_b(t3, BSummary.from_json({}), pub, band)).set_index("item").loc[item, "verdict"] == NOT_REPRODUCED
    wide = score_rows(rows_paper_b(t3, BSummary.from_json({}), pub, {**band, "rel_tol": 0.2})).set_index("item")
    assert wide.loc[item, "verdict"] == REPRODUCED and "within tolerance 5.81" in wide.loc[item, "reason"]
    # a spread wider than the plan's max_band_rel reads 'wide', with the plan's k in the reason
    t3w = t3.assign(time_reduction_vs_svd_pct_std=4.0)
    r = score_rows(rows_paper_b(t3w, BSummary.from_json({}), pub, {**band, "max_band_rel": 0.2})).set_index("item").loc[item]
    assert r["verdict"] == NOT_REPRODUCED and f"{band['k_spread']:g} sd = 8" in r["reason"]


def test_the_timing_row_reads_the_spread_between_replays_not_one_replays_bootstrap():
    """With the summary's planning_time block the scorecard's timing row is the mean of the
    replays with their sd between them (18, 24, 30 %: sd 6, 2 sd = 12 points holds 29.03 %);
    B-T3's bootstrap sd of one replay (0.5) would read it not reproduced (mutation tried once)."""
    import pandas as pd

    from opnav.landing.bsummary import BSummary
    from opnav.report.landing.summary import rows_paper_b

    t3 = pd.DataFrame([{"method": "depth", "time_reduction_vs_svd_pct": 24.0, "time_reduction_vs_svd_pct_std": 0.5}])
    pub = {"depth_time_reduction_vs_svd_pct": 29.03}
    band = {"rel_tol": 0.1, "k_spread": 2.0, "max_band_rel": 0.5}
    summ = {"planning_time": {"reduction_pct": {"depth_vs_svd": {"per_replay": [18.0, 24.0, 30.0], "mean": 24.0,
                                                                "sd_between": 6.0, "interval": "between_replays"}}}}
    df = score_rows(rows_paper_b(t3, BSummary.from_json(summ), pub, band))
    row = df[df["item"].str.contains("mean of 3 replays")].iloc[0]
    assert row["verdict"] == REPRODUCED and row["ours (spread)"] == 6.0
    assert score_rows(rows_paper_b(t3, BSummary.from_json({}), pub, band)).iloc[0]["verdict"] == NOT_REPRODUCED
