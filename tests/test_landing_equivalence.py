"""Paper B's accuracy claims as tests that can fail (opnav.landing.equivalence):
the paired TOST against scipy, the equivalence verdict with negative controls on
hand-made runs, the time-to-threshold rule, the landmark phase, the NEES band,
the closest picker and the vision cut-off on filter quantities only."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs
from scipy import stats

from opnav.landing import equivalence as eqv
from opnav.landing.montecarlo import landmark_phase, nees_band, phase_rms, time_below


@settings(max_examples=40, deadline=None)
@given(hs.integers(3, 60), hs.floats(-2.0, 2.0), hs.floats(0.05, 3.0), hs.integers(0, 2**31 - 1))
def test_tost_is_two_one_sided_t_tests(n, shift, margin, seed):
    d = np.random.default_rng(seed).normal(shift, 1.0, n)
    r = eqv.tost(d, margin, alpha=0.05)
    p_lo = stats.ttest_1samp(d, -margin, alternative="greater").pvalue
    p_hi = stats.ttest_1samp(d, margin, alternative="less").pvalue
    assert r["p"] == pytest.approx(max(p_lo, p_hi), rel=1e-8, abs=1e-12)
    assert r["equivalent"] == (max(p_lo, p_hi) < 0.05)
    # the same decision as the 90 % interval inside the margin
    lo, hi = stats.t.interval(0.90, n - 1, loc=d.mean(), scale=stats.sem(d))
    assert (r["lo"], r["hi"]) == pytest.approx((lo, hi), rel=1e-9, abs=1e-12)
    if abs(lo + margin) > 1e-9 and abs(hi - margin) > 1e-9:
        assert r["equivalent"] == (lo > -margin and hi < margin)


def test_tost_never_equivalent_without_a_margin():
    assert not eqv.tost(np.zeros(10), 0.0)["equivalent"]
    assert eqv.tost(np.full(10, 0.1), 0.2)["equivalent"]       # zero spread, inside
    assert not eqv.tost(np.full(10, 0.3), 0.2)["equivalent"]


def _runs(seed=0, n=300):
    """Hand-made paired runs: depth and svd share most of each run's error; the
    controls are worse by about the selection effect (random) or by half of it
    (center, closest)."""
    rng = np.random.default_rng(seed)
    base = rng.gamma(2.0, 0.5, n)          # the run's own difficulty (m), shared
    phase = 200.0 + 60.0 * rng.standard_normal(n)

    def method(extra, sd):
        last = base + extra + sd * rng.standard_normal(n)
        return pd.DataFrame({"lastlm_pos_err_m": last,
                             "lmrms_pos_err_m": phase + 20 * extra + 20 * sd * rng.standard_normal(n),
                             "final_pos_err_m": 3 * last}, index=pd.Index(range(n), name="run"))

    return {"svd": method(0.0, 0.05), "depth": method(0.01, 0.05), "random": method(2.0, 0.5),
            "center": method(1.0, 0.3), "closest": method(0.8, 0.3)}


def test_controls_are_not_equivalent_and_a_real_pair_is():
    st = _runs()
    out = eqv.equivalence(st, "svd", ["depth", "random", "center", "closest"], margin_frac=0.25,
                          same_pick_pct={"depth": 40.0, "random": 0.1, "center": 2.0, "closest": 7.0})
    v = {m: r["verdict"] for m, r in out["methods"].items()}
    assert v == {"depth": "equivalent", "random": "not equivalent", "center": "not equivalent",
                 "closest": "not equivalent"}
    mg = out["metrics"]["lastlm_pos_err_m"]
    assert mg["best"] == ["svd"] and mg["margin"] == pytest.approx(0.25 * mg["gap"])
    assert mg["gap"] == pytest.approx(st["random"]["lastlm_pos_err_m"].mean()
                                      - st["svd"]["lastlm_pos_err_m"].mean())
    text = out["methods"]["depth"]["text"]
    assert "margin" in text and "last landmark update" in text and "40 %" in text
    # a wide margin (the whole gap and more) lets a control pass: the verdict moves
    wide = eqv.equivalence(st, "svd", ["closest"], margin_frac=1.0)
    assert wide["methods"]["closest"]["equivalent"]


def test_claim_not_reproduced_when_a_control_passes():
    from opnav.landing.report import same_accuracy_verdict
    from opnav.core.verdicts import NOT_REPRODUCED, REPRODUCED

    st = _runs()
    for frac, ok in ((0.25, REPRODUCED), (1.0, NOT_REPRODUCED)):
        eq = eqv.equivalence(st, "svd", ["depth", "random", "center", "closest"], frac,
                             same_pick_pct={"depth": 40.0})
        acc = {"equivalence": eq, "controls": ["random", "center", "closest"],
               "controls_equivalent": [c for c in ("random", "center", "closest")
                                       if eq["methods"][c]["equivalent"]]}
        v = same_accuracy_verdict(acc, "depth")
        assert v.verdict == ok, v.reason
        assert "random not equivalent" in v.reason or "cannot fail" in v.reason
    # the same picks in 95 % of the calls: not tested
    acc["equivalence"]["methods"]["depth"]["same_pick_pct"] = 95.0
    acc["controls_equivalent"] = []
    assert "not tested" in same_accuracy_verdict(acc, "depth").reason


def test_margin_is_zero_when_random_is_not_worse():
    m = eqv.margins({"svd": 1.0, "depth": 1.0, "random": 0.9}, 0.25)
    assert m["margin"] == 0.0 and m["best"] == ["random"]
    assert eqv.margins({"svd": 1.0, "depth": 1.0, "random": 2.0}, 0.25)["best"] == ["depth", "svd"]


def test_converges_faster_rule():
    rng = np.random.default_rng(1)
    tb = 10 + rng.uniform(0, 5, 200)
    fast = eqv.converges_faster(tb - 0.8 + 0.1 * rng.standard_normal(200), tb, "depth", "svd", 100.0)
    assert fast["verdict"] == "faster" and fast["hi_s"] < 0
    same = eqv.converges_faster(tb + 0.3 * rng.standard_normal(200), tb, "depth", "svd", 100.0)
    assert same["verdict"] == "no difference shown"
    ta = tb + 1.0
    ta[:50] = np.nan                       # runs that never get there are left out, counted
    slow = eqv.converges_faster(ta, tb, "depth", "svd", 100.0)
    assert slow["verdict"] == "slower" and slow["n_runs"] == 150


def test_landmark_phase_and_time_below():
    lm = np.zeros((2, 8), bool)
    lm[0, [2, 3, 5]] = True
    first, last = landmark_phase(lm)
    assert list(first) == [2, 0] and list(last) == [5, 0]
    nrm = np.arange(16, dtype=float).reshape(2, 8)
    assert phase_rms(nrm, first, last)[0] == pytest.approx(np.sqrt(np.mean(nrm[0, 2:6] ** 2)))
    err = np.zeros((2, 8, 3))
    err[0, :, 0] = [500, 300, 150, 90, 120, 80, 10, 5]
    err[1, :, 0] = 200
    t = np.arange(8.0)
    out = time_below({"err_r": err, "t": t}, 100.0)
    assert out[0] == 3.0 and np.isnan(out[1])


def test_nees_band_is_the_chi2_band_of_the_mean():
    lo, hi = nees_band(300, 3, 0.95)
    assert (lo, hi) == pytest.approx(tuple(stats.chi2.ppf([0.025, 0.975], 900) / 300), rel=1e-10)
    # a consistent filter's 300-run mean falls inside it ~95 % of the time
    rng = np.random.default_rng(0)
    m = rng.chisquare(3, size=(2000, 300)).mean(axis=1)
    assert 0.93 < np.mean((m >= lo) & (m <= hi)) < 0.97


def test_closest_picks_the_nearest_detected_landmark_by_range():
    from opnav.landing.landmarks import make_field
    from opnav.landing.planner import PICKERS, PlanState

    field = make_field(2000.0, 3000, seed=5)
    rng = np.random.default_rng(3)
    for _ in range(20):
        r = np.array([*rng.uniform(-500, 500, 2), rng.uniform(50, 800)])
        st = PlanState(r, np.zeros(3), np.zeros(3), np.eye(3), np.eye(12))
        cand = np.sort(rng.choice(len(field.xyz), 200, replace=False))
        k = PICKERS["closest"](field, cand, st, None, None)
        d = np.linalg.norm(field.xyz[cand] - r, axis=1)
        assert d[k] == d.min()
        # horizontal nearest is not the same thing (the range includes the altitude)
        assert k == int(np.argmin(d))


def test_near_site_field_follows_the_descent():
    from opnav.landing.landmarks import make_field

    plain = make_field(12000.0, 20000, seed=7)
    dense = make_field(12000.0, 20000, seed=7, near_site={"count": 5000, "r_min_m": 1.0})
    assert np.array_equal(dense.xyz[:20000], plain.xyz)        # the uniform part unchanged
    r = np.hypot(*dense.xyz[20000:, :2].T)
    for h in (10.0, 100.0, 1000.0):                             # ~ the same count per decade
        n = np.sum((r > h) & (r < 2 * h))
        assert 150 < n < 500, (h, n)
        assert np.sum(np.hypot(*plain.xyz[:, :2].T) < 2 * h) < (5 if h < 100 else 10**6)


def test_vision_cut_off_uses_the_estimate_never_the_truth():
    """Updates happen only where the filter's own cut-off quantity (estimated
    altitude less the margin, recorded per image) is above the limit; in the
    last metres the truth is still above the limit while the estimate-based
    quantity is not, so a cut-off on the true altitude would update there and
    fail this test."""
    from opnav.core.config import load_config
    from opnav.landing.descent import run_descents, vision_cutoff_altitude
    from opnav.landing.scenario import build_scenario, camera_scenarios

    cfg = camera_scenarios(load_config()["landing"])["interior"]
    scn = build_scenario(cfg)
    runs = run_descents(scn, "closest", [0, 1])
    lim = cfg["filter"]["min_update_altitude_m"]
    true_alt = scn.truth.r[:, 2]
    checked = 0
    for d in runs:
        cut = d["cut_alt_m"]
        assert not np.any(d["updated"][1:] & ~(cut[1:] > lim))
        stop = np.flatnonzero(~(cut[1:-1] > lim))[0] + 1
        # after the cut-off the truth is still above the limit (the margin) yet no update
        assert true_alt[stop] > lim and not d["updated"][stop:].any()
        checked += 1
        # the recorded quantity is the estimate less the margin, not the truth's
        est_alt = true_alt - d["err_r"][:, 2]
        assert not np.allclose(cut[1:], vision_cutoff_altitude(np.column_stack(
            [np.zeros((len(true_alt), 2)), true_alt]), scn.update_margin_m)[1:])
        assert np.all(np.isfinite(est_alt))
    assert checked == 2
