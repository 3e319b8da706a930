"""The claims table (opnav.report.claims, approach_claims, landing_claims) on hand-made
inputs, judged by the analysis plan: verdicts that flip when the numbers do, every claim
with a plan entry and every plan entry read, a control that also meets a claim, a result
beating its own bound, a verdict that flips between two samples, and causes a reader takes
in at once."""

import dataclasses

import pandas as pd
import pytest
import yaml

from opnav.approach.summaries import ClaimsSummary
from opnav.core import published
from opnav.landing.claims_summary import LandingSummary
from opnav.report import claims as C
from opnav.report.approach_claims import claim_rows as _rows_a
from opnav.report.landing_claims import claim_rows as _rows_b

PUB = published.load()
CASES = [("T1-01", "size", 0.1), ("T1-10", "pixel", 0.1), ("T1-11", "pixel", 0.5), ("T1-12", "pixel", 1.0)]
PUB_DATA = {"T1-01": 250, "T1-10": 250, "T1-11": 1200, "T1-12": 2000}
WINDOWS = {"sliding": 50.0, "growing": 250.0}


def rows_a(summary, t1, pub, plan=None):
    return _rows_a(summary, t1, pub, plan or C.load_plan(), WINDOWS)


def rows_b(summary, pub, plan=None):
    return _rows_b(LandingSummary.from_json(summary), pub, plan or C.load_plan())


def _row(variant, case, group, px, err=1.0, bound=1.0, label="converged", data=None, before=80.0, after=18.0,
         n_seeds=20, mode="sliding"):
    return {"variant": variant, "scenario": variant.split("+")[0], "case_id": case, "group": group,
            "pixel_sigma3_px": px, "n_seeds": n_seeds, "rmse_x_arcsec": err, "rmse_y_arcsec": err,
            "crlb_x_arcsec": bound, "crlb_y_arcsec": bound, "crlb_q0_x_arcsec": bound, "label": label,
            "converged_seeds": n_seeds if label == "converged" else 0, "stalled": label == "stalled",
            "stalled_seeds": n_seeds if label == "stalled" else 0, "mode": mode,
            "data_to_converge_samples": PUB_DATA[case] if data is None else data,
            "pub_data_to_converge_samples": PUB_DATA[case], "nav_err_before_km": before,
            "nav_err_before_km_std": 1.0, "pub_nav_err_before_km": 79.06, "nav_err_after_km": after,
            "tz_observable": False}


def table(literal=None, roll=None, diag=None, **extra):
    rows = []
    for v, kw in (("literal", literal or {}), ("roll", roll or {}), *extra.items()):
        rows += [_row(v, c, g, p, **kw) for c, g, p in CASES]
    rows.append(_row("reference-start", "T1-01", "size", 0.1, **(diag or {})))
    return pd.DataFrame(rows)


#: A-summary.json as the pipeline writes it (the parts the claims read), and as they read it
SUMMARY_A_JSON = {"profile_segments": {"N": 50}, "accuracy_target_arcsec": 2.0,
                  "roll_rate": {"config_rate_deg_s": 0.1, "rate_to_target_deg_s": 0.236}}
SUMMARY_A = ClaimsSummary.from_json(SUMMARY_A_JSON)


def by_id(rows):
    return {r["claim_id"]: r for r in rows}


# ------------------------------------------------------------ paper B's hand-made summary
def _iv(mean, half):
    return {"mean": mean, "lo": mean - half, "hi": mean + half}


