"""Paper B's evidence (depth-error landmark selection): every number B-summary.json holds that a
claim may read, as :class:`opnav.report.evidence.EvidenceRow` rows, with no verdict logic.

:func:`evidence_rows` reads one sample's B-summary.json (the dict
:func:`opnav.report.landing.summary.combine_scenarios` writes; each camera scenario is a ``scope``) and
writes, for every method and every baseline or control the summary pairs it with:

* ``err_diff_{lastlm,lmrms,final}_m``: the paired mean difference ``method - versus`` of the
  position error at the last landmark update, its RMS over the landmark phase and at touchdown
  (the equivalence sections, every reference they hold), m, with its interval and se;
* ``err_mean_{...}_m``: each method's own mean of the same errors (the margins' scale), m;
* ``same_pick_pct``: how often ``method`` picks ``versus``'s landmark, %;
* ``converge_time_diff_s``: ``method - versus`` first time below a position-error threshold,
  one row per threshold (``setting threshold_m=...``), s;
* ``yaw_sigma3_ratio``: the yaw 3-sigma at touchdown over the one at the start;
* ``envelope_ratio_{vel,att}``: 3-sigma of the RMS velocity / attitude error, ``method / versus``;
* ``reduction_pct`` and ``median_time_us``: planning time (thread CPU) per replay
  (``replay1``...), between replays (``between_replays``: mean, interval, se of the spread
  between independent replays), on each SVD implementation (``versus svd_lapack``,
  ``svd_paper``) and along the overhead curve (``setting shared_us=...``); ``per_eval_us``,
  ``shared_us``, ``evals_per_call`` (the decomposition of a call) and ``shared_us_at_published``;
* ``calls_multi_minimum`` (B-C8): planning calls whose depth error has more than one local
  minimum, from the optima count (:mod:`opnav.landing.optima`);
* the published values of published.yaml the claims quote (role ``published``).

Roles (the plan's ``variants`` blocks): the paper's method ``as_written``, the baselines it names
``compared``, the negative controls ``control``, any other method ``beyond`` (never judged).
Units: m, s, %, us, deg.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

from opnav.landing.bsummary import (BSummary, EquivalenceSection, OptimaCount, PlanningTime, ScenarioSummary, Stat,
                                    num)
from opnav.report.evidence import NAN, EvidenceRow, quantity, se_from_interval
from opnav.report.plan import Plan

ERR_KEYS = {"lastlm_pos_err_m": "lastlm", "lmrms_pos_err_m": "lmrms", "final_pos_err_m": "final"}
for _q, _t in (("lastlm", "last-landmark error"), ("lmrms", "landmark-phase RMS error"), ("final", "touchdown error")):
    quantity(f"err_diff_{_q}_m", "m", "mean", _t)
    quantity(f"err_mean_{_q}_m", "m", "mean", f"mean {_t}")
quantity("same_pick_pct", "%", "none", "same landmark")
quantity("converge_time_diff_s", "s", "mean", "time to converge")
quantity("yaw_sigma3_ratio", "", "none", "yaw 3-sigma end over start")
quantity("envelope_ratio_vel", "", "none", "velocity 3-sigma ratio")
quantity("envelope_ratio_att", "", "none", "attitude 3-sigma ratio")
quantity("reduction_pct", "%", "mean", "planning-time reduction")
quantity("median_time_us", "us", "mean", "median planning call")
quantity("per_eval_us", "us", "none", "cost of one metric evaluation")
quantity("shared_us", "us", "none", "per-call time shared by every method")
quantity("evals_per_call", "", "none", "metric evaluations per call")
quantity("shared_us_at_published", "us", "none", "shared per-call time at which the published reduction holds")
quantity("calls_multi_minimum", "calls", "none", "planning calls with more than one local minimum")
quantity("max_minima_per_call", "", "none", "most local minima in one call")

#: the paths of the planner (B-summary eval_path) and the other one
OTHER_PATH = {"compiled": "paper", "paper": "compiled"}
#: the planning-time comparisons of B-summary ``planning_time_vs_depth`` -> the baseline they time
VS_LABELS = {"svd_closed_form": "svd", "svd_lapack": "svd_lapack", "svd_paper": "svd_paper", "gdop": "gdop",
             "cond": "cond"}


def roles(plan: Plan) -> dict[str, str]:
    """Method -> role for paper B, from the plan's ``variants`` blocks (as_written, compared,
    controls); timing's ``compiled`` names the method of the compiled path, ``depth``."""
    out: dict[str, str] = {}
    for cid, c in plan.claims.items():
        if c.get("paper") != "B":
            continue
        v = c.get("variants") or {}
        for m in v.get("compared") or []:
            out.setdefault(m, "compared")
        for m in v.get("controls") or []:
            out.setdefault(m, "control")
    out["depth"] = "as_written"
    for m in ("svd", "gdop", "cond", "svd_lapack", "svd_paper"):
        out.setdefault(m, "compared")
    return out


