"""Paper B's reporting pieces: B-T3, the summary JSON, and the pieces for the
manuscript and the scorecard (the report layer: it reads opnav.landing, never the reverse).

:func:`summary_table` is B-T3 (per-method accuracy and replayed planning time of
one camera scenario); :func:`scenario_summary` is that scenario's summary JSON
(the headline numbers the manuscript and the scorecard read).
:data:`COMPACT_VIEWS` are the page views of B-T3 and B-X1 (tables too wide for a
page; :mod:`opnav.report.manuscript` gathers both papers'); :func:`rows_paper_b` are paper
B's scorecard rows (timing claim, the "almost the same accuracy" claim read as an
equivalence test that must be able to fail, the yaw claim, the initial attitude),
scored by :mod:`opnav.report.scorecard` with the rule of :mod:`opnav.core.verdicts`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from opnav.core import wording
from opnav.core.tables import cell_num, cell_pm
from opnav.core.verdicts import NOT_REPRODUCED, REPRODUCED, Verdict, judge
from opnav.landing.bsummary import NAN, BSummary, ScenarioSummary, num
from opnav.report.landing.timing_text import CLOCK_WORDS, less_time_text, sources_text

# pandas is imported by the functions that build frames: the jobs that only combine the
# scenarios' summaries (combine_scenarios) do without its ~0.13 s of import
if TYPE_CHECKING:
    from typing import Mapping

    import pandas as pd

    from opnav.landing.accuracy import AccuracyTests
    from opnav.landing.montecarlo import NeesConsistency, YawConvergence
    from opnav.landing.records import MonteCarlo, Replay
    from opnav.landing.setup import Setup
    from opnav.landing.timing_summary import ClockShare, MethodSummary, PlanningTimeEvidence, VsDepthReading
    from opnav.landing.tuning import RetunedRecord


def summary_table(data: dict[str, MonteCarlo], timing: "Replay", published_reduction_vs_svd: float | None = None,
                  converged_pos_err_m: float = 100.0) -> pd.DataFrame:
    """B-T3 (paper B sec. 3, Table 3): one row per method of ``data`` (method ->
    gathered Monte Carlo, ``opnav.landing.montecarlo.gather``).

    Columns: over the runs, final (touchdown) and RMS (over time) error norms of
    position (m), velocity (m/s) and attitude (deg), each as mean and ``3 sigma``
    (three sample standard deviations), medians, the same at the last vision
    update (``lastvis_``), the share of converged runs, mean NEES, landmarks per
    run (``montecarlo.per_run_stats``); the median objective evaluations per
    call (the descent's count), the edge-rule share and pick ratios
    (``montecarlo.pick_quality``); per pair of methods the same-pick rate,
    median ``|delta beta*|`` and the paired RMS / final position differences with
    their intervals (``ranking.pair_comparison``). Planning times come from
    ``timing`` (the replay of the scenario's planning calls,
    ``opnav.landing.timing.replay``, every method of ``data`` timed), not from
    the descent: the median wall and CPU (``thread_time_ns``) time of a call
    (us) on the configured and the alternative metric path (``timed_calls``,
    ``timed_calls_alt``: the calls each rests on; the paper's definition is timed
    on a subset, ``landing.timing.max_calls_paper``), and each method's time
    reduction against each other ``100 (1 - median_a / median_b)`` (%) on the
    same replayed calls (for ``_alt``: those timed on both variants), with a
    paired bootstrap standard deviation (``timing_summary.time_reduction``). ``converged_runs_pct`` counts the runs whose
    final position error is below ``converged_pos_err_m`` (m); the published
    reduction, if given, is a column labelled ``_published`` on the depth row."""
    import pandas as pd

    # imported here: the manuscript and scorecard jobs import this module for its
    # page views and need neither scipy (ranking) nor the replay
    from opnav.landing import timing_summary as tsum
    from opnav.landing.montecarlo import per_run_stats, pick_quality, same_pick_pct
    from opnav.landing.ranking import pair_comparison

    methods = list(data)
    missing = [m for m in methods if tsum.times_ns(timing, m).size == 0 and len(timing.source)]
    if missing:
        raise ValueError(f"the planning-time replay did not time {missing}")
    rows = []
    for m in methods:
        st = per_run_stats(data[m])
        row = {"method": m, "n_runs": len(st)}
        for q in ("pos_err_m", "vel_err_mps", "att_err_deg"):
            for kind in ("final", "rms"):
                col = st[f"{kind}_{q}"]
                row[f"{kind}_{q}_mean"] = float(col.mean())
                row[f"{kind}_{q}_3sigma"] = float(3.0 * col.std(ddof=1)) if len(col) > 1 else math.nan
        row["final_pos_err_m_median"] = float(st["final_pos_err_m"].median())
        row["final_vel_err_mps_median"] = float(st["final_vel_err_mps"].median())
        # at the last vision update (before the IMU-only coast), at the last landmark
        # update and RMS over the landmark-tracking phase (what selection can move)
        for kind in ("lastvis", "lastlm", "lmrms"):
            for q in ("pos_err_m", "vel_err_mps"):
                if f"{kind}_{q}" not in st:
                    continue
                col = st[f"{kind}_{q}"]
                row[f"{kind}_{q}_mean"] = float(col.mean())
                row[f"{kind}_{q}_median"] = float(col.median())
                row[f"{kind}_{q}_3sigma"] = float(3.0 * col.std(ddof=1)) if len(col) > 1 else math.nan
        row["converged_runs_pct"] = float(100.0 * (st["final_pos_err_m"] < converged_pos_err_m).mean())
        row["mean_nees_pos"] = float(st["mean_nees_pos"].mean())
        row["mean_nees_vel"] = float(st["mean_nees_vel"].mean())
        row["landmarks_per_run"] = float(st["n_landmarks"].mean())
        alt_m = "alt" if tsum.times_ns(timing, m, "alt").size else "main"
        row["median_plan_time_us"] = tsum.median_us(timing, m)
        row["median_plan_cpu_us"] = tsum.median_us(timing, m, clock="cpu")
        # the same replayed calls on the alternative metric path (the configured one
        # for methods without it)
        row["median_plan_time_alt_us"] = tsum.median_us(timing, m, alt_m)
        row["median_plan_cpu_alt_us"] = tsum.median_us(timing, m, alt_m, clock="cpu")
        row["timed_calls"] = int(len(timing.source))
        # the alternative path's medians rest on its own calls (the paper path: a subset,
        # landing.timing.max_calls_paper), its reductions on the calls timed on both
        row["timed_calls_alt"] = tsum.timed_calls(timing, m, alt_m)
        ev = data[m].plan_evals
        row["metric_evals_per_call"] = float(np.median(ev)) if len(ev) else math.nan
        row["plan_calls"] = int(len(ev))
        pq = pick_quality(data[m])
        row.update(edge_calls_pct=pq.edge_calls_pct, pick_ratio_median=pq.pick_ratio_median,
                   pick_ratio_max=pq.pick_ratio_max)
        if m != methods[0]:
            row[f"same_pick_as_{methods[0]}_pct"] = same_pick_pct(data[m], data[methods[0]])
        for b in methods:
            if b == m:
                continue
            pc = pair_comparison(data[m], data[b])
            row[f"same_pick_vs_{b}_pct"] = pc.same_pick_pct
            row[f"median_abs_dbeta_vs_{b}_deg"] = pc.median_abs_dbeta_deg
            for k in ("rms_pos", "final_pos"):
                row[f"d_{k}_vs_{b}_m"] = pc.diffs[k].m
                row[f"d_{k}_vs_{b}_lo_m"] = pc.diffs[k].lo_m
                row[f"d_{k}_vs_{b}_hi_m"] = pc.diffs[k].hi_m
            red, sd = tsum.time_reduction(timing, m, b)
            row[f"time_reduction_vs_{b}_pct"] = red
            row[f"time_reduction_vs_{b}_pct_std"] = sd
            row[f"cpu_time_reduction_vs_{b}_pct"] = tsum.time_reduction(timing, m, b, clock="cpu",
                                                                       n_boot=0)[0]
            alt_b = "alt" if tsum.times_ns(timing, b, "alt").size else "main"
            red, sd = tsum.time_reduction(timing, m, b, path_a=alt_m, path_b=alt_b)
            row[f"time_reduction_vs_{b}_alt_pct"] = red
            row[f"time_reduction_vs_{b}_alt_pct_std"] = sd
        rows.append(row)
    df = pd.DataFrame(rows)
    if published_reduction_vs_svd is not None:
        df["time_reduction_vs_svd_pct_published"] = [
            float(published_reduction_vs_svd) if m == "depth" else math.nan for m in df["method"]]
    return df


@dataclass(frozen=True)
class TimingSection:
    """B-summary's ``timing``: the replay's method in numbers (``timing_summary.method_summary``,
    its fields at the top level) and the replayed calls' sources in words."""

    summary: "MethodSummary" = field(metadata={"json_flatten": True})
    sources_text: str


def scenario_summary(scenario: str, table: pd.DataFrame, data: dict[str, MonteCarlo], timing: "Replay",
                     single: dict, setup: Setup, *, eval_path: str, yaw_ratio: float,
                     published_reduction_vs_svd: float, accuracy: "AccuracyTests | None" = None) -> dict:
    """The summary JSON of one camera scenario (``B-summary.json`` per scenario,
    read by the manuscript macros and the scorecard, :func:`rows_paper_b`).

    ``table``: its B-T3 (:func:`summary_table` of ``data``, method -> gathered
    Monte Carlo); ``timing``: the replay behind it; ``single``: the single
    descent's summary; ``setup``: the scenario's landing setup (the
    initial attitude, ``scenario.initial_attitude_report``). Holds per method its
    B-T3 row, per pair of methods ``ranking.pair_comparison``, the depth method's
    time reduction against SVD (%, None unless both were flown) beside the
    published one, the replay's method (``timing_summary.method_summary``), the
    initial attitude (deg) in the paper's convention and as thrust tilt and
    azimuth, the yaw verdict (``montecarlo.yaw_convergence`` of the first
    method: does the 3-sigma envelope fall below ``yaw_ratio`` of its start?),
    the number of runs and the smallest same-pick rate of a method against
    depth (%, the check that an accuracy comparison could fail; nan without one),
    and ``accuracy``: ``landing.accuracy.accuracy_tests`` (its fields at the top level, the
    equivalence results and converges-faster readings with their sentences,
    ``report.landing.equivalence_text``).
    """
    from opnav.landing import timing_summary as tsum
    from opnav.landing.montecarlo import yaw_convergence
    from opnav.landing.ranking import pair_table
    from opnav.landing.scenario import initial_attitude_report

    methods = list(data)
    yaw = yaw_convergence(data[methods[0]], float(yaw_ratio), methods[0])
    ym = "depth" if "depth" in data else methods[0]
    yaw_err = np.asarray(data[ym].err_rpy_deg)[:, :, 2]
    pairs = pair_table(data)
    att = initial_attitude_report(setup)
    t = table.set_index("method")
    same_pick = [float(t.loc[m, "same_pick_as_depth_pct"]) for m in methods
                 if m != "depth" and "same_pick_as_depth_pct" in t.columns]
    out = {
        "scenario": scenario,
        "single": single,
        "methods": {r["method"]: dict(r) for r in table.to_dict("records")},
        "pairs": {f"{r['method_a']}_vs_{r['method_b']}": dict(r) for r in pairs.to_dict("records")},
        "time_reduction_vs_svd_pct": (float(t.loc["depth", "time_reduction_vs_svd_pct"])
                                      if {"svd", "depth"} <= set(t.index) else None),
        "eval_path": eval_path,
        # the reductions in words for the manuscript ("34.2 % less", "137.4 % more")
        "depth_vs_svd_time_text": {p: less_time_text(float(t.loc["depth", f"time_reduction_vs_svd{x}_pct"]))
                                   for p, x in (("path", ""), ("alt", "_alt"))
                                   if {"svd", "depth"} <= set(t.index)
                                   and f"time_reduction_vs_svd{x}_pct" in t.columns},
        "timing": TimingSection(ms := tsum.method_summary(timing), sources_text(ms.sources)),
        "published_time_reduction_vs_svd_pct": published_reduction_vs_svd,
        "initial_attitude_deg": att.paper_convention_deg,
        "initial_tilt_deg": att.tilt_deg,
        "initial_azimuth_deg": att.azimuth_deg,
        "yaw_converges": yaw.converges,
        "yaw_reason": yaw_reason(yaw),
        # the numbers behind it (the claims judge them against the analysis plan's ratio)
        "yaw_sigma3_deg": {"method": ym, "start": float(3 * yaw_err[:, 0].std(ddof=1)),
                           "end": float(3 * yaw_err[:, -1].std(ddof=1)), "n_runs": int(yaw_err.shape[0])},
        "n_runs": yaw.n_runs,
        "min_same_pick_vs_depth_pct": min(same_pick, default=math.nan),
        "planning_time_vs_depth": (vs := tsum.vs_depth(timing)),
        "planning_time": (ev := tsum.planning_time_evidence(timing, published_reduction_vs_svd)),  # B-C4, B-C9
        "planning_time_text": planning_time_text(vs, tsum.clock_share(timing), ev),
    }
    if accuracy is not None:     # the tests' records at the top level, their sentences beside them
        import dataclasses

        from opnav.report.landing.equivalence_text import Worded, converges_text, worded_section

        out.update((f.name, getattr(accuracy, f.name)) for f in dataclasses.fields(accuracy))
        out["equivalence"] = worded_section(accuracy.equivalence)
        out["equivalence_vs_baselines"] = {b: worded_section(v) for b, v in accuracy.equivalence_vs_baselines.items()}
        out["converges_faster"] = {m: Worded(v, converges_text(v)) for m, v in accuracy.converges_faster.items()}
        out["converges_faster_by_threshold"] = {t: {m: Worded(v, converges_text(v)) for m, v in per.items()}
                                                for t, per in accuracy.converges_faster_by_threshold.items()}
    return out


def yaw_reason(y: YawConvergence) -> str:
    """The yaw reading in words (``montecarlo.yaw_convergence``'s numbers)."""
    return (f"yaw 3-sigma over the {y.n_runs} runs ({y.method}): "
            f"{y.sigma3_start_deg:.2f} deg at start, {y.sigma3_end_deg:.2f} deg at touchdown "
            f"({'below' if y.converges else 'not below'} {y.ratio:.0%} of the start)")


def compact_b_t3(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """B-T3 for the page: per method final/RMS errors (mean, 3-sigma), NEES, timing."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        row = {"method": r["method"]}
        for q, unit in (("pos", "m"), ("vel", "mps"), ("att", "deg")):
            u = {"mps": "m/s"}.get(unit, unit)
            row[f"final {q} ({u})"] = cell_pm(r[f"final_{q}_err_{unit}_mean"], r[f"final_{q}_err_{unit}_3sigma"])
            row[f"RMS {q} ({u})"] = cell_pm(r[f"rms_{q}_err_{unit}_mean"], r[f"rms_{q}_err_{unit}_3sigma"])
            if q == "pos" and "lastlm_pos_err_m_mean" in df.columns:
                row["last-landmark pos (m)"] = cell_pm(r["lastlm_pos_err_m_mean"], r["lastlm_pos_err_m_3sigma"])
                row["landmark-phase RMS pos (m)"] = cell_pm(r["lmrms_pos_err_m_mean"], r["lmrms_pos_err_m_3sigma"])
        if "mean_nees_pos" in df.columns:
            row["NEES pos, vel"] = f"{cell_num(r['mean_nees_pos'], '{:.2f}')}, {cell_num(r.get('mean_nees_vel'), '{:.2f}')}"
        row["median plan (µs)"] = cell_num(r["median_plan_time_us"], "{:.0f}")
        if "metric_evals_per_call" in df.columns:
            row["evals/call"] = cell_num(r["metric_evals_per_call"], "{:.0f}")
        red = r.get("time_reduction_vs_svd_pct")
        row["time vs SVD (%)"] = "--" if red is None or pd.isna(red) else f"{-float(red):+.1f}"
        rows.append(row)
    return [("", pd.DataFrame(rows))]


def compact_b_x1(df: "pd.DataFrame") -> list[tuple[str, "pd.DataFrame"]]:
    """B-X1 for the page: every selection rule ranked, paired difference against depth."""
    import pandas as pd

    rows = []
    for _, r in df.iterrows():
        lo, hi = r.get("d_lastlm_pos_vs_ref_boot_lo"), r.get("d_lastlm_pos_vs_ref_boot_hi")
        rows.append({
            "method": r["method"],
            "rank acc., time": f"{cell_num(r.get('rank_accuracy'), '{:.0f}')}, {cell_num(r.get('rank_time'), '{:.0f}')}",
            "RMS pos (m)": cell_pm(r.get("rms_pos_err_m_mean"), r.get("rms_pos_err_m_3sigma")),
            "final pos (m)": cell_pm(r.get("final_pos_err_m_mean"), r.get("final_pos_err_m_3sigma")),
            "final vel (m/s)": cell_pm(r.get("final_vel_err_mps_mean"), r.get("final_vel_err_mps_3sigma")),
            "NEES pos": cell_num(r.get("mean_nees_pos"), "{:.2f}"),
            "median plan (µs)": cell_num(r.get("median_plan_time_us"), "{:.0f}"),
            "last-landmark pos (m)": cell_pm(r.get("lastlm_pos_err_m_mean"), r.get("lastlm_pos_err_m_3sigma")),
            "last-landmark pos minus depth (m), 95 % CI": f"{cell_num(r.get('d_lastlm_pos_vs_ref_mean'), '{:.3g}')} [{cell_num(lo, '{:.3g}')}, {cell_num(hi, '{:.3g}')}]",
            "same pick (%)": cell_num(r.get("same_pick_as_ref_pct"), "{:.1f}"),
        })
    return [("", pd.DataFrame(rows))]


def combine_scenarios(parts: dict[str, dict], headline: str, cameras: dict[str, dict]) -> dict:
    """One summary of every camera scenario (B-summary.json, B-X1-summary.json): the
    headline scenario's summary at the top level, every scenario's (with its camera)
    under ``scenarios``, in the given order."""
    out = dict(parts[headline])
    out["scenarios"] = {n: {**p, "camera": cameras.get(n, {})} for n, p in parts.items()}
    out["headline_scenario"] = headline
    out["scenario_names_text"] = ", ".join(parts)
    return out


#: Page views of paper B's tables too wide for a page, by SPEC id.
COMPACT_VIEWS = {"B-T3": compact_b_t3, "B-X1": compact_b_x1}


def same_accuracy_verdict(s: ScenarioSummary, method: str = "depth") -> Verdict:
    """Verdict on "almost the same accuracy" (``method`` vs the equivalence
    reference) from one scenario's summary (``opnav.landing.bsummary.ScenarioSummary``: the
    document :func:`opnav.landing.accuracy.accuracy_tests` wrote, read back), by the claims
    table's rule (B-C1 of the analysis plan; its margin and same-pick threshold are the ones
    recorded in the summary): not tested when the two methods pick the same landmark in
    ``same_pick_max_pct`` of the planning calls or more (equal accuracy then
    follows by construction) or the margin is 0; else reproduced iff the paired
    equivalence test shows ``method`` equivalent on both primary metrics. A
    negative control (``random``, ``center``, ``closest``) that passes too does
    not change the verdict: the reason says the test cannot credit the metric.
    The reason names margin, metric, same-pick rate and the controls' verdicts."""
    eq = s.equivalence
    if eq is None or s.same_pick_max_pct is None or eq.margin_rel is None:
        raise ValueError("landing summary: no same_pick_max_pct / margin_rel from the analysis plan "
                         "(a summary of an older build: rebuild landing_summary)")
    pick_max = float(s.same_pick_max_pct)
    res = eq.methods[method]
    ctrl = "; ".join(f"{c} {eq.methods[c].verdict}" for c in s.controls)
    why = f"{res.text}; negative controls vs {eq.reference}: {ctrl or 'none'}"
    sp = NAN if res.same_pick_pct is None else res.same_pick_pct
    if not math.isnan(sp) and sp >= pick_max:
        return Verdict(NOT_REPRODUCED, f"not tested (same pick >= {pick_max:g} %): {why}")
    from opnav.landing.equivalence import PRIMARY_METRICS

    if any(eq.metrics[q].margin <= 0 for q in PRIMARY_METRICS):
        return Verdict(NOT_REPRODUCED, f"not tested ({eq.reference}'s mean error is not positive, "
                                       f"margin 0): {why}")
    if res.equivalent and s.controls_equivalent:
        return Verdict(REPRODUCED, f"{why}; but the controls {', '.join(s.controls_equivalent)} "
                                   "pass it too, so the test cannot credit the metric")
    return Verdict(REPRODUCED if res.equivalent else NOT_REPRODUCED, why)