def _scenario(d_depth=0.0, controls=None, pick=50.0, faster=(-3.0, -5.0, -1.0), yaw=False, red=29.0,
              red_alt=70.0, gdop=0.0, times=None, env=1.0, n_runs=300):
    """One camera's summary: depth minus SVD of each landmark-phase error is ``d_depth`` m
    (+-0.005) against SVD means of 0.4 and 2 m; ``controls``: control -> its difference
    from SVD (m); ``gdop``: depth minus GDOP and minus condition number (m, B-T3 pairs)."""
    controls = {"random": 2.0, "center": 1.0, "closest": 0.8} if controls is None else controls
    q = ("lastlm_pos_err_m", "lmrms_pos_err_m")
    meth = {"depth": {q[0]: _iv(d_depth, 0.005), q[1]: _iv(d_depth, 0.005), "same_pick_pct": pick}}
    meth.update({c: {q[0]: _iv(x, 0.01), q[1]: _iv(x, 0.01), "same_pick_pct": 5.0} for c, x in controls.items()})
    times = times or {"depth": 4.0, "svd": 5.0, "gdop": 7.0, "cond": 8.0}
    methods = {m: {"median_plan_time_us": t, "rms_pos_err_m_mean": 3.0, "final_pos_err_m_mean": 1.0,
                   "rms_vel_err_mps_3sigma": 0.3 * (env if m == "depth" else 1.0),
                   "rms_att_err_deg_3sigma": 0.2} for m, t in times.items()}
    methods["depth"].update({"time_reduction_vs_svd_pct": red, "time_reduction_vs_svd_pct_std": 1.0,
                             "time_reduction_vs_svd_alt_pct": red_alt, "time_reduction_vs_svd_alt_pct_std": 1.0})
    pairs = {f"depth_vs_{b}": {"d_rms_pos_m": gdop, "d_rms_pos_lo_m": gdop - 0.01, "d_rms_pos_hi_m": gdop + 0.01,
                               "d_final_pos_m": gdop, "d_final_pos_lo_m": gdop - 0.01, "d_final_pos_hi_m": gdop + 0.01}
             for b in ("gdop", "cond")}
    return {"eval_path": "compiled", "yaw_converges": yaw, "yaw_reason": "yaw 3-sigma flat", "n_runs": n_runs,
            "equivalence": {"reference": "svd", "methods": meth,
                            "metrics": {q[0]: {"means": {"svd": 0.4}}, q[1]: {"means": {"svd": 2.0}}}},
            "converges_faster": {"depth": {"verdict": "faster", "mean_s": faster[0], "lo_s": faster[1],
                                           "hi_s": faster[2], "n_runs": 300, "threshold_m": 100.0}},
            "methods": methods, "pairs": pairs}


def summary_b(**kw_by_scenario):
    scen = {"interior": _scenario(**kw_by_scenario.get("interior", {})),
            "site-tilt": _scenario(**kw_by_scenario.get("site-tilt", {}))}
    return {"headline_scenario": "interior", "scenarios": scen, "initial_tilt_deg": 9.8, "initial_azimuth_deg": 16.5}


def both(**kw):
    return {"interior": kw, "site-tilt": kw}


# ------------------------------------------------------------ the contract and the plan
def test_columns_verdicts_and_causes_are_the_contract():
    df = C.frame(rows_a(SUMMARY_A, table(), PUB["paper_a"]) + rows_b(summary_b(), PUB["paper_b"]))
    assert list(df.columns) == C.COLUMNS == [
        "paper", "claim_id", "claim", "published", "ours_as_written", "ours_best", "best_variant", "bound",
        "ours_replication", "verdict", "verdict_replication", "flags", "named", "would_take", "cause", "evidence",
        "sample"]
    assert set(df["verdict"]) <= set(C.VERDICTS) and df["claim_id"].is_unique
    assert set(C.VERDICT_SHORT) == set(C.VERDICT_TEXT) == set(C.VERDICTS)
    for c in df["cause"]:
        assert c.count(". ") == 0 and c.endswith(".") and len(c.split()) <= 40, c


@pytest.mark.xfail(reason='the plan of issue 52 (v2) is read by the generic scorer, landing next', strict=False)
def test_every_claim_has_a_plan_entry_and_every_entry_is_read():
    """Scoring both papers reads every claim, margin and guard of the plan (a margin left
    in the plan but read by no verdict fails), and every row has a plan entry."""
    plan = C.load_plan()
    df = C.frame(rows_a(SUMMARY_A, table(), PUB["paper_a"], plan) + rows_b(summary_b(), PUB["paper_b"], plan))
    C.check_plan_covers(df, plan)
    assert plan.unused() == []
    assert set(df["claim_id"]) == set(plan.claims)
    t = plan.table()
    assert list(t.columns) == C.PLAN_COLUMNS and len(t) == len(plan.claims)
    assert (t.loc[t["claim_id"] == "B-C1", "margin"].iloc[0]).startswith("margin_rel = 0.1")