def _f(x: Any) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return NAN
    return v


class _Rows:
    def __init__(self, sample: str, source: str, role_of: Mapping[str, str]):
        self.sample, self.source, self.role_of = sample, source, role_of
        self.rows: dict[tuple, EvidenceRow] = {}

    def role(self, m: str) -> str:
        return self.role_of.get(m, "beyond")

    def add(self, scope, method, versus, q, est, *, lo=NAN, hi=NAN, level=NAN, n=0, se=NAN, unit=None,
            where="", setting="", sample=None, role=None):
        from opnav.report.evidence import QUANTITIES

        est = _f(est)
        s = sample or self.sample
        key = (s, scope, method, versus, q, setting)
        if key in self.rows:      # the first section that holds a pair wins (the equivalence section)
            return
        self.rows[key] = EvidenceRow(
            claim_id="", sample=s, scope=scope, method=method, versus=versus, role=role or self.role(method),
            quantity=q, estimate=est, lo=_f(lo), hi=_f(hi), level=_f(level), n=int(n or 0),
            unit=QUANTITIES[q].unit if unit is None else unit, source=f"{self.source}#{where}" if where else self.source,
            se=_f(se), setting=setting)


def _equivalence(r: _Rows, scope: str, sec: EquivalenceSection, where: str, errors: Mapping[str, Mapping[str, Stat]],
                 n_runs: int):
    ref = sec.reference
    alpha = num(sec.alpha)
    level = 1.0 - 2.0 * alpha if math.isfinite(alpha) else NAN
    for key, q in ERR_KEYS.items():
        mm = sec.metrics.get(key)
        for m, v in (mm.means if mm else {}).items():
            st = errors.get(m, {}).get(key)
            sd = (num(st.sigma3) if st else NAN) / 3.0
            r.add(scope, m, "", f"err_mean_{q}_m", v, n=n_runs, se=sd / math.sqrt(n_runs) if n_runs else NAN,
                  where=f"{where}.metrics.{key}.means.{m}")
    for m, res in sec.methods.items():
        for key, q in ERR_KEYS.items():
            t = res.tests.get(key)
            if t is None:
                continue
            n = int(t.n or n_runs or 0)
            se = t.se
            if not math.isfinite(se):
                se = se_from_interval(t.lo, t.hi, n, level)
            r.add(scope, m, ref, f"err_diff_{q}_m", t.mean, lo=t.lo, hi=t.hi, level=level, n=n,
                  se=se, where=f"{where}.methods.{m}.{key}")
        if res.same_pick_pct is not None:
            r.add(scope, m, ref, "same_pick_pct", res.same_pick_pct, n=n_runs, where=f"{where}.methods.{m}.same_pick_pct")


