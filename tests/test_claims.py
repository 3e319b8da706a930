"""The claims table (opnav.report.claims) end to end on hand-made summaries: the plan's schema
and its refusals, the extractors (every number of a summary becomes an evidence row), the
claim rows as typed records whose every quoted number is a row of the evidence, the plan's
amendments recomputed on the same evidence, and the prose."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest
import yaml

from opnav.core import published
from opnav.report import approach_claims as A
from opnav.report import claims as C
from opnav.report import landing_claims as B

REPO = Path(__file__).resolve().parents[1]
from opnav.report.evidence import COLUMNS as EV_COLUMNS
from opnav.report.evidence import QUANTITIES, Evidence, read_csv, write_csv

PUB = published.load()
PLAN = C.load_plan()
CASES = [("T1-01", "size", 0.1), ("T1-10", "pixel", 0.1), ("T1-11", "pixel", 0.5), ("T1-12", "pixel", 1.0)]
PUB_DATA = {"T1-01": 250, "T1-10": 250, "T1-11": 1200, "T1-12": 2000}
WINDOWS = {"sliding": 50.0, "growing": 250.0}


# ------------------------------------------------------------ hand-made summaries
def _row(variant, case, group, px, err=1.0, bound=1.0, label="converged", data=None, before=80.0, after=18.0,
         n_seeds=20, mode="sliding", true_theta=15.0):
    return {"variant": variant, "scenario": variant.split("+")[0], "case_id": case, "group": group,
            "pixel_sigma3_px": px, "n_seeds": n_seeds, "rmse_x_arcsec": err, "rmse_y_arcsec": err,
            "crlb_x_arcsec": bound, "crlb_y_arcsec": bound, "crlb_q0_x_arcsec": bound, "crlb_q0_y_arcsec": bound,
            "label": label, "converged_seeds": n_seeds if label == "converged" else 0, "stalled": label == "stalled",
            "stalled_seeds": n_seeds if label == "stalled" else 0, "mode": mode,
            "data_to_converge_samples": PUB_DATA[case] if data is None else data,
            "nav_err_before_km": before, "nav_err_before_km_std": 1.0, "nav_err_after_km": after,
            "nav_err_after_km_std": 1.0, "nav_err_true_theta_km": true_theta, "tz_observable": False}


def table(literal=None, roll=None, diag=None, **extra):
    rows = []
    for v, kw in (("literal", literal or {}), ("roll", roll or {}), *extra.items()):
        rows += [_row(v, c, g, p, **kw) for c, g, p in CASES]
    rows.append(_row("reference-start", "T1-01", "size", 0.1, **(diag or {})))
    return pd.DataFrame(rows)


SUMMARY_A = {"profile_segments": {"N": 50},
             "roll_rate": {"rates_deg_s": [0.05, 0.1, 0.2, 0.4], "bound_at_samples_arcsec": [20.0, 10.0, 2.5, 0.6]}}


def _iv(mean, half, n=300):
    return {"mean": mean, "lo": mean - half, "hi": mean + half, "n": n}


def _scenario(d_depth=0.0, controls=None, pick=50.0, faster=(-3.0, -5.0, -1.0), yaw=(2.5, 2.6), gdop=0.0,
              n_runs=300, planning=None):
    controls = {"random": 2.0, "center": 1.0, "closest": 0.8} if controls is None else controls
    q = ("lastlm_pos_err_m", "lmrms_pos_err_m")

    def sec(ref, tested):
        return {"reference": ref, "alpha": 0.05,
                "metrics": {q[0]: {"means": {ref: 0.4, "depth": 0.4}}, q[1]: {"means": {ref: 2.0, "depth": 2.0}}},
                "methods": {m: {q[0]: _iv(x, 0.005 if m == "depth" else 0.01),
                                q[1]: _iv(x, 0.005 if m == "depth" else 0.01),
                                "same_pick_pct": pick if m == "depth" else 5.0} for m, x in tested.items()}}
    s = {"eval_path": "compiled", "yaw_sigma3_deg": {"method": "depth", "start": yaw[0], "end": yaw[1], "n_runs": n_runs},
         "n_runs": n_runs, "equivalence": sec("svd", {"depth": d_depth, **controls}),
         "equivalence_vs_baselines": {b: sec(b, {"depth": gdop}) for b in ("gdop", "cond")},
         "converges_faster": {"depth": {"mean_s": faster[0], "lo_s": faster[1], "hi_s": faster[2], "n_runs": 300,
                                        "threshold_m": 100.0, "level": 0.95}},
         "methods": {m: {"rms_vel_err_mps_3sigma": 0.3, "rms_att_err_deg_3sigma": 0.2} for m in ("depth", "svd", "gdop", "cond")},
         "errors": {m: {"lastlm_pos_err_m": {"3sigma": 0.3}, "lmrms_pos_err_m": {"3sigma": 0.6}} for m in ("svd", "gdop", "cond", "depth")}}
    if planning:
        s["planning_time"] = planning
    return s


def planning_time(per_replay=(24.0, 26.0, 28.0)):
    meds = [{"depth": 4.0 * (1 - x / 100) / 0.96 * 0.96 / 1.0, "svd": 4.0, "gdop": 5.0, "cond": 5.2} for x in per_replay]
    for mm, x in zip(meds, per_replay):
        mm["depth"] = 4.0 * (1 - x / 100)
    return {"clock": "thread_cpu", "n_replays": len(per_replay),
            "replays": [{"median_us": m, "n_calls": 200, "load_avg": 0.5} for m in meds],
            "reduction_pct": {"depth_vs_svd": {"per_replay": list(per_replay)}},
            "decomposition": {m: {"shared_us": 3.0, "per_eval_us": pe, "evals_per_call": 30}
                              for m, pe in (("depth", 0.02), ("svd", 0.06), ("gdop", 0.08), ("cond", 0.08))},
            "overhead_curve": {"shared_us": [1.0, 2.0, 3.0, 4.0], "reduction_pct": [40.0, 31.0, 25.0, 20.0]},
            "shared_us_at_published": 2.2}


def summary_b(**kw_by_scenario):
    scen = {s: _scenario(**kw_by_scenario.get(s, {})) for s in ("interior", "site-tilt")}
    return {"headline_scenario": "interior", "scenarios": scen, "initial_tilt_deg": 9.8, "initial_azimuth_deg": 16.5}


def evidence(t1=None, sb=None, rep_b=None, optima=None):
    rows = A.evidence_rows(table() if t1 is None else t1, SUMMARY_A, "main", "A-T1_table1.csv", "A-summary.json",
                           WINDOWS)
    rows += B.evidence_rows(summary_b() if sb is None else sb, "main", "B-summary.json", PLAN, optima)
    if rep_b is not None:
        rows += B.evidence_rows(rep_b, "replication", "replication/B-summary.json", PLAN)
    rows += A.published_rows(PUB["paper_a"]) + B.published_rows(PUB["paper_b"])
    return C.evidence_table(PLAN, rows)


def built(**kw):
    ev = evidence(**kw)
    rows, js, sweeps = C.build(PLAN, ev, C.replication_plan(PLAN, {}))
    return {r.claim_id: r for r in rows}, ev + C.derived_rows(js), sweeps


# ------------------------------------------------------------ the plan
def test_every_claim_has_a_test_and_every_margin_is_read_by_one():
    assert set(PLAN.tests()) == set(PLAN.claims)
    assert PLAN.unreferenced() == [], "a margin or setting no test names"
    assert PLAN.level == 0.9 and PLAN.stamp.startswith("v2 sha256:")
    for cid, t in PLAN.tests().items():
        for q in t.reads():
            assert q in QUANTITIES, f"{cid} reads {q}, which no extractor writes"


def test_the_plan_refuses_a_literal_number_a_missing_margin_and_a_bad_comparison(tmp_path):
    raw = yaml.safe_load(C.PLAN_FILE.read_text())

    def refused(mutate, words):
        import copy

        r = copy.deepcopy(raw)
        mutate(r)
        p = tmp_path / "plan.yaml"
        p.write_text(yaml.dump(r, Dumper=getattr(yaml, "CSafeDumper", yaml.SafeDumper)))
        with pytest.raises(C.PlanError) as e:
            C.load_plan(p)
        msg = str(e.value)
        assert "\n" not in msg and all(w in msg for w in words), msg

    refused(lambda r: r["claims"]["A-C1"]["test"]["conditions"][0].__setitem__("upper", 2.0),
            ["A-C1", "never a literal"])
    refused(lambda r: r["claims"]["B-C1"]["margins"].pop("margin_rel"), ["B-C1", "margin_rel"])
    refused(lambda r: r["claims"]["B-C3"]["test"]["conditions"][0].__setitem__("comparison", "vibes"), ["B-C3"])
    refused(lambda r: r["claims"]["B-C2"].__setitem__("level", 0.95), ["B-C2", "level_reason"])
    refused(lambda r: r["claims"]["A-C6"]["margins"]["rel_tol"].pop("reason"), ["A-C6", "rel_tol"])


def test_the_checksum_follows_the_text(tmp_path):
    p = tmp_path / "plan.yaml"
    p.write_text(C.PLAN_FILE.read_text().replace("value: 0.10, reason: \"'almost", "value: 0.11, reason: \"'almost"))
    assert C.load_plan(p).checksum != PLAN.checksum


def test_the_converged_fraction_has_one_home_the_plan(tmp_path):
    """Paper A's converged label computes with the plan's settings.converge_frac_of_bound: no
    config key holds it (the schema refuses one, naming where it went), a Setup built without it
    reads the plan, and a plan with another value gives another label threshold."""
    from opnav.approach.setup import EMSettings
    from opnav.core import planvalues
    from opnav.core.config import schema_problems

    plan_value = C.load_plan().raw["settings"]["converge_frac_of_bound"]["value"]
    em = {"method": "plain", "tz_tol": 1e-6, "converge_tol_arcsec": 0.5, "stall_rate": 0.95, "ml_max_maps": 60}
    assert EMSettings.from_config(em).converge_frac_of_bound == plan_value
    assert EMSettings.from_config({**em, "converge_frac_of_bound": 0.3}).converge_frac_of_bound == 0.3  # a rule's params
    p = tmp_path / "plan.yaml"
    p.write_text(C.PLAN_FILE.read_text().replace("converge_frac_of_bound:\n    value: 0.1", "converge_frac_of_bound:\n    value: 0.2"))
    assert planvalues.converge_frac_of_bound(p) == 0.2 and planvalues.converge_frac_of_bound() == plan_value
    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    assert "converge_frac_of_bound" not in cfg["approach"]["em"]
    cfg["approach"]["em"]["converge_frac_of_bound"] = 0.1
    lines = schema_problems(cfg)
    assert len(lines) == 1 and "converge_frac_of_bound" in lines[0] and "analysis plan" in lines[0], lines


def test_the_plan_states_the_replication_size_the_config_flies():
    with pytest.raises(C.PlanError, match="replication.landing_n_runs"):
        C.replication_plan(PLAN, {"enabled": True, "landing_n_runs": 50})


# ------------------------------------------------------------ extractors
def test_every_number_of_the_summaries_becomes_an_evidence_row():
    ev = Evidence(evidence())
    df = ev.frame()
    assert list(df.columns) == EV_COLUMNS
    assert set(df["quantity"]) <= set(QUANTITIES)
    # every method x baseline the equivalence sections pair, both errors, both cameras
    d = df[(df.quantity == "err_diff_lastlm_m") & (df.claim_id == "B-C1")]
    assert set(zip(d.scope, d.method, d.versus)) == {(c, m, b) for c in ("interior", "site-tilt") for m, b in (
        ("depth", "svd"), ("depth", "gdop"), ("depth", "cond"), ("random", "svd"), ("center", "svd"),
        ("closest", "svd"))}
    assert set(d[d.method == "random"]["role"]) == {"control"} and set(d[d.method == "depth"]["role"]) == {"as_written"}
    a = df[(df.quantity == "rms_err_arcsec") & (df.claim_id == "A-C2")]
    assert len(a) == len(table()) and set(a.role) == {"as_written", "faithful", "diagnostic"}
    # the roll-rate curve as a sweep, the published values as rows
    assert len(df[(df.quantity == "crlb_published_data_arcsec") & (df.claim_id == "A-C1")]) == 4
    assert ((df.role == "published") & (df.quantity == "reduction_pct") & (df.estimate == 29.03)).any()


def test_an_old_summary_without_a_yaw_block_is_read_from_its_sentence():
    s = _scenario()
    s.pop("yaw_sigma3_deg")
    s["yaw_reason"] = "yaw 3-sigma over the 300 runs (depth): 2.46 deg at start, 2.54 deg at touchdown (not below 50%)"
    rows = B.evidence_rows({"scenarios": {"interior": s}, "headline_scenario": "interior"}, "main", "x", PLAN)
    y = [r for r in rows if r.quantity == "yaw_sigma3_ratio"]
    assert len(y) == 1 and y[0].method == "depth" and abs(y[0].estimate - 2.54 / 2.46) < 1e-12


def test_timing_rows_per_replay_between_replays_and_every_pair():
    sb = summary_b(interior={"planning": planning_time()}, **{"site-tilt": {"planning": planning_time()}})
    df = Evidence(evidence(sb=sb)).frame()
    t = df[(df.quantity == "reduction_pct") & (df.claim_id == "B-C4") & (df.scope == "interior")]
    assert {"replay1", "replay2", "replay3", "between_replays"} <= set(t["sample"])
    bw = t[(t["sample"] == "between_replays") & (t.versus == "svd") & (t.setting == "")].iloc[0]
    assert bw.estimate == pytest.approx(26.0) and bw.n == 3 and bw.se == pytest.approx(2.0 / math.sqrt(3))
    pairs = df[(df.quantity == "reduction_pct") & (df.claim_id == "B-C9") & (df["sample"] == "between_replays")
               & (df.setting == "")]
    assert {("svd", "gdop"), ("svd", "cond")} <= set(zip(pairs.method, pairs.versus))


# ------------------------------------------------------------ claim rows
def test_claims_from_hand_made_summaries_and_their_verdicts():
    rows, ev, _ = built()
    assert rows["A-C1"].verdict == C.REPRODUCED and rows["B-C1"].verdict == C.REPRODUCED
    assert rows["B-C3"].verdict == C.REPRODUCED and rows["B-C2"].verdict == C.REPRODUCED
    assert rows["B-C4"].verdict == C.NOT_TESTED, "no planning_time: one replay at most"
    assert rows["B-C8"].verdict == C.NOT_TESTED and "calls_multi_minimum" in rows["B-C8"].named
    rows, _, _ = built(t1=table(literal={"err": 20.0, "bound": 20.6}, roll={"err": 1.0, "bound": 0.9}))
    r = rows["A-C1"]
    assert r.verdict == C.WITH_ADDITION and "roll" in r.named and r.best_variant == "roll"
    assert "roll" in r.would_take
    assert all(x.plan == PLAN.stamp for x in rows.values())


def test_every_number_a_claim_row_quotes_is_a_row_of_evidence_or_of_the_plan():
    """Cause, would_take, ours, bound: each number is an estimate, lo or hi of an evidence row
    keyed to the claim, a published value, or a number of the plan (margins, settings, level):
    claims.unquoted_numbers, the rule benchmarks/claims_agree.py applies to a build."""
    sb = summary_b(interior={"planning": planning_time(), "d_depth": 0.05}, **{"site-tilt": {"planning": planning_time()}})
    rows, ev, _ = built(t1=table(literal={"err": 20.0, "bound": 20.6}), sb=sb,
                        optima={"interior": {"n_calls": 409, "calls_multi_minimum": 0}})
    assert C.unquoted_numbers(PLAN, rows.values(), ev) == []
    # a control: a number in no row is found
    r = next(iter(rows.values()))
    bad = C.ClaimRow(**{**r.__dict__, "cause": r.cause + " (123.456 m)"})
    assert any("123" in x for x in C.unquoted_numbers(PLAN, [bad], ev))


def test_evidence_csv_and_claims_agree_after_a_round_trip(tmp_path):
    ev = evidence()
    write_csv(ev, tmp_path / "evidence.csv")
    back = read_csv(tmp_path / "evidence.csv")
    a, _, _ = C.build(PLAN, ev, C.replication_plan(PLAN, {}))
    b, _, _ = C.build(PLAN, list(back), C.replication_plan(PLAN, {}))
    assert [(x.claim_id, x.verdict, x.cause) for x in a] == [(x.claim_id, x.verdict, x.cause) for x in b]


def test_claim_rows_are_records_that_refuse_an_unknown_verdict_or_a_missing_name():
    with pytest.raises(ValueError, match="verdict"):
        C.ClaimRow("A", "A-C1", "x", "y", verdict="great")
    with pytest.raises(ValueError, match="named"):
        C.ClaimRow("A", "A-C1", "x", "y", verdict=C.NOT_TESTED)
    long = " ".join(["word"] * 60) + "."
    assert len(C.one_sentence("A-C1", long).split()) <= C.MAX_CAUSE_WORDS
    df = C.frame([C.ClaimRow("A", "A-C1", "x", "y", verdict=C.REPRODUCED)])
    assert list(df.columns) == C.COLUMNS and C.records(df)[0].verdict == C.REPRODUCED


def test_a_replication_that_moves_is_unstable_in_the_table():
    rep = summary_b(interior={"d_depth": 0.08}, **{"site-tilt": {"d_depth": 0.08}})
    rows, _, _ = built(rep_b=rep)
    r = rows["B-C1"]
    assert r.verdict == C.UNSTABLE and r.verdict_replication == C.NOT_REPRODUCED
    assert "verdict_main: reproduced" in r.flags and r.ours_replication


# ------------------------------------------------------------ amendments
def test_amendments_are_recomputed_on_the_same_evidence():
    """Each amendment's verdicts before -> after on this evidence: A-C3's tolerance 200 -> 50
    samples turns a count 150 samples off from reproduced into not reproduced; A-C7's bound
    (information -> floor) moves it from not reproducible to depends on a choice."""
    t1 = table(literal={"err": 1.0, "bound": 0.5, "after": 40.0, "true_theta": 30.0},
               roll={"after": 40.0, "true_theta": 30.0})
    t1.loc[t1["case_id"] == "T1-11", "data_to_converge_samples"] = 1350.0
    am = C.amendments(PLAN, evidence(t1=t1), C.replication_plan(PLAN, {}))
    assert list(am.columns) == C.AMENDMENT_COLUMNS
    a3 = am[am["what"].str.startswith("A-C3's tolerance") & (am["claim_id"] == "A-C3")]
    assert len(a3) == 1 and a3.iloc[0]["verdict_before"] == C.REPRODUCED
    assert a3.iloc[0]["verdict_after"] in (C.NOT_REPRODUCED, C.WITH_ADDITION)
    a7 = am[am["what"].str.startswith("A-C7's bound") & (am["claim_id"] == "A-C7")].iloc[0]
    assert (a7["verdict_before"], a7["verdict_after"]) == (C.NOT_REPRODUCIBLE, C.DEPENDS)
    from opnav.report.manuscript import prose_tex

    tex = C.amendments_latex(am, PLAN, prose_tex)
    assert "A-C3" in tex and PLAN.checksum in tex and "2026-12-04" in tex


# ------------------------------------------------------------ prose
def test_abstract_sentence_changes_with_a_verdict():
    rows, _, _ = built()
    df = C.frame(rows.values())
    a = C.abstract(df)
    df2 = df.copy()
    df2.loc[df2["claim_id"] == "A-C1", "verdict"] = C.NOT_REPRODUCED
    assert C.abstract(df2) != a and "not reproduced" in C.abstract(df2)


def test_a_choice_claims_best_reading_is_where_it_holds_never_where_depth_does_worse():
    """Issue 55 item 9: B-C1 held in one camera and failed in the other, with depth worse than
    SVD there; e19e33d's table named the failing camera (site-tilt) as the 'best faithful
    variant'. The best reading is the camera where the claim holds, 'ours, as written' quotes
    the one where it fails, whichever camera is listed first."""
    for good, bad in (("interior", "site-tilt"), ("site-tilt", "interior")):
        sb = summary_b(**{good: {"d_depth": 0.0}, bad: {"d_depth": 0.08}})   # depth worse than SVD in `bad`
        rows, _, _ = built(sb=sb)
        r = rows["B-C1"]
        assert r.verdict == C.DEPENDS, r
        assert r.best_variant == good and f"({good})" in r.ours_best and "+0.08" not in r.ours_best, r
        assert f"({bad})" in r.ours_as_written and "+0.08" in r.ours_as_written, r
    # nothing holds anywhere: no best reading at all
    rows, _, _ = built(sb=summary_b(interior={"d_depth": 0.08}, **{"site-tilt": {"d_depth": 0.08}}))
    assert rows["B-C1"].verdict == C.NOT_REPRODUCED and rows["B-C1"].best_variant == ""