def _plan_without(tmp_path, path):
    raw = yaml.safe_load(C.PLAN_FILE.read_text())
    node = raw
    for k in path[:-1]:
        node = node[k]
    del node[path[-1]]
    p = tmp_path / "analysis_plan.yaml"
    p.write_text(yaml.safe_dump(raw, allow_unicode=True))
    return C.load_plan(p)


@pytest.mark.xfail(reason='the plan of issue 52 (v2) is read by the generic scorer, landing next', strict=False)
def test_a_margin_missing_from_the_plan_stops_the_scorer_naming_it(tmp_path):
    plan = _plan_without(tmp_path, ["claims", "B-C1", "margins", "margin_rel"])
    with pytest.raises(C.PlanError, match=r"claims\.B-C1\.margins\.margin_rel is missing"):
        rows_b(summary_b(), PUB["paper_b"], plan)
    plan = _plan_without(tmp_path, ["claims", "A-C8"])
    with pytest.raises(C.PlanError, match="claim A-C8 has no entry"):
        rows_a(SUMMARY_A, table(), PUB["paper_a"], plan)
    # an unused entry is named: a plan that only paper B read leaves paper A's unread
    plan = C.load_plan()
    rows_b(summary_b(), PUB["paper_b"], plan)
    assert "claims.A-C1.margins.target_arcsec" in plan.unused()


def test_only_a_claim_the_plan_gives_an_information_bound_can_be_not_reproducible(tmp_path):
    t = table(literal={"err": 10.0, "bound": 20.6}, roll={"err": 8.0, "bound": 9.0})
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C1"]["verdict"] == C.NOT_REPRODUCIBLE
    plan = _plan_without(tmp_path, ["claims", "A-C1", "bound"])
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"], plan))["A-C1"]["verdict"] == C.NOT_REPRODUCED


def test_a_malformed_margin_is_refused_in_one_line(tmp_path):
    raw = yaml.safe_load(C.PLAN_FILE.read_text())
    raw["claims"]["A-C6"]["margins"]["rel_tol"] = {"value": 0.1}
    p = tmp_path / "plan.yaml"
    p.write_text(yaml.safe_dump(raw, allow_unicode=True))
    with pytest.raises(C.PlanError, match=r"claims\.A-C6\.margins\.rel_tol needs a numeric 'value' and a 'reason'"):
        C.load_plan(p)


def test_the_plan_margin_decides_not_a_constant_in_code(tmp_path):
    """B-C1 at a 5 % difference: equivalent within the plan's 10 %, not within 2 %."""
    s = summary_b(**both(d_depth=0.02))            # 5 % of SVD's 0.4 m
    assert by_id(rows_b(s, PUB["paper_b"]))["B-C1"]["verdict"] == C.REPRODUCED
    raw = yaml.safe_load(C.PLAN_FILE.read_text())
    raw["claims"]["B-C1"]["margins"]["margin_rel"]["value"] = 0.02
    p = tmp_path / "plan.yaml"
    p.write_text(yaml.safe_dump(raw, allow_unicode=True))
    assert by_id(rows_b(s, PUB["paper_b"], C.load_plan(p)))["B-C1"]["verdict"] == C.NOT_REPRODUCED


# ------------------------------------------------------------ paper A
def test_accuracy_is_scored_as_accuracy_and_flips():
    ok = by_id(rows_a(SUMMARY_A, table(), PUB["paper_a"]))["A-C1"]
    assert ok["verdict"] == C.REPRODUCED and ok["would_take"] == ""
    # literal far from the truth, the roll variant within 2 arcsec: only with an addition, named
    r = by_id(rows_a(SUMMARY_A, table(literal={"err": 10.0}), PUB["paper_a"]))["A-C1"]
    assert r["verdict"] == C.WITH_ADDITION and "roll" in r["named"] and r["best_variant"] == "roll"
    r = by_id(rows_a(SUMMARY_A, table(literal={"err": 10.0, "bound": 1.0}), PUB["paper_a"]))["A-C2"]
    assert r["would_take"].startswith("a boresight roll (roll,")
    # an estimate at the truth that did not converge is not accuracy
    r = by_id(rows_a(SUMMARY_A, table(literal={"label": "stalled"}, roll={"err": 9.0}), PUB["paper_a"]))["A-C1"]
    assert r["verdict"] == C.NOT_REPRODUCED