def _rows_paper_b_scenario(t3: pd.DataFrame, s: ScenarioSummary, pub: dict, label: str,
                           timing_band: dict | None = None) -> list[dict]:
    rows: list[dict] = []
    tag = f"[{label}] " if label else ""
    t3 = t3.set_index("method")
    between = s.planning_time.reduction_pct.get("depth_vs_svd") if s.planning_time is not None else None
    if between is not None and (between.interval or "between_replays") == "between_replays":
        # judged as the claims table judges B-C4: the mean over independent replays, its spread the
        # sd between them (never one replay's bootstrap over the calls)
        rows.append({"paper": "B", "item": f"{tag}median planning time, depth vs SVD: reduction "
                                           f"(mean of {len(between.per_replay)} replays)",
                     "published": float(pub["depth_time_reduction_vs_svd_pct"]), "ours": num(between.mean),
                     "spread": num(between.sd_between), "unit": "%",
                     "band": dict(timing_band or {})})
    elif "depth" in t3.index and "time_reduction_vs_svd_pct" in t3.columns:
        # the claim's size depends on how the planning call is implemented: the
        # configured path and the other one (compiled vs the paper's definition
        # interpreted, opnav.landing.planner), each a row
        path = s.eval_path
        other = {"compiled": "paper", "paper": "compiled"}.get(path, "") if path else ""
        for suffix, p in (("", path), ("_alt", other)):
            col = f"time_reduction_vs_svd{suffix}_pct"
            if col not in t3.columns:
                continue
            spread = t3.loc["depth"].get(f"{col}_std", float("nan"))
            rows.append({"paper": "B", "item": f"{tag}median planning time, depth vs SVD: reduction"
                                               + (f" (SVD on the {p} path)" if p else ""),
                         "published": float(pub["depth_time_reduction_vs_svd_pct"]),
                         "ours": float(t3.loc["depth", col]),
                         "spread": float(spread), "unit": "%", "band": dict(timing_band or {})})
    if s.equivalence is not None:
        ref = s.equivalence.reference
        for m, cf in s.converges_faster.items():
            v = same_accuracy_verdict(s, m)
            ours = s.equivalence.methods[m].tests["lastlm_pos_err_m"].mean
            rows.append({"paper": "B", "item": f"{tag}{m} vs {ref}: 'almost the same' accuracy "
                                               "(paired equivalence, negative controls)",
                         "published": float("nan"), "ours": ours, "unit": "m",
                         "verdict": v.verdict, "reason": v.reason})
            if cf.min_difference_s is None:
                raise ValueError("landing summary: converges_faster has no min_difference_s from the analysis "
                                 "plan (a summary of an older build: rebuild landing_summary)")
            rows.append({"paper": "B", "item": f"{tag}position error converges a bit faster with {m} "
                                               f"than {ref}",
                         "published": float("nan"), "ours": cf.mean_s, "unit": "s",
                         "verdict": REPRODUCED if cf.verdict == "faster" else NOT_REPRODUCED,
                         "reason": cf.text})
    if s.yaw_converges is not None:
        rows.append({"paper": "B", "item": f"{tag}yaw error does not converge (one known landmark)",
                     "published": float("nan"), "ours": float("nan"), "unit": "",
                     "verdict": REPRODUCED if not s.yaw_converges else NOT_REPRODUCED,
                     "reason": s.yaw_reason if s.yaw_reason is not None else "from the Monte-Carlo attitude envelopes"})
    return rows


