"""The scorecard's tolerance rule, checked on hand-made cases."""

import math

from hypothesis import given, strategies as st

from opnav.scorecard import (NOT_REPRODUCED, NOT_REPRODUCIBLE, REPRODUCED, judge, score_rows,
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