def test_bound_makes_it_not_reproducible_and_says_what_it_would_take():
    t = table(literal={"err": 10.0, "bound": 20.6}, roll={"err": 8.0, "bound": 9.0}, diag={"err": 0.1, "bound": 0.07})
    r = by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C1"]
    assert r["verdict"] == C.NOT_REPRODUCIBLE and "20.6" in r["named"]
    assert "0.236 deg/s" in r["would_take"], "the roll rate the pipeline measured"
    t = table(literal={"err": 10.0, "bound": 1.0}, roll={"err": 8.0}, diag={"err": 0.1})
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C1"]["verdict"] == C.NOT_REPRODUCED


def test_published_errors_with_the_real_bound_are_suspect_never_reproduced():
    """Fed the published errors (1.43, 1.21 arcsec) with the real bound of 20.6 arcsec kept,
    A-C1, A-C2 and A-C4 read suspect (14x below the bound), never reproduced."""
    head = PUB["paper_a"]["headline"]
    t = table(literal={"bound": 20.6}, roll={"err": 9.0, "bound": 9.0})
    lit = t["variant"] == "literal"
    t.loc[lit, "rmse_x_arcsec"], t.loc[lit, "rmse_y_arcsec"] = head["est_error_arcsec"]
    r = by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))
    for cid in ("A-C1", "A-C2", "A-C4"):
        assert r[cid]["verdict"] == C.SUSPECT, cid
        assert "beats_bound: 14x (literal)" in r[cid]["flags"], r[cid]["flags"]
    # within the plan's factor (an error at half the bound, 20 seeds) it is not suspect
    t = table(literal={"err": 0.6, "bound": 1.0})
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C1"]["verdict"] == C.REPRODUCED
    # a few seeds widen the allowance: 0.35 of the bound is suspect at 20 seeds, not at 2
    assert by_id(rows_a(SUMMARY_A, table(literal={"err": 0.35, "bound": 1.0}), PUB["paper_a"]))["A-C1"]["verdict"] \
        == C.SUSPECT
    t = table(literal={"err": 0.35, "bound": 1.0, "n_seeds": 2})
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C1"]["verdict"] == C.REPRODUCED


def test_pixel_claims_more_data_and_unaffected_accuracy():
    r = by_id(rows_a(SUMMARY_A, table(), PUB["paper_a"]))
    assert r["A-C5"]["verdict"] == C.REPRODUCED and r["A-C10"]["verdict"] == C.REPRODUCED
    t = table()
    t.loc[(t["variant"] == "literal") & (t["case_id"] == "T1-12"), "rmse_x_arcsec"] = 5.0
    t.loc[(t["variant"] == "roll") & (t["case_id"] == "T1-12"), "rmse_x_arcsec"] = 5.0
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C10"]["verdict"] == C.NOT_REPRODUCED
    t = table(literal={"bound": 20.6})
    r = by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C5"]
    assert r["verdict"] == C.WITH_ADDITION and r["best_variant"] == "roll"
    assert "not identifiable" in r["ours_as_written"] and "20.6" in r["bound"]


def test_counts_are_evidence_only_on_identifiable_data_above_the_first_window():
    # the growing rows start at 250 samples: a count of 250 is the window, not evidence
    t = table(literal={"bound": 20.6}, **{"roll+growing": {"mode": "growing"}})
    t = t[t["variant"] != "roll"]
    r = by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C3"]
    assert r["verdict"] == C.NOT_REPRODUCED, r
    assert "on data whose bound exceeds" in r["ours_as_written"]
    assert "at the first window" in r["ours_best"]
    # the published count +- 50 samples (the plan), not +- 200
    t = table(roll={"data": 330})
    t.loc[t["variant"] == "literal", "data_to_converge_samples"] += 60
    assert by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))["A-C3"]["verdict"] == C.NOT_REPRODUCED