def rows_paper_b(t3: pd.DataFrame, summary: BSummary, pub: dict, timing_band: dict | None = None) -> list[dict]:
    """Scorecard rows for paper B: per camera scenario of ``summary`` (B-summary.json read back,
    ``opnav.landing.bsummary.BSummary``: each scenario with its B-T3 rows; a summary of one
    scenario, ``combined`` false, with ``t3``) the 29.03 % timing claim and the accuracy claims;
    once, the initial attitude scored as thrust tilt and azimuth separately (the paper's triple
    read as -(yaw, pitch, roll), Z-Y-X, roll 0). ``timing_band``: the analysis plan's B-C4
    ``rel_tol``, ``k_spread``, ``max_band_rel`` for the timing rows (passed in by the
    workflow; without it, :mod:`opnav.core.verdicts`' defaults)."""
    import pandas as pd

    rows: list[dict] = []
    if summary.combined:
        for name, sc in summary.scenarios.items():
            rows += _rows_paper_b_scenario(pd.DataFrame(list(sc.methods.values())), sc, pub, name, timing_band)
    else:
        rows += _rows_paper_b_scenario(t3, summary.scenarios[summary.headline], pub, "", timing_band)
    if summary.initial_tilt_deg is not None:
        att = pub["table1_initial_state"]["att_deg"]
        for item, published_v, ours, why in (
                ("initial thrust tilt from the vertical (paper: -pitch)", -float(att[1]),
                 float(summary.initial_tilt_deg), "set by the Table 1 state and the touchdown"),
                ("initial thrust azimuth (paper: -yaw)", -float(att[0]),
                 float(summary.initial_azimuth_deg),
                 "depends on the terminal horizontal acceleration (landing.terminal_accel_mps2), "
                 "which the paper does not state")):
            v = judge(published_v, ours, abs_tol=1.0, unit="deg")
            rows.append({"paper": "B", "item": item, "published": published_v, "ours": ours,
                         "unit": "deg", "verdict": v.verdict, "reason": f"{v.reason}; {why}"})
    return rows