def _converges(r: _Rows, scope: str, s: ScenarioSummary, ref: str):
    sections = []
    for thr, per in s.converges_faster_by_threshold.items():
        sections.append((per, f"converges_faster_by_threshold.{thr}"))
    sections.append((s.converges_faster, "converges_faster"))
    for per, where in sections:
        for m, cf in per.items():
            thr = cf.threshold_m
            level = cf.level
            if not math.isfinite(level):
                alpha = s.equivalence.alpha if s.equivalence is not None else None
                level = 1.0 - (0.05 if alpha is None else alpha)
            n = int(cf.n_runs)
            se = cf.se_s
            if not math.isfinite(se):
                se = se_from_interval(cf.lo_s, cf.hi_s, n, level)
            r.add(scope, m, cf.versus or ref, "converge_time_diff_s", cf.mean_s, lo=cf.lo_s,
                  hi=cf.hi_s, level=level, n=n, se=se, setting=f"threshold_m={thr:g}", where=f"{where}.{m}")


_YAW = re.compile(r"\(([\w-]+)\): ([\d.]+) deg at start, ([\d.]+) deg at touchdown")


def _yaw(r: _Rows, scope: str, s: ScenarioSummary, first: str):
    y = s.yaw_sigma3
    n = s.n_runs
    if y:
        start, end, m = y.start, y.end, y.method or first
        where = "yaw_sigma3_deg"
    else:   # a summary before yaw_sigma3_deg: the numbers of its yaw_reason sentence
        mt = _YAW.search(str(s.yaw_reason or ""))
        if not mt:
            return
        start, end, m, where = float(mt.group(2)), float(mt.group(3)), mt.group(1), "yaw_reason"
    if start > 0:
        ratio = end / start
        r.add(scope, m, "", "yaw_sigma3_ratio", ratio, n=n, se=ratio * math.sqrt(1.0 / max(n - 1, 1)), where=where)


def _envelopes(r: _Rows, scope: str, s: ScenarioSummary, n_runs: int):
    env: dict[str, dict[str, tuple[float, str]]] = {}
    for m, e in s.errors.items():
        for key, q in (("rms_vel_err_mps", "vel"), ("rms_att_err_deg", "att")):
            if key in e and e[key].sigma3 is not None:
                env.setdefault(m, {})[q] = (num(e[key].sigma3), f"errors.{m}.{key}.3sigma")
    for m, row in s.methods.items():   # B-T3's rows, by column
        for key, q in (("rms_vel_err_mps_3sigma", "vel"), ("rms_att_err_deg_3sigma", "att")):
            if row.get(key) is not None:
                env.setdefault(m, {}).setdefault(q, (num(row[key]), f"methods.{m}.{key}"))
    for m, a in env.items():
        for b, bb in env.items():
            if m == b:
                continue
            for q in ("vel", "att"):
                if q in a and q in bb and bb[q][0] > 0 and math.isfinite(a[q][0]):
                    ratio = a[q][0] / bb[q][0]
                    # two sample sd's (independent-sample approximation; the paired runs make it conservative)
                    se = ratio * math.sqrt(1.0 / max(n_runs - 1, 1))
                    r.add(scope, m, b, f"envelope_ratio_{q}", ratio, n=n_runs, se=se, where=f"{a[q][1]} / {bb[q][1]}")


def _stats(vals: list[float]) -> tuple[float, float, int]:
    v = [x for x in vals if math.isfinite(x)]
    k = len(v)
    if k == 0:
        return NAN, NAN, 0
    m = sum(v) / k
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (k - 1)) if k > 1 else NAN
    return m, sd, k