def test_a_filter_floor_is_not_an_information_bound():
    """A true-theta floor above 20 km is evidence that the claim hinges on the arc length and
    error rule (depends on a choice, flagged), never 'not reproducible'."""
    t = table(literal={"after": 118.0}, roll={"after": 88.0}, diag={"after": 41.8})
    floor = dataclasses.replace(SUMMARY_A, nav_err_true_theta_km=29.4)
    r = by_id(rows_a(floor, t, PUB["paper_a"]))["A-C7"]
    assert r["verdict"] == C.DEPENDS and "arc length" in r["named"]
    assert "floor_not_bound: true-theta filter 29.4 km" in r["flags"]
    low = dataclasses.replace(SUMMARY_A, nav_err_true_theta_km=12.0)
    assert by_id(rows_a(low, t, PUB["paper_a"]))["A-C7"]["verdict"] == C.NOT_REPRODUCED


def test_nav_before_cause_is_generated_from_the_geometry():
    r = by_id(rows_a(SUMMARY_A, table(literal={"before": 120.0}, roll={"before": 120.0}), PUB["paper_a"]))["A-C6"]
    assert r["verdict"] == C.NOT_REPRODUCED and "108 km" in r["cause"] and "22.4 arcsec" in r["cause"]


# ------------------------------------------------------------ paper B
def test_paper_b_verdicts_flip_with_the_numbers():
    r = by_id(rows_b(summary_b(), PUB["paper_b"]))
    for cid in ("B-C1", "B-C2", "B-C3", "B-C4", "B-C9", "B-C10"):
        assert r[cid]["verdict"] == C.REPRODUCED, (cid, r[cid])
    assert r["B-C7"]["verdict"] == C.NOT_REPRODUCED and r["B-C8"]["verdict"] == C.NOT_TESTED
    assert r["B-C1"]["flags"] == ""
    r = by_id(rows_b(summary_b(**both(pick=95.0)), PUB["paper_b"]))
    assert r["B-C1"]["verdict"] == C.NOT_TESTED and "95" in r["B-C1"]["named"]
    r = by_id(rows_b(summary_b(**{"site-tilt": {"d_depth": 0.2}}), PUB["paper_b"]))
    assert r["B-C1"]["verdict"] == C.DEPENDS and "camera" in r["B-C1"]["named"]
    r = by_id(rows_b(summary_b(**both(d_depth=-0.2, gdop=-0.5)), PUB["paper_b"]))
    assert r["B-C7"]["verdict"] == C.REPRODUCED and r["B-C1"]["verdict"] == C.NOT_REPRODUCED
    r = by_id(rows_b(summary_b(**both(times={"depth": 6.0, "svd": 5.0, "gdop": 7.0, "cond": 8.0}, env=1.3)),
                     PUB["paper_b"]))
    assert r["B-C9"]["verdict"] == C.NOT_REPRODUCED and r["B-C10"]["verdict"] == C.NOT_REPRODUCED


def test_a_control_that_also_meets_the_claim_is_a_flag_not_a_verdict():
    """Depth within the margin of SVD, and so is the closest-range picker: the claim holds
    (reproduced), and the flag and the cause say the test cannot credit the metric."""
    s = summary_b(**both(controls={"random": 2.0, "center": 1.0, "closest": 0.01}))
    r = by_id(rows_b(s, PUB["paper_b"]))["B-C1"]
    assert r["verdict"] == C.REPRODUCED
    assert r["flags"] == "control_also_meets: closest (interior); control_also_meets: closest (site-tilt)"
    assert "cannot credit" in r["cause"] and "closest" in r["cause"]


def test_converging_faster_needs_a_whole_filter_step():
    r = by_id(rows_b(summary_b(**both(faster=(-0.4, -0.7, -0.1))), PUB["paper_b"]))["B-C2"]
    assert r["verdict"] == C.NOT_REPRODUCED, "a 0.4 s gain is below the 1 s step"
    r = by_id(rows_b(summary_b(**{"site-tilt": {"faster": (0.4, 0.1, 0.7)}}), PUB["paper_b"]))["B-C2"]
    assert r["verdict"] == C.DEPENDS