# ------------------------------------------------------------ the descent's end and NEES, in words

def end_phase_table(data: dict[str, dict], alt_true_m: np.ndarray, margin_m: float,
                    ground_m: float = 1.0) -> "pd.DataFrame":
    """The end-phase table of one scenario: one row per method of ``data`` (gathered Monte
    Carlo), :func:`opnav.landing.montecarlo.end_phase` of its per-step records against the
    true altitude ``alt_true_m`` at each filter time (m)."""
    import pandas as pd

    from opnav.landing.montecarlo import end_phase

    import dataclasses

    return pd.DataFrame([{"method": m, **dataclasses.asdict(end_phase(d, alt_true_m, margin_m, ground_m))}
                         for m, d in data.items()])


def _fmt(x, f="{:.0f}") -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f.format(x)


def _per_method(end: dict, key: str, f: str, methods: list[str], unit: str = " s") -> str:
    vals = [_fmt(end[m][key], f) for m in methods]
    if len(set(vals)) == 1:
        return vals[0] + unit
    return " / ".join(vals) + unit + " (" + " / ".join(methods) + ")"


def end_phase_text(end: dict[str, dict], scenario: str, min_update_alt_m: float,
                   methods: tuple = ("depth", "svd", "random")) -> str:
    """The manuscript's sentences about the end of the descent in camera ``scenario``, from
    its end-phase rows (``end``: method -> :func:`opnav.landing.montecarlo.end_phase`), for
    ``methods`` among them: when landmark updates and vision updates stop (medians over the
    runs), and how many runs take vision updates with the true altitude below the ground
    threshold and below the cut-off's margin."""
    ms = [m for m in methods if m in end] or list(end)[:3]
    e0 = end[ms[0]]
    n = e0["n_runs"]
    lm = _per_method(end, "last_lm_t_s_median", "{:.0f}", ms)
    vis = _per_method(end, "last_vis_t_s_median", "{:.0f}", ms)
    gap = _per_method(end, "vision_after_last_lm_s_median", "{:.0f}", ms)
    below = [end[m]["runs_vision_below_ground_m"] for m in ms]
    below_m = [end[m]["runs_vision_below_margin"] for m in ms]
    gaps = [end[m]["vision_after_last_lm_s_median"] for m in ms]
    if all(g is not None and g <= 0.5 for g in gaps):
        s = (f"In the {scenario} camera, landmark updates continue until vision ends (medians: last "
             f"landmark update {lm}, last vision update {vis}). ")
    else:
        s = (f"In the {scenario} camera, landmark updates stop at a median {lm}. Vision updates (then the "
             f"site's bearing alone) stop at {vis}, {gap} later. ")
    cut = (f"Vision stops once the estimated altitude less {e0['margin_m']:g} m falls to "
           f"{min_update_alt_m:g} m")
    if not any(below) and not any(below_m):
        return s + (f"{cut}; no run of {n} takes a vision update with the true altitude below "
                    f"{e0['margin_m']:g} m.")
    who = f" ({' / '.join(ms)})" if len(ms) > 1 else ""

    def counts(c):
        return " / ".join(str(x) for x in c)
    return s + (f"{cut}, and an estimate a few metres high keeps it on. Of {n} runs{who}, {counts(below)} "
                f"take vision updates with the true altitude below {e0['ground_m']:g} m and "
                f"{counts(below_m)} below {e0['margin_m']:g} m (lowest {_fmt(e0['min_true_alt_vision_m'], '{:.2f}')} m"
                f" for {ms[0]}).")


