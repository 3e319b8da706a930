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
    assert r.p == pytest.approx(max(p_lo, p_hi), rel=1e-8, abs=1e-12)
    assert r.equivalent == (max(p_lo, p_hi) < 0.05)
    # the same decision as the 90 % interval inside the margin
    lo, hi = stats.t.interval(0.90, n - 1, loc=d.mean(), scale=stats.sem(d))
    assert (r.lo, r.hi) == pytest.approx((lo, hi), rel=1e-9, abs=1e-12)
    if abs(lo + margin) > 1e-9 and abs(hi - margin) > 1e-9:
        assert r.equivalent == (lo > -margin and hi < margin)


def test_tost_never_equivalent_without_a_margin():
    assert not eqv.tost(np.zeros(10), 0.0).equivalent
    assert eqv.tost(np.full(10, 0.1), 0.2).equivalent       # zero spread, inside
    assert not eqv.tost(np.full(10, 0.3), 0.2).equivalent


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


#: B-C1's margin_rel in the analysis plan (data/analysis_plan.yaml), as the workflow passes it
def _plan_rel():
    from opnav.report.claims import load_plan

    return load_plan().margin("B-C1", "margin_rel")


def test_controls_are_not_equivalent_and_a_real_pair_is():
    st = _runs()
    rel = _plan_rel()
    out = eqv.equivalence(st, "svd", ["depth", "random", "center", "closest"], margin_rel=rel,
                          same_pick_pct={"depth": 40.0, "random": 0.1, "center": 2.0, "closest": 7.0})
    v = {m: r.verdict for m, r in out.methods.items()}
    assert v == {"depth": "equivalent", "random": "not equivalent", "center": "not equivalent",
                 "closest": "not equivalent"}
    for q in eqv.PRIMARY_METRICS:
        mg = out.metrics[q]
        assert mg.best == ["svd"] and mg.margin == pytest.approx(rel * st["svd"][q].mean())
    from opnav.report.landing.equivalence_text import equivalence_text

    text = equivalence_text("depth", out)
    assert "margin" in text and "last landmark update" in text and "40 %" in text
    assert f"{rel:g} x svd's mean error" in text
    # a wide margin (the baseline's whole mean error) lets a control pass: the verdict moves
    wide = eqv.equivalence(st, "svd", ["closest"], margin_rel=1.0)
    assert wide.methods["closest"].equivalent


def test_margin_does_not_come_from_the_controls_runs():
    """The margin is the plan's fraction of the reference's mean, whatever the other
    methods flew: making random 50 m worse moves no margin and no verdict (the former
    0.25 x (random's mean - best mean) rule widens the margin to ~12 m and passes
    closest and center)."""
    st = _runs()
    rel = _plan_rel()
    tested = ["depth", "center", "closest"]
    a = eqv.equivalence(st, "svd", tested, margin_rel=rel)
    b = eqv.equivalence({**st, "random": st["random"] + 50.0}, "svd", tested, margin_rel=rel)
    for q in eqv.PRIMARY_METRICS:
        assert b.metrics[q].margin == a.metrics[q].margin == pytest.approx(rel * st["svd"][q].mean())
    assert {m: r.equivalent for m, r in b.methods.items()} == {"depth": True, "center": False,
                                                                      "closest": False}


def _accuracy(st, pick_max, same_pick=40.0):
    eq = eqv.equivalence(st, "svd", ["depth", "random", "center", "closest"], _plan_rel(),
                         same_pick_pct={"depth": same_pick})
    from opnav.core.tables import json_ready

    return {"equivalence": json_ready(eq), "controls": ["random", "center", "closest"], "same_pick_max_pct": pick_max,
            "controls_equivalent": [c for c in ("random", "center", "closest") if eq.methods[c].equivalent]}