def _planning_time(r: _Rows, scope: str, pt: PlanningTime, replay_prefix: str, between: str):
    """The timing issue's planning_time block: per replay, between replays, decomposition, curve."""
    reps = pt.replays
    meds: dict[str, dict[int, float]] = {}
    for k, rep in enumerate(reps):
        for m, us in rep.median_us.items():
            meds.setdefault(m, {})[k] = num(us)
            r.add(scope, m, "", "median_time_us", us, n=rep.n_calls,
                  sample=f"{replay_prefix}{k + 1}", where=f"planning_time.replays.{k}.median_us.{m}")
    for m, st in pt.median_us.items():
        mean, sd, kk = _stats(list(st.per_replay))
        sdb = sd if st.sd_between is None else st.sd_between
        r.add(scope, m, "", "median_time_us", mean if st.mean is None else st.mean, lo=st.lo, hi=st.hi,
              level=st.level, n=kk, se=sdb / math.sqrt(kk) if kk else NAN,
              sample=between, where=f"planning_time.median_us.{m}")
    declared = set()
    for key, st in pt.reduction_pct.items():
        a, _, b = key.partition("_vs_")
        if st.interval == "bootstrap" or st.path:
            # timed once (beside other jobs): one replay's reading with its bootstrap interval over
            # the calls, never a spread between replays
            vs = b
            x = (st.per_replay or (st.mean,))[0]
            r.add(scope, a, vs, "reduction_pct", x, lo=st.lo, hi=st.hi, level=st.level,
                  n=st.n_calls, sample=f"{replay_prefix}1",
                  se=se_from_interval(st.lo, st.hi, st.n_calls, st.level),
                  where=f"planning_time.reduction_pct.{key}")
            declared.add((a, vs))
            continue
        declared.add((a, b))
        pr = list(st.per_replay)
        for k, x in enumerate(pr):
            n = reps[k].n_calls if k < len(reps) else 0
            r.add(scope, a, b, "reduction_pct", x, n=n, sample=f"{replay_prefix}{k + 1}",
                  where=f"planning_time.reduction_pct.{key}.per_replay.{k}")
        mean, sd, kk = _stats(pr)
        sdb = sd if st.sd_between is None else st.sd_between
        r.add(scope, a, b, "reduction_pct", mean if st.mean is None else st.mean, lo=st.lo, hi=st.hi,
              level=st.level, n=kk, se=sdb / math.sqrt(kk) if kk else NAN, sample=between,
              where=f"planning_time.reduction_pct.{key}")
    # every other pair from the replays' medians (the same replays, so the same spread rule)
    for a, ma in meds.items():
        for b, mb in meds.items():
            if a == b or (a, b) in declared:
                continue
            pr = [100.0 * (1.0 - ma[k] / mb[k]) for k in ma if k in mb and mb[k] > 0]
            for k, x in enumerate(pr):
                r.add(scope, a, b, "reduction_pct", x, sample=f"{replay_prefix}{k + 1}",
                      where=f"planning_time.replays.{k}.median_us ({a} against {b})")
            mean, sd, kk = _stats(pr)
            if kk:
                r.add(scope, a, b, "reduction_pct", mean, n=kk, se=sd / math.sqrt(kk) if kk > 1 else NAN,
                      sample=between, where=f"planning_time.replays.*.median_us ({a} against {b})")
    for m, d in pt.decomposition.items():
        for q in ("per_eval_us", "shared_us", "evals_per_call"):
            v = getattr(d, q)
            if v is not None:
                r.add(scope, m, "", q, v, n=len(reps), sample=between, where=f"planning_time.decomposition.{m}.{q}")
    curve = pt.overhead_curve
    ca, cb = curve.a, curve.b
    for x, y in zip(curve.shared_us, curve.reduction_pct):
        r.add(scope, ca, cb, "reduction_pct", y, sample=between, setting=f"shared_us={x:.4g}",
              where="planning_time.overhead_curve")
    if pt.shared_us_at_published is not None:
        r.add(scope, ca, cb, "shared_us_at_published", pt.shared_us_at_published, sample=between,
              where="planning_time.shared_us_at_published")