@dataclass(frozen=True)
class NeesReading:
    """The filter's consistency in words (:func:`nees_reading`; B-summary ``nees_reading``): per
    state its reading, the two together (``verdict``) and the sentence."""

    pos: str
    vel: str
    verdict: str
    text: str


def nees_reading(nees: "NeesConsistency", scenario: str | None = None) -> NeesReading:
    """The filter's consistency read from its held-out NEES (``montecarlo.nees_consistency``):
    per state (pos, vel) ``consistent`` if the time-averaged NEES of the run mean lies inside
    the 95 % band of an n-run mean, ``underconfident`` below it (the covariance larger than the
    errors), ``overconfident`` above it; and a sentence saying so with the numbers."""
    lo, hi = nees.band

    def reading(x: float) -> str:
        return "consistent" if lo <= x <= hi else "underconfident" if x < lo else "overconfident"

    pos, vel = reading(nees.pos_mean), reading(nees.vel_mean)
    verdict = pos if pos == vel else f"{pos} in position, {vel} in velocity"
    where = f" of the {scenario} camera" if scenario else ""
    return NeesReading(pos, vel, verdict, (
        f"On the held-out runs{where} the filter is {verdict}. Its mean NEES over {nees.n_runs} runs "
        f"is {nees.pos_mean:.2f} in position and {nees.vel_mean:.2f} in velocity, against the 95 % "
        f"band [{lo:.2f}, {hi:.2f}] of a {nees.n_runs}-run mean for 3 degrees of freedom. The run mean "
        f"lies in the band at {nees.pos_in_band_pct:.1f} % of the filter times in position and "
        f"{nees.vel_in_band_pct:.1f} % in velocity."))