def test_claim_reproduced_and_flagged_when_a_control_passes():
    """As the claims table reads B-C1: a control that meets the margin too leaves the
    claim reproduced and the reason says the test cannot credit the metric."""
    from opnav.core.verdicts import NOT_REPRODUCED, REPRODUCED
    from opnav.landing.bsummary import ScenarioSummary
    from opnav.report.landing.summary import same_accuracy_verdict

    st = _runs()
    acc = _accuracy(st, 90.0)
    v = same_accuracy_verdict(ScenarioSummary.from_json(acc), "depth")
    assert v.verdict == REPRODUCED and "cannot credit" not in v.reason and "random not equivalent" in v.reason
    near = {**st, "closest": st["svd"] + 0.001 * (st["closest"] - st["svd"])}    # a control as good as svd
    acc = _accuracy(near, 90.0)
    assert acc["controls_equivalent"] == ["closest"]
    v = same_accuracy_verdict(ScenarioSummary.from_json(acc), "depth")
    assert v.verdict == REPRODUCED and "closest pass it too, so the test cannot credit" in v.reason
    worse = {**near, "depth": st["closest"]}                                     # depth fails, the control passes
    assert same_accuracy_verdict(ScenarioSummary.from_json(_accuracy(worse, 90.0)), "depth").verdict == NOT_REPRODUCED


def test_same_pick_threshold_is_the_recorded_plan_number():
    """The not-tested threshold is the one the summary records (the plan's B-C1
    same_pick_max_pct), not a number in code: 92 % same picks are tested under 95 and
    not under 90 (a threshold fixed at 90 in code fails the first)."""
    from opnav.landing.bsummary import ScenarioSummary
    from opnav.report.landing.summary import same_accuracy_verdict

    st = _runs()
    assert "not tested" not in same_accuracy_verdict(ScenarioSummary.from_json(_accuracy(st, 95.0, 92.0)), "depth").reason
    assert "not tested (same pick >= 90 %)" in same_accuracy_verdict(ScenarioSummary.from_json(_accuracy(st, 90.0, 92.0)), "depth").reason
    acc = _accuracy(st, 90.0)
    del acc["same_pick_max_pct"]
    with pytest.raises(ValueError, match="same_pick_max_pct"):
        same_accuracy_verdict(ScenarioSummary.from_json(acc), "depth")


def test_margin_is_zero_when_the_reference_error_is_not_positive():
    m = eqv.margins({"svd": 0.0, "depth": 1.0, "random": 0.9}, "svd", 0.1)
    assert m.margin == 0.0 and m.best == ["svd"]
    m = eqv.margins({"svd": 2.0, "depth": 1.0, "random": 0.5}, "svd", 0.1)    # random better: no matter
    assert m.margin == pytest.approx(0.2) and m.best == ["random"]
    with pytest.raises(ValueError, match="margin_rel"):
        eqv.margins({"svd": 1.0}, "svd", 0.0)


def _step():
    from opnav.report.claims import load_plan

    return load_plan().margin("B-C2", "min_difference_s")


def test_converges_faster_rule():
    rng = np.random.default_rng(1)
    tb = 10 + rng.uniform(0, 5, 200)
    step = _step()
    fast = eqv.converges_faster(tb - 1.5 * step + 0.1 * rng.standard_normal(200), tb, "depth", "svd", 100.0,
                                min_difference_s=step)
    assert fast.verdict == "faster" and fast.hi_s < 0 and fast.min_difference_s == step
    same = eqv.converges_faster(tb + 0.3 * rng.standard_normal(200), tb, "depth", "svd", 100.0,
                                min_difference_s=step)
    assert same.verdict == "no difference shown"
    ta = tb + 1.5 * step
    ta[:50] = np.nan                       # runs that never get there are left out, counted
    slow = eqv.converges_faster(ta, tb, "depth", "svd", 100.0, min_difference_s=step)
    assert slow.verdict == "slower" and slow.n_runs == 150


def test_faster_needs_the_plans_smallest_difference():
    """A difference the interval shows but smaller than the plan's step (B-C2: one filter
    step) is not "faster" (the interval-below-zero rule alone calls it faster: tried once)."""
    rng = np.random.default_rng(2)
    tb = 10 + rng.uniform(0, 5, 300)
    step = _step()
    ta = tb - 0.6 * step + 0.05 * rng.standard_normal(300)
    r = eqv.converges_faster(ta, tb, "depth", "svd", 100.0, min_difference_s=step)
    assert r.hi_s < 0 and r.verdict == "no difference shown"
    assert eqv.converges_faster(ta, tb, "depth", "svd", 100.0, min_difference_s=0.5 * step).verdict == "faster"