def _old_timing(r: _Rows, scope: str, s: ScenarioSummary, replay: str):
    """A summary before the planning_time block: one replay (its bootstrap is not a spread
    between replays, so these rows sit in a replay sample, never between_replays)."""
    for label, v in s.planning_time_vs_depth.items():
        b = VS_LABELS.get(label, label)
        r.add(scope, "depth", b, "reduction_pct", v.depth_reduction_pct, lo=v.lo, hi=v.hi, level=0.95,
              sample=replay, where=f"planning_time_vs_depth.{label}")
    for m, row in s.methods.items():   # B-T3's rows, by column
        n = int(row.get("timed_calls") or 0)
        us = row.get("median_plan_cpu_us", row.get("median_plan_time_us"))
        r.add(scope, m, "", "median_time_us", us, n=n, sample=replay, where=f"methods.{m}.median_plan_cpu_us")
        for b in s.methods:
            if b == m:
                continue
            red = row.get(f"cpu_time_reduction_vs_{b}_pct", row.get(f"time_reduction_vs_{b}_pct"))
            r.add(scope, m, b, "reduction_pct", red, n=n, sample=replay, where=f"methods.{m}.cpu_time_reduction_vs_{b}_pct")
        alt = OTHER_PATH.get(s.eval_path, "")
        if alt and row.get("time_reduction_vs_svd_alt_pct") is not None:
            r.add(scope, m, "svd", "reduction_pct", row["time_reduction_vs_svd_alt_pct"], se=row.get(
                "time_reduction_vs_svd_alt_pct_std"), n=int(row.get("timed_calls_alt") or 0), sample=replay,
                setting=f"path={alt}", where=f"methods.{m}.time_reduction_vs_svd_alt_pct")


def _optima(r: _Rows, scope: str, o: OptimaCount):
    r.add(scope, o.method, "", "calls_multi_minimum", o.calls_multi_minimum, n=o.n_calls,
          where="calls_multi_minimum")
    if o.max_minima_per_call is not None:
        r.add(scope, o.method, "", "max_minima_per_call", o.max_minima_per_call, n=o.n_calls,
              where="max_minima_per_call")


def evidence_rows(summary: Mapping[str, Any] | BSummary, sample: str, source: str, plan: Plan,
                  optima: Mapping[str, Mapping[str, Any]] | None = None) -> list[EvidenceRow]:
    """Every evidence row of one sample's B-summary.json (``sample``: main | replication;
    ``source``: its path, for the ``source`` column; ``optima``: scenario -> the B-C8 count of
    :func:`opnav.landing.optima.count_summary`, where it was run). The document is read through
    its typed form (``opnav.landing.bsummary.BSummary``). No verdict logic."""
    if isinstance(summary, BSummary):
        b = summary
    elif isinstance(summary, Mapping):
        b = BSummary.from_json(summary)
    else:
        raise TypeError(f"landing_claims.evidence_rows: summary must be the B-summary dict, got {type(summary).__name__}")
    counts = {n: OptimaCount.from_json(o) for n, o in (optima or {}).items()}
    r = _Rows(sample, source, roles(plan))
    rep_prefix = "replay" if sample == "main" else "replay_rep"
    between = "between_replays" if sample == "main" else sample
    for name in b.headline_first:
        s = b.scenarios[name]
        n_runs = s.n_runs
        eq = s.equivalence
        if eq is not None:
            _equivalence(r, name, eq, "equivalence", s.errors, n_runs)
        for base, sec in s.equivalence_vs_baselines.items():
            _equivalence(r, name, sec, f"equivalence_vs_baselines.{base}", s.errors, n_runs)
        _converges(r, name, s, (eq.reference if eq is not None else None) or "svd")
        methods = list(s.methods)
        _yaw(r, name, s, methods[0] if methods else "depth")
        _envelopes(r, name, s, n_runs)
        if s.planning_time is not None:
            _planning_time(r, name, s.planning_time, rep_prefix, between)
        else:
            _old_timing(r, name, s, f"{rep_prefix}1")
        if name in counts:
            _optima(r, name, counts[name])
        elif s.optima is not None:
            _optima(r, name, s.optima)
    return list(r.rows.values())