def test_timing_depends_on_the_svd_implementation_and_says_what_it_would_take():
    r = by_id(rows_b(summary_b(**both(red=8.0, red_alt=29.0)), PUB["paper_b"]))["B-C4"]
    assert r["verdict"] == C.DEPENDS and "paper's definition" in r["would_take"]
    assert r["named"] == "how the SVD baseline is implemented" and "another SVD implementation" in r["cause"]
    r = by_id(rows_b(summary_b(interior={"red": 8.0, "red_alt": 80.0}), PUB["paper_b"]))["B-C4"]
    assert r["verdict"] == C.DEPENDS and r["named"] == "which camera is flown"
    assert r["would_take"] == "timing on the compiled implementation in the site-tilt camera"
    # a timing whose spread is wider than half the published value tests nothing
    s = summary_b(**both(red=-19.5))
    s["scenarios"]["interior"]["methods"]["depth"]["time_reduction_vs_svd_pct_std"] = 2743.0
    r = by_id(rows_b(s, PUB["paper_b"]))["B-C4"]
    assert r["verdict"] == C.NOT_TESTED and "band_too_wide: compiled implementation, interior camera" in r["flags"]
    r = by_id(rows_b(summary_b(**both(red=8.0)), PUB["paper_b"]))["B-C4"]
    assert r["verdict"] == C.NOT_REPRODUCED and r["would_take"] == "" and "8 % less" in r["cause"]


# ------------------------------------------------------------ samples
def test_a_verdict_that_flips_between_samples_is_unstable():
    main = C.frame(rows_b(summary_b(), PUB["paper_b"]))
    rep = C.frame(rows_b(summary_b(**{"interior": {"faster": (-0.2, -0.5, 0.1)},
                                      "site-tilt": {"faster": (-0.2, -0.5, 0.1)}}), PUB["paper_b"]))
    out = C.with_replication(main, rep, C.replication_plan(C.load_plan(), {"enabled": False})).set_index("claim_id")
    assert out.loc["B-C2", "verdict"] == C.UNSTABLE
    assert out.loc["B-C2", "verdict_replication"] == C.NOT_REPRODUCED
    assert "reproduced" in out.loc["B-C2", "cause"] and "not reproduced" in out.loc["B-C2", "cause"]
    assert "verdict_main: reproduced" in out.loc["B-C2", "flags"]
    assert out.loc["B-C1", "verdict"] == C.REPRODUCED and out.loc["B-C1", "verdict_replication"] == C.REPRODUCED
    assert out.loc["B-C1", "ours_replication"] != ""
    assert out.loc["B-C8", "verdict_replication"] == "", "not among the plan's replicated claims"


def test_the_plan_states_the_replication_size_the_config_flies():
    plan = C.load_plan()
    from pathlib import Path
    cfg = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "config.yaml").read_text())["replication"]
    assert cfg["enabled"] and "B-C2" in C.replication_plan(plan, cfg), "the full profile flies what the plan states"
    with pytest.raises(C.PlanError, match=r"replication\.landing_n_runs = 100 but the config's"):
        C.replication_plan(plan, {**cfg, "landing_n_runs": 300})


def test_quick_profile_rows_say_the_sample_is_too_small():
    df = C.frame(rows_b(summary_b(**both(n_runs=4)), PUB["paper_b"]))
    q = C.mark_sample(df, "quick")
    assert (q["sample"] == "quick").all() and q["flags"].str.contains("sample_too_small: quick profile").all()
    assert "too small for verdicts" in C.sample_sentence(q)
    assert "sample_too_small: 4 runs" in df.set_index("claim_id").loc["B-C1", "flags"]
    assert q.set_index("claim_id").loc["B-C1", "flags"] == "sample_too_small: quick profile"
    f = C.mark_sample(C.frame(rows_b(summary_b(), PUB["paper_b"])), "full")
    assert (f["sample"] == "full").all() and C.sample_sentence(f) == ""
    assert not f["flags"].str.contains("sample_too_small").any()