def nees_table(retuned: "RetunedRecord") -> "pd.DataFrame":
    """The NEES table of one camera scenario from ``landing_retuned``'s record: one row per
    tuning (the paper's, flown by default; the retuned scale, :func:`opnav.landing.tuning.retune`),
    its bearing-noise scale and iterations, the tuning runs' mean NEES (position, velocity),
    the held-out NEES (mean over the filter times of the run mean), the share of filter times
    in the band (%), the reading (:func:`nees_reading`) and the median last-landmark and
    touchdown position errors (m)."""
    import pandas as pd

    rows = []
    for name, r in (("paper", retuned.paper), ("retuned", retuned.retuned)):
        h, e = r.heldout.nees, r.heldout.errors
        rows.append({"tuning": name, "meas_noise_scale": r.meas_noise_scale, "iterations": r.iterations,
                     "tuning_nees_pos": r.tuning_nees_pos, "tuning_nees_vel": r.tuning_nees_vel,
                     "heldout_nees_pos": h.pos_mean, "heldout_nees_vel": h.vel_mean,
                     "in_band_pct_pos": h.pos_in_band_pct, "in_band_pct_vel": h.vel_in_band_pct,
                     "reading": nees_reading(h).verdict,
                     "lastlm_pos_err_m_median": e.lastlm_pos_err_m_median,
                     "final_pos_err_m_median": e.final_pos_err_m_median})
    return pd.DataFrame(rows)