def published_rows(pub: Mapping[str, Any], source: str = "published.yaml") -> list[EvidenceRow]:
    """Paper B's published values the claims quote (role published)."""
    return [EvidenceRow(claim_id="", sample="main", scope="", method="", versus="", role="published",
                        quantity="reduction_pct", estimate=float(pub["depth_time_reduction_vs_svd_pct"]), unit="%",
                        source=f"{source}#paper_b.depth_time_reduction_vs_svd_pct")]


# ------------------------------------------------------------ derived inputs
def terminal_accel_to_match(landing_cfg: Mapping[str, Any], tilt_deg: float, azimuth_deg: float) -> list[float]:
    """The terminal horizontal acceleration (m/s^2) under which our guidance starts with the
    published thrust tilt and azimuth (least squares over ``landing.terminal_accel_mps2``)."""
    from scipy.optimize import least_squares

    from opnav.landing.scenario import thrust_tilt_azimuth_deg
    from opnav.landing.setup import Setup

    setup = Setup.from_config(landing_cfg)

    def resid(a):
        t, z = thrust_tilt_azimuth_deg(setup.replace(terminal_accel_mps2=(float(a[0]), float(a[1]))))
        return [t - tilt_deg, (z - azimuth_deg + 180.0) % 360.0 - 180.0]

    a0 = setup.terminal_accel_mps2 or [0.0, 0.0]
    sol = least_squares(resid, x0=[float(a0[0]), float(a0[1])], xtol=1e-12, ftol=1e-12)
    return [float(sol.x[0]), float(sol.x[1])]


def input_rows(summary: Mapping[str, Any] | BSummary, pub: Mapping[str, Any], plan: Plan,
               landing_cfg: Mapping[str, Any] | None = None) -> list[dict]:
    """Paper B's derived inputs (inputs.csv): Table 1's initial pitch and yaw, how we derive
    them and what would match the published values (``summary``: B-summary.json, read through
    its typed form)."""
    b = summary if isinstance(summary, BSummary) else BSummary.from_json(summary)
    if b.initial_tilt_deg is None or math.isnan(b.initial_tilt_deg):
        return []
    att = pub["table1_initial_state"]["att_deg"]
    tilt_pub, az_pub = -float(att[1]), -float(att[0])
    tilt, az = float(b.initial_tilt_deg), float(b.initial_azimuth_deg)
    ins = plan.raw.get("inputs", {})
    match = ""
    if landing_cfg is not None:
        a = terminal_accel_to_match(landing_cfg, tilt_pub, az_pub)
        t2, z2 = _tilt_az({**landing_cfg, "terminal_accel_mps2": a})
        match = (f"terminal horizontal acceleration ({a[0]:.3g}, {a[1]:.3g}) m/s^2 gives tilt {t2:.2f} deg, "
                 f"azimuth {z2:.2f} deg")
    return [
        {"input": "B Table 1 initial pitch (thrust tilt)", "ours": f"{fmt_(tilt)} deg",
         "published": f"{att[1]:g} deg (tilt {tilt_pub:g} deg)",
         "how_derived": ins.get("initial_pitch", {}).get("how_derived", ""),
         "what_would_match": match},
        {"input": "B Table 1 initial yaw (thrust azimuth)", "ours": f"{fmt_(az)} deg",
         "published": f"{att[0]:g} deg (azimuth {az_pub:g} deg)",
         "how_derived": ins.get("initial_yaw", {}).get("how_derived", ""),
         "what_would_match": match},
    ]


def _tilt_az(cfg):
    from opnav.landing.scenario import thrust_tilt_azimuth_deg
    from opnav.landing.setup import Setup

    return thrust_tilt_azimuth_deg(Setup.from_config(cfg))


def fmt_(x: float) -> str:
    from opnav.report.scorer import fmt

    return fmt(x)


#: the claims the abstract quotes with their cause
HEADLINE_IDS = ("B-C1", "B-C4")