# ------------------------------------------------------------ prose
def test_abstract_sentence_changes_with_a_verdict():
    good = C.frame(rows_a(SUMMARY_A, table(), PUB["paper_a"]) + rows_b(summary_b(), PUB["paper_b"]))
    bad = C.frame(rows_a(SUMMARY_A, table(literal={"err": 10.0, "bound": 20.6}, roll={"err": 8.0}),
                         PUB["paper_a"]) + rows_b(summary_b(), PUB["paper_b"]))
    a_good, a_bad = C.abstract(good), C.abstract(bad)
    first_good, first_bad = a_good.split(". ")[0], a_bad.split(". ")[0]
    assert first_good != first_bad
    assert "not reproducible under the stated assumptions" in first_bad and "A-C1;" in first_bad
    assert "not reproducible" not in first_good
    assert "20.6" in a_bad  # the bound of the headline claim, with its number
    assert C.conclusion(good) != C.conclusion(bad)


def test_row_rejects_unknown_verdict_missing_name_and_long_causes():
    with pytest.raises(ValueError, match="verdict"):
        C.row("A", "A-C0", "c", "p", "reproduced-ish", "x.", "A-T1")
    with pytest.raises(ValueError, match="named"):
        C.row("A", "A-C0", "c", "p", C.DEPENDS, "x.", "A-T1")
    with pytest.raises(ValueError, match="one sentence"):
        C.row("A", "A-C0", "c", "p", C.REPRODUCED, "One. Two.", "A-T1")
    with pytest.raises(ValueError, match="words"):
        C.row("A", "A-C0", "c", "p", C.REPRODUCED, " ".join(["word"] * 60), "A-T1")


def test_variants_beyond_the_paper_never_earn_a_verdict_but_are_named():
    t = table(literal={"err": 10.0, "bound": 20.6}, roll={"err": 8.0, "bound": 9.0})
    stars = _row("stars", "T1-01", "size", 0.1, err=0.2, bound=0.2)
    stars["tz_observable"] = True
    t = pd.concat([t, pd.DataFrame([stars])], ignore_index=True)
    r = by_id(rows_a(SUMMARY_A, t, PUB["paper_a"]))
    assert r["A-C1"]["verdict"] == C.NOT_REPRODUCIBLE and r["A-C1"]["best_variant"] == "roll"
    assert r["A-C9"]["verdict"] == C.REPRODUCED and "stars" in r["A-C9"]["evidence"]


def test_claims_summary_finds_the_as_written_row_by_its_fields_not_its_label():
    """ClaimsSummary.from_json takes the as-written row (literal, plain EM, sliding) by its
    scenario, method and mode, whatever the key and the order of the rows; what is absent
    reads as None (N as 0). Mutation tried: dropping the method test picks literal+squarem's
    5.0 km and fails."""
    row = {"scenario": "literal", "mode": "sliding"}
    summ = {"profile_segments": {"N": 50}, "roll_rate": {"config_rate_deg_s": 0.1, "rate_to_target_deg_s": 0.236},
            "variants": {"literal+squarem": {**row, "method": "squarem", "nav_err_true_theta_km": 5.0},
                         "literal+growing+squarem": {**row, "mode": "growing", "method": "squarem",
                                                     "nav_err_true_theta_km": 6.0},
                         "prior": {**row, "scenario": "prior", "method": "plain", "nav_err_true_theta_km": 7.0},
                         "any key": {**row, "method": "plain", "nav_err_true_theta_km": 29.4}}}
    assert ClaimsSummary.from_json(summ) == ClaimsSummary(50.0, 0.236, 0.1, 29.4)
    assert ClaimsSummary.from_json({}) == ClaimsSummary(0.0, None, None, None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        SUMMARY_A.window_samples = 10.0


def test_paper_a_claims_refuse_a_summary_dict():
    """No label-keyed dict crosses into the claims: a raw A-summary dict is refused in one line."""
    with pytest.raises(TypeError, match="ClaimsSummary.from_json"):
        rows_a({"profile_segments": {"N": 50}}, table(), PUB["paper_a"])