def _judge_b(cid, scenario, full=False):
    """The claims table's verdict of ``cid`` on one camera's summary (its evidence rows judged
    by the generic scorer against the plan)."""
    from opnav.report import claims as C
    from opnav.report import scorer as S
    from opnav.report.landing_claims import evidence_rows

    plan = C.load_plan()
    if full and "equivalence_vs_baselines" not in scenario:
        # only SVD is paired here: GDOP and condition number are left out of the test
        plan = plan.amended({f"claims.{cid}.test.versus": ["svd"]})
    rows = C.evidence_table(plan, evidence_rows({"scenarios": {"interior": scenario}}, "main", "x", plan))
    j = S.judge(plan, cid, rows)
    return j if full else j.verdict


@pytest.mark.parametrize("shift", [-1.6, -0.6, 0.0, 0.6])
def test_faster_reading_agrees_with_the_claims_table(shift):
    """The scorecard's B-C2 row (the summary's verdict) and the claims table's B-C2 (the
    plan's step on the summary's interval) agree."""
    import pandas as pd

    from opnav.core.verdicts import REPRODUCED
    from opnav.landing.bsummary import BSummary
    from opnav.report.landing.summary import rows_paper_b
    claim = None
    rng = np.random.default_rng(4)
    tb = 10 + rng.uniform(0, 5, 300)
    cf = eqv.converges_faster(tb + shift * _step() + 0.05 * rng.standard_normal(300), tb, "depth", "svd", 100.0,
                              min_difference_s=_step())
    from opnav.core.tables import json_ready

    summary = {"converges_faster": {"depth": json_ready(cf)}}
    claim = _judge_b("B-C2", summary)
    eq = {"reference": "svd", "margin_rel": 0.1, "metrics": {q: {"margin": 1.0} for q in eqv.PRIMARY_METRICS},
          "methods": {"depth": {"equivalent": True, "verdict": "equivalent", "same_pick_pct": 10.0, "text": "",
                                "lastlm_pos_err_m": {"mean": 0.0}}}}
    rows = rows_paper_b(pd.DataFrame({"method": ["depth"]}),
                        BSummary.from_json({**summary, "equivalence": eq, "controls": [], "controls_equivalent": [],
                         "same_pick_max_pct": 90.0}), {})
    ours = next(r for r in rows if "converges a bit faster" in r["item"])["verdict"]
    assert (ours == REPRODUCED) == (claim == "reproduced")
    assert (ours == REPRODUCED) == (shift <= -1.5)


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
    from opnav.landing.records import MonteCarlo

    out = time_below(MonteCarlo(err_r=err, t=t), 100.0)
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
    from opnav.landing.setup import NearSite

    plain = make_field(12000.0, 20000, seed=7)
    dense = make_field(12000.0, 20000, seed=7, near_site=NearSite(count=5000, r_min_m=1.0))
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
    from landing_helpers import scenario_setups
    from opnav.landing.scenario import build_scenario

    cfg = scenario_setups(load_config()["landing"])["interior"]
    scn = build_scenario(cfg)
    runs = run_descents(scn, "closest", [0, 1])
    lim = cfg.filter.min_update_altitude_m
    true_alt = scn.truth.r[:, 2]
    checked = 0
    for d in runs:
        cut = d.cut_alt_m
        assert not np.any(d.updated[1:] & ~(cut[1:] > lim))
        stop = np.flatnonzero(~(cut[1:-1] > lim))[0] + 1
        # after the cut-off the truth is still above the limit (the margin) yet no update
        assert true_alt[stop] > lim and not d.updated[stop:].any()
        checked += 1
        # the recorded quantity is the estimate less the margin, not the truth's
        est_alt = true_alt - d.err_r[:, 2]
        assert not np.allclose(cut[1:], vision_cutoff_altitude(np.column_stack(
            [np.zeros((len(true_alt), 2)), true_alt]), scn.update_margin_m)[1:])
        assert np.all(np.isfinite(est_alt))
    assert checked == 2


