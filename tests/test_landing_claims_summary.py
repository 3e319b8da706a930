"""Paper B's typed boundary to the report layer (issue 41 item 4): the claims read
B-summary.json through LandingSummary / ScenarioClaims, by meaning."""

import math

import pytest
from test_claims import PUB, summary_b

from opnav.landing.claims_summary import Interval, LandingSummary, ScenarioClaims
from opnav.report import claims as C
from opnav.report.landing_claims import claim_rows, input_rows


def test_the_headline_scenario_comes_first_and_an_older_summary_is_one_scenario():
    s = summary_b()
    s["headline_scenario"] = "site-tilt"
    ls = LandingSummary.from_json(s)
    assert ls.headline == "site-tilt" and [x.name for x in ls.scenarios] == ["site-tilt", "interior"]
    assert (ls.initial_tilt_deg, ls.initial_azimuth_deg) == (9.8, 16.5)
    one = LandingSummary.from_json({**summary_b()["scenarios"]["interior"], "scenario": "interior"})
    assert one.headline == "interior" and len(one.scenarios) == 1 and one.initial_tilt_deg is None


def test_paired_intervals_from_the_equivalence_section_or_the_pair_table_either_way_round():
    """The equivalence section when it holds the pair; else B-T3's pair table, read the other
    way round (reference first) with the sign and the interval's ends swapped, beside the
    reference's mean. Mutation: negating without swapping lo and hi, or taking the
    reference mean from the method, fails."""
    s = ScenarioClaims.from_json("x", summary_b()["scenarios"]["interior"])
    eq = s.paired("depth", "svd")
    assert eq["lastlm_pos_err_m"] == Interval(0.0, -0.005, 0.005, 0.4)
    fwd = s.paired("depth", "gdop")
    assert fwd["rms_pos_err_m"] == pytest.approx((0.0, -0.01, 0.01, 3.0))
    pairs = {"gdop_vs_depth": {"d_rms_pos_m": 1.0, "d_rms_pos_lo_m": 0.5, "d_rms_pos_hi_m": 2.0,
                               "d_final_pos_m": 0.1, "d_final_pos_lo_m": 0.0, "d_final_pos_hi_m": 0.3}}
    rev = ScenarioClaims.from_json("x", {"methods": {"gdop": {"rms_pos_err_m_mean": 7.0}}, "pairs": pairs})
    iv = rev.paired("depth", "gdop")
    assert iv["rms_pos_err_m"] == Interval(-1.0, -2.0, -0.5, 7.0)
    assert math.isnan(iv["final_pos_err_m"].reference_mean)  # gdop's row has no touchdown mean
    assert rev.paired("depth", "cond") is None and math.isnan(rev.same_pick_pct("depth"))


def test_the_claims_refuse_an_untyped_summary_and_read_the_typed_one():
    """Mutation: accepting the dict again fails; the typed summary gives every claim."""
    with pytest.raises(TypeError, match="LandingSummary"):
        claim_rows(summary_b(), PUB["paper_b"], C.load_plan())
    with pytest.raises(TypeError, match="LandingSummary"):
        input_rows(summary_b(), PUB["paper_b"], C.load_plan())
    rows = claim_rows(LandingSummary.from_json(summary_b()), PUB["paper_b"], C.load_plan())
    assert [r["claim_id"] for r in rows] == ["B-C1", "B-C2", "B-C3", "B-C4", "B-C7", "B-C8", "B-C9", "B-C10"]