def nees_retuned_text(retuned: "RetunedRecord") -> str:
    """The manuscript's sentence on the retuned filter (``landing_retuned``'s record): the
    scale chosen on the tuning runs, its held-out NEES and shares in the band beside the
    paper tuning's errors, and, when the retuned filter is not consistent in both states,
    what the tuning runs show about why (their median and largest run against the mean)."""
    p, r = retuned.paper, retuned.retuned
    ph, rh = p.heldout.nees, r.heldout.nees
    pe, re_ = p.heldout.errors, r.heldout.errors
    lo, hi = rh.band
    rd = nees_reading(rh)
    n = retuned.tuning_n_runs
    s = (f"Retuned within the same protocol, the {retuned.scenario} camera's bearing-noise scale is "
         f"{r.meas_noise_scale:.3g} against the paper tuning's {p.meas_noise_scale:.3g}: the scale whose NEES "
         f"on the {n} tuning runs lies closest to the band's centre. Held out, its NEES is position "
         f"{rh.pos_mean:.2f} ({rd.pos}) and velocity {rh.vel_mean:.2f} ({rd.vel}) against "
         f"[{lo:.2f}, {hi:.2f}], in the band at {rh.pos_in_band_pct:.1f} % and {rh.vel_in_band_pct:.1f} % of "
         f"the filter times. The median position error at the last landmark update goes from "
         f"{_fmt(pe.lastlm_pos_err_m_median, '{:.2f}')} to {_fmt(re_.lastlm_pos_err_m_median, '{:.2f}')} m, "
         f"and at touchdown from {_fmt(pe.final_pos_err_m_median, '{:.2f}')} to "
         f"{_fmt(re_.final_pos_err_m_median, '{:.2f}')} m.")
    if rd.verdict == "consistent":
        return s
    tlo, thi = retuned.tuning_band
    if r.tuning_in_band:
        why = [f"On the {n} tuning runs both lay in their band [{tlo:.2f}, {thi:.2f}] "
               f"({r.tuning_nees_pos:.2f}, {r.tuning_nees_vel:.2f}): that sample does not pin the mean"]
    else:
        why = [f"No scale tried puts both in the band on the tuning runs either (closest: position "
               f"{r.tuning_nees_pos:.2f}, velocity {r.tuning_nees_vel:.2f} against [{tlo:.2f}, {thi:.2f}])"]
    if rd.pos != rd.vel:
        why.append(f"Held out, the velocity NEES is {rh.vel_mean / rh.pos_mean:.2f} times the position's "
                   f"({ph.vel_mean / ph.pos_mean:.2f} with the paper tuning), and one scale on the bearing noise "
                   "moves both together")
    med, big = r.tuning_nees_pos_run_median, r.tuning_nees_pos_run_max
    if big > HEAVY_TAIL_RATIO * med:
        why.append(f"The mean over runs rests on a few runs (position NEES of the median tuning run {med:.2f}, "
                   f"of the largest {big:.1f}): errors heavier-tailed than the Gaussian the filter assumes")
    return s + "".join(f" {w}." for w in why)