@pytest.mark.parametrize("case", ["plain", "control_meets", "depth_fails", "same_picks", "random_far"])
def test_scorecard_reading_agrees_with_the_claims_table(case):
    """The scorecard's reading of B-C1 (same_accuracy_verdict on the summary) and the claims
    table's (report.landing_claims, the plan's margin on the summary's intervals) agree:
    one margin, one same-pick threshold (a margin back on the runs' random gap splits them in
    the random_far case: tried once)."""
    from opnav.core.verdicts import REPRODUCED
    from opnav.landing.bsummary import ScenarioSummary
    from opnav.report.landing.summary import same_accuracy_verdict
    from opnav.report import claims as C
    from opnav.report.claims import load_plan

    st = _runs()
    if case in ("control_meets", "depth_fails"):
        st = {**st, "closest": st["svd"] + 0.001 * (st["closest"] - st["svd"])}
    if case == "depth_fails":
        st = {**st, "depth": _runs()["center"]}
    if case == "random_far":        # random 50 m worse: a margin from random's gap would pass the controls
        st = {**st, "random": st["random"] + 50.0}
    plan = load_plan()
    acc = _accuracy(st, plan.margin("B-C1", "same_pick_max_pct"), 95.0 if case == "same_picks" else 40.0)
    ours = same_accuracy_verdict(ScenarioSummary.from_json(acc), "depth")
    j = _judge_b("B-C1", acc, full=True)
    if case == "same_picks":
        assert j.verdict == C.NOT_TESTED and "not tested" in ours.reason
    else:
        assert (j.verdict == C.REPRODUCED) == (ours.verdict == REPRODUCED)
        assert any(f[0] == "control_also_meets" for f in j.flags) == ("cannot credit" in ours.reason)


def test_the_summary_writes_the_records_keys_and_the_report_layers_sentences():
    """B-summary.json keeps its keys (issue 56: typed in memory, serialised at the edge): a
    method's paired tests by metric key beside equivalent / same_pick_pct / verdict and the
    sentence, each metric's margin with its name in words, converges-faster's numbers and its
    sentence (the words are the report layer's: no 'text' field on the records)."""
    import dataclasses

    from opnav.core.tables import json_ready
    from opnav.report.landing.equivalence_text import METRIC_TEXT, Worded, converges_text, worded_section

    st = _runs()
    sec = eqv.equivalence(st, "svd", ["depth"], margin_rel=_plan_rel(), same_pick_pct={"depth": 40.0})
    doc = json_ready(worded_section(sec))
    assert set(doc) == {"reference", "alpha", "margin_rel", "metrics", "methods"}
    assert set(doc["methods"]["depth"]) == {*eqv.PRIMARY_METRICS, eqv.TOUCHDOWN_METRIC, "equivalent",
                                            "same_pick_pct", "verdict", "text"}
    assert set(doc["methods"]["depth"]["lastlm_pos_err_m"]) == {"mean", "lo", "hi", "p", "equivalent", "margin",
                                                                "n", "se", "level"}
    assert doc["metrics"]["lmrms_pos_err_m"]["text"] == METRIC_TEXT["lmrms_pos_err_m"]
    assert {"margin", "rel", "reference_mean", "best", "means"} < set(doc["metrics"]["lmrms_pos_err_m"])
    assert "depth vs svd: equivalent" in doc["methods"]["depth"]["text"]
    for rec in (eqv.PairedTest, eqv.MethodEquivalence, eqv.EquivalenceSection, eqv.ConvergesFaster):
        assert "text" not in {f.name for f in dataclasses.fields(rec)}
    rng = np.random.default_rng(2)
    tb = 10 + rng.uniform(0, 5, 50)
    cf = eqv.converges_faster(tb - 3.0, tb, "depth", "svd", 100.0, min_difference_s=1.0)
    d = json_ready(Worded(cf, converges_text(cf)))
    assert "method" not in d and d["verdict"] == "faster" and d["versus"] == "svd"
    assert d["text"].startswith("first time below 100 m, depth minus svd: -3 s") and d["text"].endswith(": faster")
