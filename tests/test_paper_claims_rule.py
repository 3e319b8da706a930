"""The paper_claims job (workflow/scripts/paper_claims.py) on hand-made summaries: it writes
the claims table with the contract's columns, the analysis-plan table, the inputs table and,
given a replication sample, its verdicts beside the main ones."""

import json
import runpy
from pathlib import Path

import pandas as pd
import yaml

from opnav.report import claims as C
from test_claims import SUMMARY_A, summary_b, table

REPO = Path(__file__).resolve().parents[1]
CFG = yaml.safe_load((REPO / "config" / "config.yaml").read_text())


class _Files(dict):
    """Snakemake's named lists as the script reads them (keys(), [k] and .k)."""

    def __getattr__(self, k):
        return self[k]


class _Job:
    def __init__(self, inp, out, params, log):
        self.input, self.output, self.params, self.log = _Files(inp), _Files(out), _Files(params), [log]


def _run(tmp_path, rep_faster=None, profile="full"):
    a_sum, b_sum = tmp_path / "A-summary.json", tmp_path / "B-summary.json"
    a_sum.write_text(json.dumps(SUMMARY_A))
    b_sum.write_text(json.dumps(summary_b()))
    t1 = tmp_path / "A-T1.csv"
    table().to_csv(t1, index=False)
    inp = {"summary_A": str(a_sum), "summary_B": str(b_sum), "a_table1": str(t1),
           "plan": str(C.PLAN_FILE)}
    if rep_faster is not None:
        rb = tmp_path / "rep-B-summary.json"
        rb.write_text(json.dumps(summary_b(interior={"faster": rep_faster}, **{"site-tilt": {"faster": rep_faster}})))
        inp["rep_summary_B"] = str(rb)
    opt = tmp_path / "optima.json"
    opt.write_text(json.dumps({"scenario": "interior", "n_calls": 409, "calls_multi_minimum": 0}))
    inp["optima"] = [str(opt)]
    out = {k: str(tmp_path / f"out.{k}") for k in ("csv", "md", "tex", "detail", "json", "plan", "inputs", "evidence",
                                                    "amendments", "amendments_tex", "would_take_tex")}
    sweep = [cid for cid, t in C.load_plan().tests().items() if any(w.kind == "sweep" for w in t.would_take)]
    out["would_take"] = [str(tmp_path / f"wt_{c}.png") for c in sweep]
    lc = CFG["landing"]
    params = {"profile": profile, "replication": CFG["replication"], "windows": {"sliding": 50, "growing": 250}, "dt_s": 0.5,
              "sweep_claims": sweep, "landing": {k: lc[k] for k in ("duration_s", "gravity_mps2", "initial_state", "yaw_deg",
                                             "terminal_accel_mps2")}}
    runpy.run_path(str(REPO / "workflow" / "scripts" / "paper_claims.py"),
                   init_globals={"snakemake": _Job(inp, out, params, str(tmp_path / "log.txt"))})
    return {k: (Path(v) if isinstance(v, str) else [Path(x) for x in v]) for k, v in out.items()}


def test_the_job_writes_claims_plan_and_inputs(tmp_path):
    """The job writes evidence.csv and claims.csv that agree: the claims re-judged from the
    written evidence give the same rows; the amendments, their LaTeX and the figures exist."""
    from opnav.report import evidence

    out = _run(tmp_path)
    df = pd.read_csv(out["csv"], keep_default_na=False)
    assert list(df.columns) == C.COLUMNS and (df["sample"] == "full").all()
    ev = evidence.read_csv(out["evidence"])
    plan = C.load_plan()
    rows, _, _ = C.build(plan, [r for r in ev if r.role != "derived"], C.replication_plan(plan, {}))
    assert [r.verdict for r in rows] == list(df["verdict"]) and [r.cause for r in rows] == list(df["cause"])
    assert (df["plan"] == plan.stamp).all()
    assert df.set_index("claim_id").loc["B-C8", "verdict"] != C.NOT_TESTED, "B-C8 read the optima count"
    am = pd.read_csv(out["amendments"], keep_default_na=False)
    assert list(am.columns) == C.AMENDMENT_COLUMNS and len(am) >= len(plan.amendments())
    assert all(p.exists() and p.stat().st_size > 1000 for p in out["would_take"])
    wt = out["would_take_tex"].read_text()   # the appendix's figures: one per swept claim, each with its caption
    assert wt.count("\\begin{figure}") == len(out["would_take"])
    assert all(f"would_take/{p.name[3:-4]}.pdf" in wt and f"{p.name[3:-4]}: what it would take" in wt
               for p in out["would_take"])
    assert (df["verdict_replication"] == "").all(), "no replication sample was given"
    plan = pd.read_csv(out["plan"])
    assert list(plan.columns) == C.PLAN_COLUMNS and set(plan["claim_id"]) == set(df["claim_id"])
    ins = pd.read_csv(out["inputs"]).set_index("input")
    assert list(ins.columns) == C.INPUT_COLUMNS[1:]
    yaw = ins.loc["B Table 1 initial yaw (thrust azimuth)"]
    assert yaw["published"].startswith("-25.7 deg") and "terminal horizontal acceleration" in yaw["what_would_match"]
    assert "azimuth 25.70 deg" in yaw["what_would_match"], "the derived acceleration matches the published yaw"
    assert "0.96 s" in ins.loc["A sample time", "published"]
    j = json.loads(out["json"].read_text())
    assert j["text"]["sample"] == "" and j["sample"] == "full"


def test_the_job_reads_the_replication_and_marks_the_quick_profile(tmp_path):
    """Replication: depth minus SVD time to converge -0.2 s [-0.5, +0.1] against the main's -3 s
    [-5, -1]: the estimates differ (z about 3.3), so B-C2 is unstable."""
    out = _run(tmp_path, rep_faster=(-0.2, -0.5, 0.1), profile="quick")
    df = pd.read_csv(out["csv"], keep_default_na=False).set_index("claim_id")
    assert df.loc["B-C2", "verdict"] == C.UNSTABLE and df.loc["B-C2", "verdict_replication"] == C.NOT_REPRODUCED
    assert df.loc["B-C1", "verdict_replication"] == C.REPRODUCED and df.loc["A-C1", "verdict_replication"] == ""
    assert (df["sample"] == "quick").all() and df["flags"].str.contains("sample_too_small: quick profile").all()
    assert "too small for verdicts" in json.loads(out["json"].read_text())["text"]["sample"]