#: wording rule of :func:`nees_retuned_text`: a largest tuning run's NEES above this many times
#: the median run's is called heavy-tailed
HEAVY_TAIL_RATIO = 3.0


def planning_time_text(vs: "Mapping[str, VsDepthReading]", clock: "ClockShare",
                       ev: "PlanningTimeEvidence | None" = None) -> str:
    """The manuscript's sentence on planning time (thread CPU, per call; ``timing_summary.CLOCK``, the
    clock the verdicts read) from ``timing_summary.vs_depth`` and ``timing_summary.clock_share``: depth
    against SVD's closed form, a LAPACK SVD of the same H and the paper's definition, each with its
    paired 95 % interval, and the clock's measured cost; with ``ev``
    (``timing_summary.planning_time_evidence``) first the reading between independent replays, the
    call's shared part and evaluations, the shared part at which the published reduction would hold,
    and why the compiled and the paper's paths differ."""
    def part(label, name):   # one sentence per baseline (issue 55 item 4)
        v = vs.get(label)
        if not v:
            return None
        return (f"Against {name}: {wording.num(v.depth_median_us)} against {wording.num(v.median_us)} us (depth "
                f"{less_time_text(v.depth_reduction_pct)} time, 95 % interval of the reduction "
                f"[{v.depth_reduction_lo_pct:+.1f}, {v.depth_reduction_hi_pct:+.1f}] %).")
    parts = [p for p in (part("svd_closed_form", "the closed-form SVD"),
                         part("svd_lapack", "a LAPACK SVD of the same H"),
                         part("svd_paper", "the paper's definition of SVD (interpreted, depth likewise)")) if p]
    if not parts:
        return ""
    ck = ("" if clock.share_pct_max is None else
          f" Each call is the mean of back-to-back repetitions; the clock ({clock.clock_ns:.0f} ns a "
          f"reading pair) is at most {clock.share_pct_max:.1f} % of a timed bracket.")
    head = evidence_text(ev) if ev else ""
    return head + "Median planning call of depth (thread CPU, all replays pooled). " + " ".join(parts) + ck


def evidence_text(ev: "PlanningTimeEvidence") -> str:
    """The planning-time evidence (``timing_summary.planning_time_evidence``) in words: depth against
    SVD between independent replays, the shared part and the evaluations of a call, the shared part
    at which the published reduction would hold, and why the two paths differ. Empty without
    replayed depth and SVD."""
    import math

    r = ev.reduction_pct.get("depth_vs_svd")
    dec = ev.decomposition
    if not r or "depth" not in dec or "svd" not in dec:
        return ""
    per = ", ".join(f"{x:.1f}" for x in r.per_replay)
    sd = r.sd_between
    out = (f"Over {ev.n_replays} independent replays (each a separate process, alone on the machine; "
           f"clock: {CLOCK_WORDS}) depth's median call on the {ev.eval_path or ev.path} path took "
           f"{less_time_text(r.mean)} time than the closed-form SVD's on average. Per replay: {per} %"
           + (f"; between-replay sd {sd:.1f} points, {100 * r.level:.0f} % interval [{r.lo:.1f}, {r.hi:.1f}] %"
              if math.isfinite(sd) else "") + ". ")
    rp = ev.replays[0] if ev.replays else None
    lo_hi = rp.median_interval_us.get("depth") if rp else None
    if lo_hi and all(x is not None and math.isfinite(x) for x in lo_hi):
        out += (f"Each replay's median rests on {rp.n_calls} calls (depth's in the first replay "
                f"{rp.median_us['depth']:.2f} us, distribution-free 95 % interval [{lo_hi[0]:.2f}, {lo_hi[1]:.2f}] us). ")
    d, s = dec["depth"], dec["svd"]
    if all(math.isfinite(x) for x in (d.shared_us, s.shared_us, d.eval_us, s.eval_us)):
        c = ev.overhead_curve
        no_shared = c.no_shared_reduction_pct if c.no_shared_reduction_pct is not None else math.nan
        out += (f"A call is a part both methods share (numba's dispatch, argument unpacking, the search's own "
                f"steps: {d.shared_us:.2f} us for depth, {s.shared_us:.2f} us for SVD) and its evaluations. "
                f"Depth's {d.evals_per_call:.0f} evaluations of {1e3 * d.per_eval_us:.0f} ns take "
                f"{d.eval_us:.2f} us, SVD's {s.evals_per_call:.0f} of {1e3 * s.per_eval_us:.0f} ns "
                f"{s.eval_us:.2f} us. Without the shared part depth's median call "
                f"would take {less_time_text(no_shared)} time. ")
        sp = ev.shared_us_at_published
        pub = ev.published_pct
        if sp is not None and math.isfinite(sp):
            out += f"The published {pub:g} % would hold with a shared part of {sp:.2f} us. "
        elif pub is not None:
            out += f"No shared part would give the published {pub:g} %: the calls without it give less. "
        out += ("The shared part is what a busier machine lengthens, so the percentage moves with the load while "
                "the evaluations' difference stays. On the paper's definition (interpreted Python, CasADi and "
                "LAPACK) each evaluation costs tens of microseconds or more, the shared part is negligible and "
                "the reduction is the metrics' own, which is why the two paths read so differently. ")
    return out
