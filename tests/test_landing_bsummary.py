"""B-summary.json read back typed (issue 56 item 1): ``opnav.landing.bsummary``, what the claims'
evidence (report.landing_claims) and the scorecard (report.landing.summary.rows_paper_b) read by
meaning, never by the document's keys."""

from __future__ import annotations

import ast
import math
from pathlib import Path

from opnav.landing.bsummary import BSummary, ScenarioSummary


def _scenario(**over):
    s = {"scenario": "interior", "n_runs": 4, "eval_path": "compiled",
         "equivalence": {"reference": "svd", "alpha": 0.05, "margin_rel": 0.1,
                         "metrics": {"lastlm_pos_err_m": {"means": {"svd": 0.2, "depth": 0.1}, "margin": 0.02}},
                         "methods": {"depth": {"equivalent": True, "verdict": "equivalent", "text": "t",
                                               "same_pick_pct": 40.0,
                                               "lastlm_pos_err_m": {"mean": -0.01, "lo": -0.02, "hi": 0.0, "n": 4}}}},
         "errors": {"depth": {"rms_vel_err_mps": {"mean": 1.0, "median": 0.9, "3sigma": 2.0}}},
         "converges_faster": {"depth": {"versus": "svd", "mean_s": -1.0, "threshold_m": 100.0,
                                        "min_difference_s": 1.0, "verdict": "faster", "text": "x"}},
         "planning_time": {"reduction_pct": {"depth_vs_svd": {"per_replay": [20.0, 30.0], "mean": None,
                                                              "interval": "between_replays"}},
                           "replays": [{"n_calls": 20, "median_us": {"depth": 3.0}}]},
         "yaw_sigma3_deg": {"method": "depth", "start": 2.0, "end": 2.5, "n_runs": 4},
         "yaw_converges": False, "same_pick_max_pct": 90.0, "controls": ["random"]}
    s.update(over)
    return s


def test_a_scenario_reads_by_meaning():
    """Numbers, sections and the absent/null rule: a key written as null (NaN) reads NaN, an
    absent one None (the readers fall back on their own estimate only for an absent one)."""
    s = ScenarioSummary.from_json(_scenario())
    eq = s.equivalence
    assert (eq.reference, eq.alpha, eq.margin_rel) == ("svd", 0.05, 0.1)
    t = eq.methods["depth"].tests["lastlm_pos_err_m"]
    assert (t.mean, t.lo, t.hi, t.n) == (-0.01, -0.02, 0.0, 4) and math.isnan(t.se)
    assert eq.metrics["lastlm_pos_err_m"].means == {"svd": 0.2, "depth": 0.1}
    assert s.errors["depth"]["rms_vel_err_mps"].sigma3 == 2.0
    assert s.converges_faster["depth"].min_difference_s == 1.0 and s.converges_faster["depth"].verdict == "faster"
    r = s.planning_time.reduction_pct["depth_vs_svd"]
    assert math.isnan(r.mean) and r.sd_between is None and r.per_replay == (20.0, 30.0)
    assert s.planning_time.replays[0].median_us == {"depth": 3.0} and s.yaw_sigma3.end == 2.5
    bare = ScenarioSummary.from_json({})
    assert bare.equivalence is None and bare.planning_time is None and bare.n_runs == 0


def test_a_combined_document_keeps_its_scenarios_and_headline():
    d = {"scenarios": {"site-tilt": _scenario(scenario="site-tilt"), "interior": _scenario()},
         "headline_scenario": "interior", "initial_tilt_deg": 9.8, "initial_azimuth_deg": 16.5}
    b = BSummary.from_json(d)
    assert b.combined and b.headline == "interior" and b.headline_first == ["interior", "site-tilt"]
    assert b.initial_tilt_deg == 9.8 and b.scenarios["site-tilt"].n_runs == 4
    one = BSummary.from_json(_scenario())
    assert not one.combined and list(one.scenarios) == ["interior"]


def test_the_readers_read_no_summary_key():
    """report.landing_claims' evidence readers and the scorecard's B rows read the summary by
    attribute: their only constant-string lookups are into B-T3's rows (``row``, a table row by
    column), the published values (``pub``), the plan's inputs and keyed sections (a pair
    ``depth_vs_svd``, a metric). Mutation: ``s.get("n_runs")`` back in evidence_rows fails it."""
    import opnav.report as rep

    root = Path(rep.__file__).parent
    readers = {"landing_claims.py": ("_equivalence", "_converges", "_yaw", "_envelopes", "_planning_time",
                                     "_old_timing", "_optima", "evidence_rows", "input_rows"),
               "landing/summary.py": ("same_accuracy_verdict", "_rows_paper_b_scenario", "rows_paper_b")}
    allowed = {"row", "pub", "ins", "plan.raw", "s.planning_time.reduction_pct", "s.equivalence.methods[m].tests",
               "t3.loc", "pub['table1_initial_state']"}
    bad = []
    for rel, names in readers.items():
        tree = ast.parse((root / rel).read_text())
        for fn in (n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in names):
            for n in ast.walk(fn):
                on = None
                if isinstance(n, ast.Subscript) and isinstance(n.slice, ast.Constant) and isinstance(n.slice.value, str):
                    on = ast.unparse(n.value)
                elif (isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr == "get"
                      and n.args and isinstance(n.args[0], ast.Constant) and isinstance(n.args[0].value, str)):
                    on = ast.unparse(n.func.value)
                if on is not None and on not in allowed and not on.startswith(("ins.get(", "row.get(")):
                    bad.append(f"{rel}:{n.lineno} {fn.name}: {ast.unparse(n)[:60]}")
    assert not bad, "\n".join(bad)
