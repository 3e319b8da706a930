"""The generic scorer (opnav.report.scorer) on hand-made evidence tables, judged by the real
analysis plan: each comparison, and each mutation a referee would try (a margin moved, the
published numbers planted in one sample, a control inside the margin, a replication whose
estimate moves, a replication that is only wider, a planning-time band built from one replay's
bootstrap). Each test says which rule it guards; the mutations were tried once on the scorer
(docstrings say what failed)."""

from __future__ import annotations

import math


from opnav.report import approach_claims  # noqa: F401  (registers paper A's quantities)
from opnav.report import landing_claims  # noqa: F401  (registers paper B's quantities)
from opnav.report import claims as C
from opnav.report import scorer as S
from opnav.report.evidence import EvidenceRow, rms_se

PLAN = C.load_plan()
CAMS = ("interior", "site-tilt")


def R(claim, quantity, est, *, sample="main", scope="interior", method="depth", versus="", role="as_written",
      lo=math.nan, hi=math.nan, level=0.9, n=300, se=math.nan, setting="", unit="m"):
    if not math.isfinite(se) and math.isfinite(lo) and math.isfinite(hi):
        from opnav.report.evidence import se_from_interval

        se = se_from_interval(lo, hi, n, level)
    return EvidenceRow(claim_id=claim, sample=sample, scope=scope, method=method, versus=versus, role=role,
                       quantity=quantity, estimate=est, lo=lo, hi=hi, level=level if math.isfinite(lo) else math.nan,
                       n=n, unit=unit, source="hand-made", se=se, setting=setting)


def pub(claim, quantity, est, scope="", unit=""):
    return EvidenceRow(claim_id=claim, sample="main", scope=scope, method="", versus="", role="published",
                       quantity=quantity, estimate=est, unit=unit, source="hand-made")


# ------------------------------------------------------------ paper B: B-C1 and B-C7, one test for every baseline
def b_c1(claim="B-C1", d=None, half=0.005, controls=None, pick=50.0, sample="main", cams=CAMS, n=300,
         means=(0.4, 2.0)):
    """Depth minus each baseline (svd, gdop, cond) of both landmark-phase errors: ``d`` maps
    (camera, baseline) -> mean difference (default 0) with a +-``half`` 90 % interval; each
    baseline's own mean errors ``means`` (m); controls -> their difference from SVD."""
    d = d or {}
    controls = {"random": 2.0, "center": 1.0, "closest": 0.8} if controls is None else controls
    rows = []
    for cam in cams:
        for b in ("svd", "gdop", "cond"):
            x = d.get((cam, b), d.get(b, 0.0))
            h = half[(cam, b)] if isinstance(half, dict) else half
            for q, mean in zip(("lastlm", "lmrms"), means):
                rows.append(R(claim, f"err_mean_{q}_m", mean, sample=sample, scope=cam, method=b, role="compared",
                              n=n, se=0.01))
                rows.append(R(claim, f"err_diff_{q}_m", x, sample=sample, scope=cam, versus=b, lo=x - h, hi=x + h, n=n))
            rows.append(R(claim, "same_pick_pct", pick if b == "svd" else 40.0, sample=sample, scope=cam, versus=b,
                          unit="%", n=n))
        for c, x in controls.items():
            for q in ("lastlm", "lmrms"):
                rows.append(R(claim, f"err_diff_{q}_m", x, sample=sample, scope=cam, method=c, versus="svd",
                              role="control", lo=x - 0.01, hi=x + 0.01, n=n))
    return rows


def test_equivalence_for_every_baseline_by_one_rule():
    """B-C1: the same equivalence test for SVD, GDOP and condition number. A GDOP interval outside
    the margin fails the claim in that camera (e19e33d judged GDOP and cond by B-T3's pairs: a
    GDOP difference only in the equivalence section went unseen)."""
    assert S.judge(PLAN, "B-C1", b_c1()).verdict == C.REPRODUCED
    j = S.judge(PLAN, "B-C1", b_c1(d={("interior", "gdop"): 0.1}))
    assert j.verdict == C.DEPENDS and "camera" in j.named
    assert "GDOP" in j.cause and "+0.1" in j.cause, "the cause quotes the GDOP interval that failed"
    assert S.judge(PLAN, "B-C1", b_c1(d={"cond": 0.1})).verdict == C.NOT_REPRODUCED


def test_the_cause_quotes_the_interval_that_failed():
    """Change which interval fails, the cause follows (e19e33d's B-C7 quoted SVD's interval,
    wholly in depth's favour, as 'not shown')."""
    a = S.judge(PLAN, "B-C1", b_c1(d={"gdop": 0.1}))
    b = S.judge(PLAN, "B-C1", b_c1(d={"cond": -0.3}))
    assert "GDOP" in a.cause and "condition number" not in a.cause
    assert "condition number" in b.cause and "-0.3" in b.cause and "GDOP" not in b.cause
    c = S.judge(PLAN, "B-C7", b_c1("B-C7", d={"svd": -0.1, "gdop": -0.1, "cond": 0.002}))
    assert c.verdict == C.NOT_REPRODUCED and "condition number" in c.cause and "SVD" not in c.cause


def test_a_moved_margin_moves_the_verdict():
    """B-C1's margin_rel from the plan: 10 % of 0.4 m is 0.04 m; an interval reaching 0.05 m fails,
    and passes once the plan's margin is 0.2 (no margin in code)."""
    rows = b_c1(d={"svd": 0.045})
    assert S.judge(PLAN, "B-C1", rows).verdict == C.NOT_REPRODUCED
    wide = PLAN.amended({"claims.B-C1.margins.margin_rel": {"value": 0.2, "reason": "test"}})
    assert S.judge(wide, "B-C1", rows).verdict == C.REPRODUCED


def test_a_control_inside_the_margin_is_a_flag_or_voids_the_test():
    """A negative control meeting the claim: with effect flag the claim holds with
    control_also_meets; with effect decide (the rule before the 2026-12-04 amendment) it is void."""
    j = S.judge(PLAN, "B-C1", b_c1(controls={"random": 2.0, "closest": 0.001}))
    assert j.verdict == C.REPRODUCED
    assert any(f[0] == "control_also_meets" and "closest" in f[1] for f in j.flags)
    assert "cannot credit" in j.cause
    old = PLAN.amended({"claims.B-C1.test.controls.effect": "decide"})
    assert S.judge(old, "B-C1", b_c1(controls={"closest": 0.001})).verdict == C.NOT_TESTED
    assert not any(f[0] == "control_also_meets" for f in S.judge(PLAN, "B-C1", b_c1()).flags)


def test_same_picks_leave_a_baseline_out_and_all_of_them_untested():
    """The same-pick guard: a baseline picking depth's landmark in >= 90 % of the calls cannot
    differ from it; it is left out (flag). B-C10 has the guard too (e19e33d had none)."""
    j = S.judge(PLAN, "B-C1", b_c1(pick=95.0, d={"svd": 0.3}))
    assert j.verdict == C.REPRODUCED and any(f[0] == "not_tested_vs" and "SVD" in f[1] for f in j.flags)
    rows = [r if r.quantity != "same_pick_pct" else R("B-C1", "same_pick_pct", 99.0, scope=r.scope, versus=r.versus,
                                                     unit="%") for r in b_c1()]
    j = S.judge(PLAN, "B-C1", rows)
    assert j.verdict == C.NOT_TESTED and "same landmark" in j.named
    env = [R("B-C10", f"envelope_ratio_{q}", 1.0, scope=cam, versus=b, unit="") for cam in CAMS
           for b in ("svd", "gdop", "cond") for q in ("vel", "att")]
    env += [R("B-C10", "same_pick_pct", 99.9, scope=cam, versus=b, unit="%") for cam in CAMS for b in ("svd", "gdop", "cond")]
    assert S.judge(PLAN, "B-C10", env).verdict == C.NOT_TESTED


# ------------------------------------------------------------ two samples
def test_a_replication_whose_estimate_moves_is_unstable():
    """Main: depth minus SVD 0.0 +-0.005 (equivalent); replication: 0.06 +-0.01, outside the
    margin and far from the main estimate (z > 5): unstable, and the cause quotes both."""
    rows = b_c1() + b_c1(sample="replication", d={"svd": 0.06}, half=0.01, n=100)
    j = S.judge(PLAN, "B-C1", rows)
    assert j.verdict == C.UNSTABLE and j.replication.verdict != C.REPRODUCED
    assert "main" in j.cause and "0.06" in j.cause


def test_a_replication_that_is_only_wider_is_underpowered_not_unstable():
    """The replication's estimate equals the main's but its interval is wider than the margin:
    the samples agree (no difference between them), so the claim is read on the pooled sample
    and flagged replication_underpowered (e19e33d read 'unstable': the B-C1 interior case).
    Mutation tried once: sample_difference mode 'verdicts' (the old rule) reads unstable."""
    main = b_c1(d={"svd": 0.02}, half=0.015)
    rep = b_c1(sample="replication", d={"svd": 0.02}, half=0.03, n=100)
    ev = C.evidence_table(PLAN, C.raw_rows(main + rep))
    j = S.judge(PLAN, "B-C1", ev)
    assert j.main.verdict == C.REPRODUCED and j.replication.verdict == C.NOT_REPRODUCED
    assert j.verdict == C.REPRODUCED, "the pooled sample decides"
    assert any(f[0] == "replication_underpowered" for f in j.flags)
    old = PLAN.amended({"sample_difference.test": "verdicts"})
    assert S.judge(old, "B-C1", ev).verdict == C.UNSTABLE


def test_a_pooled_reading_says_it_is_pooled():
    """The cause of a claim read on the pooled sample quotes the pooled interval and says so: the
    full build of d1501f2 quoted B-C7's pooled interior interval (+0.00227 m [-0.0648, +0.0693])
    beside the main sample's (-0.00167 m) with only '(interior)', two numbers for one quantity.
    Mutation tried once: the sample left out of the quote fails it."""
    main = b_c1(d={"svd": 0.02}, half=0.015)
    rep = b_c1(sample="replication", d={"svd": 0.02}, half=0.03, n=100)
    ev = C.evidence_table(PLAN, C.raw_rows(main + rep))
    j = S.judge(PLAN, "B-C1", ev)
    assert j.pooled is not None and j.verdict == j.pooled.verdict
    assert "both samples pooled" in j.cause
    assert all("pooled" not in S.quote(u.first(), PLAN) for u in j.main.units if u.first() is not None)


def _a_rows(claim="A-C1", sample="main", err=20.0, bound=20.6, roll_err=0.08, roll_bound=0.06, n=20):
    rows = []
    for m, role, e, b in (("literal", "as_written", err, bound), ("roll+growing+squarem", "faithful", roll_err, roll_bound)):
        rows.append(R(claim, "rms_err_arcsec", e, sample=sample, scope="T1-01", method=m, role=role, n=n,
                      se=rms_se(e, n), unit="arcsec"))
        rows.append(R(claim, "converged_label", 1.0, sample=sample, scope="T1-01", method=m, role=role, n=n, unit=""))
        rows.append(R(claim, "crlb_arcsec", b, sample=sample, scope="T1-01", method=m, role="bound", n=n, unit="arcsec"))
    return rows


def test_published_numbers_planted_in_one_sample_show_as_suspect():
    """The published errors (1.43, 1.21 arcsec) planted as the as-written error of the
    replication only, beside its 20.6 arcsec bound: suspect shows (verdict and a flag naming
    the sample), never hidden by 'unstable' (e19e33d kept it only in verdict_main)."""
    rows = _a_rows() + _a_rows(sample="replication", err=1.43, n=10)
    j = S.judge(PLAN, "A-C1", rows)
    assert j.verdict == C.SUSPECT and ("suspect", "replication") in j.flags
    assert S.judge(PLAN, "A-C1", _a_rows()).verdict == C.WITH_ADDITION


def test_the_bound_rule_is_the_plans():
    """A-C1: as written misses 2 arcsec, its bound (20.6) exceeds it, a faithful variant meets
    it: with addition; without the faithful variant, not reproducible (bound: information);
    A-C3 has the rule too now (the 2026-12-07 amendment), and without it reads not reproduced."""
    rows = [r for r in _a_rows() if r.method == "literal"]
    j = S.judge(PLAN, "A-C1", rows)
    assert j.verdict == C.NOT_REPRODUCIBLE and "20.6" in j.named and "20.6" in j.cause
    no_rule = PLAN.amended({"claims.A-C1.test.bound": None})
    assert S.judge(no_rule, "A-C1", rows).verdict == C.NOT_REPRODUCED


def test_a_floor_is_not_an_information_bound():
    """A-C7: the true-theta filter's floor above the limit makes the claim depend on a choice
    (flag floor_not_bound), never not reproducible; as information bound (the rule before the
    2026-12-04 amendment) it would be."""
    rows = [R("A-C7", "nav_err_after_km", 113.0, scope="T1-01", method="literal", n=20, se=1.0, unit="km"),
            R("A-C7", "converged_label", 1.0, scope="T1-01", method="literal", n=20, unit=""),
            R("A-C7", "nav_err_true_theta_km", 29.4, scope="T1-01", method="literal", role="bound", n=20, unit="km")]
    j = S.judge(PLAN, "A-C7", rows)
    assert j.verdict == C.DEPENDS and any(f[0] == "floor_not_bound" for f in j.flags) and "29.4" in j.cause
    old = PLAN.amended({"claims.A-C7.test.bound.rule": "information"})
    assert S.judge(old, "A-C7", rows).verdict == C.NOT_REPRODUCIBLE


# ------------------------------------------------------------ planning time: replays
def _timing(claim="B-C4", replays=(28.0, 29.5, 30.0), boot_sd=0.7, cams=("interior",), between=True):
    rows = []
    for cam in cams:
        for k, x in enumerate(replays):
            # one replay: its estimate with its bootstrap sd over the calls (a standard error of that replay)
            rows.append(R(claim, "reduction_pct", x, sample=f"replay{k + 1}", scope=cam, versus="svd", se=boot_sd,
                          n=1, unit="%"))
        if between:
            m = sum(replays) / len(replays)
            sd = math.sqrt(sum((x - m) ** 2 for x in replays) / (len(replays) - 1))
            rows.append(R(claim, "reduction_pct", m, sample="between_replays", scope=cam, versus="svd",
                          se=sd / math.sqrt(len(replays)), n=len(replays), unit="%"))
    return rows + [pub(claim, "reduction_pct", 29.03, unit="%")]


def test_the_timing_band_is_built_from_the_spread_between_replays():
    """B-C4: published 29.03 % +- max(10 %, 2 sd between replays). Replays 18, 24, 30 % (mean
    24 %, sd 6): the band is 29.03 +- 12 and holds 24 %. One replay's bootstrap sd (0.7) must
    never build it: with only the replays (no between-replay row) the claim is not tested
    (e19e33d judged 17.7 % against 29.03 +- max(2.9, 2 x 0.7): not reproduced, and 29.4 %
    reproduced, moving between builds). Mutation tried once: reading B-C4 on the replay sample
    (samples.main: replay1) judges 24 % against 29.03 +- 2.9 and reads not reproduced."""
    j = S.judge(PLAN, "B-C4", _timing(replays=(18.0, 24.0, 30.0)))
    assert j.verdict == C.REPRODUCED, j.cause
    only_one = S.judge(PLAN, "B-C4", _timing(replays=(24.0,), between=False))
    assert only_one.verdict == C.NOT_TESTED and "between independent replays" in only_one.named
    tight = S.judge(PLAN, "B-C4", _timing(replays=(23.9, 24.0, 24.1)))
    assert tight.verdict == C.NOT_REPRODUCED and "24" in tight.cause


def test_the_seed_guard_counts_seeds_not_replays():
    """min_full_seeds guards Monte-Carlo samples: B-C4's three replays of 200 recorded calls are
    the plan's design, not three seeds (d1501f2's full build flagged B-C4 and B-C9
    'sample_too_small: 3 seeds or runs'); a Monte-Carlo claim of 5 runs is still flagged.
    Mutation tried once: without the planning-time exemption the first assertion fails."""
    # the replication's replays of its own recorded calls: sample 'replication', n = 3 replays
    rep = [R("B-C4", "reduction_pct", 25.0, sample="replication", scope="interior", versus="svd", se=2.4, n=3,
             unit="%")]
    ev = C.evidence_table(PLAN, C.raw_rows(_timing(replays=(18.0, 24.0, 30.0)) + rep))
    row, _, _ = C.claim_row(PLAN, "B-C4", ev, replicated=True)
    assert "sample_too_small" not in (row.flags or "")
    small = b_c1(n=5)
    row, _, _ = C.claim_row(PLAN, "B-C1", C.evidence_table(PLAN, C.raw_rows(small)), replicated=False)
    assert "sample_too_small: 5 seeds or runs" in (row.flags or "")


def test_timing_depends_on_the_svd_implementation_where_another_meets_the_band():
    rows = _timing(replays=(10.0, 11.0, 12.0)) + [
        R("B-C4", "reduction_pct", 29.0, sample="between_replays", scope="interior", versus="svd_lapack", se=0.5,
          n=3, unit="%")]
    j = S.judge(PLAN, "B-C4", rows)
    assert j.verdict == C.DEPENDS and "implemented" in j.named and "LAPACK" in dict(j.flags)["holds_with"]


def test_order_needs_intervals_that_exclude_a_tie():
    """B-C9: depth < SVD < GDOP, cond, each pair ordered only when its between-replay interval
    excludes 0; a 1 % gap whose interval straddles 0 is not an order."""
    def pair(a, b, m, se):
        return R("B-C9", "reduction_pct", m, sample="between_replays", versus=b, method=a, role="as_written"
                 if a == "depth" else "compared", se=se, n=3, unit="%")
    ok = [pair("depth", "svd", 25.0, 1.0), pair("svd", "gdop", 10.0, 1.0), pair("svd", "cond", 12.0, 1.0)]
    assert S.judge(PLAN, "B-C9", ok).verdict == C.REPRODUCED
    tie = [pair("depth", "svd", 25.0, 1.0), pair("svd", "gdop", 1.5, 1.0), pair("svd", "cond", 12.0, 1.0)]
    j = S.judge(PLAN, "B-C9", tie)
    assert j.verdict == C.NOT_REPRODUCED and "GDOP" in j.cause


# ------------------------------------------------------------ the other comparisons
def test_superiority_needs_a_whole_step_and_sweeps_the_threshold():
    """B-C2: depth minus SVD first time below the plan's threshold (100 m): the interval below 0
    and at least one filter step (1 s). would_take finds the threshold where it flips."""
    def rows(x100):
        out = []
        for cam in CAMS:
            for thr, x in ((25, -3.0), (50, -2.0), (100, x100), (200, 0.5), (400, 1.0)):
                out.append(R("B-C2", "converge_time_diff_s", x, scope=cam, versus="svd", lo=x - 0.3, hi=x + 0.3,
                             setting=f"threshold_m={thr}", unit="s"))
        return out
    assert S.judge(PLAN, "B-C2", rows(-1.5)).verdict == C.REPRODUCED
    j = S.judge(PLAN, "B-C2", rows(-0.5))
    assert j.verdict == C.NOT_REPRODUCED
    wt, sweeps = S.would_take(PLAN, "B-C2", rows(-0.5), j)
    flip = sweeps[0].flip
    assert 50 <= flip <= 100 and "threshold" in wt
    assert "minimum difference of 0.5 s instead of 1" in wt, "the step at which it would count at the plan's threshold"


def test_count_and_sign():
    """B-C8: no planning call with a second local minimum (count == 0); B-C3: the yaw 3-sigma
    ratio above the plan's 0.5."""
    assert S.judge(PLAN, "B-C8", [R("B-C8", "calls_multi_minimum", 0.0, scope=c, unit="calls") for c in CAMS]
                   ).verdict == C.REPRODUCED
    j = S.judge(PLAN, "B-C8", [R("B-C8", "calls_multi_minimum", float(c == "site-tilt") * 3, scope=c, unit="calls")
                               for c in CAMS])
    assert j.verdict == C.DEPENDS and "3" in j.cause
    assert S.judge(PLAN, "B-C3", [R("B-C3", "yaw_sigma3_ratio", 1.03, scope=c, unit="") for c in CAMS]
                   ).verdict == C.REPRODUCED
    assert S.judge(PLAN, "B-C3", [R("B-C3", "yaw_sigma3_ratio", 0.2, scope=c, unit="") for c in CAMS]
                   ).verdict == C.NOT_REPRODUCED


def test_a_method_without_a_verdict_changes_nothing():
    """The registry's own method (role beyond) in the evidence: read by no verdict."""
    rows = b_c1(d={"svd": 0.1})
    extra = [R("B-C1", "err_diff_lastlm_m", 0.0, scope=c, method="mine", versus=b, role="beyond", lo=-0.001,
               hi=0.001) for c in CAMS for b in ("svd", "gdop", "cond")]
    assert S.judge(PLAN, "B-C1", rows).verdict == S.judge(PLAN, "B-C1", rows + extra).verdict == C.NOT_REPRODUCED


def test_no_evidence_is_not_tested_with_why():
    j = S.judge(PLAN, "A-C12", [])
    assert j.verdict == C.NOT_TESTED and j.named


def test_sweep_interpolates_where_the_bound_reaches_the_target():
    """A-C1's would_take: the roll rate where the bound after the published data reaches the
    plan's target, from the bound-against-rate rows (log-linear between the swept rates); the
    plan's target moved to 0.5 arcsec moves it (e19e33d kept the 2 arcsec rate)."""
    rows = [r for r in _a_rows() if r.method == "literal"]
    rows += [R("A-C1", "crlb_published_data_arcsec", b, scope="T1-01", method="roll", role="faithful",
               setting=f"roll_rate_deg_s={x:g}", unit="arcsec", n=0) for x, b in ((0.1, 5.0), (0.2, 2.5), (0.4, 1.25))]
    j = S.judge(PLAN, "A-C1", rows)
    wt, sw = S.would_take(PLAN, "A-C1", rows, j)
    assert sw and abs(sw[0].flip - 0.25) < 0.03 and "0.25" in wt
    half = PLAN.amended({"claims.A-C1.margins.target_arcsec": {"value": 1.0, "reason": "test"}})
    wt2, sw2 = S.would_take(half, "A-C1", rows, S.judge(half, "A-C1", rows))
    assert sw2[0].flip is None and "no roll rate from 0.1 to 0.4 deg/s" in wt2


def test_an_undecided_band_writes_the_ends_it_quotes():
    """A band too wide to decide (A-C11's per-case navigation error: its 2-sd spread wider than
    the plan's max_band_rel) still quotes its ends ('113 km against 6.03 to 30.8 km (T1-01)'),
    so they are derived evidence rows like a decided band's (the full build of aeaf765 quoted
    them in no row). Mutation tried once: numbers set only for decided bands fails it."""
    rows = [R("A-C11", "nav_err_after_km", 113.0, scope="T1-01", method="literal", se=2.8, n=20, unit="km"),
            pub("A-C11", "nav_err_after_km", 18.43, scope="T1-01", unit="km")]
    row, j, _ = C.claim_row(PLAN, "A-C11", C.evidence_table(PLAN, C.raw_rows(rows)), replicated=False)
    assert "too wide to decide" in (j.main.units[0].outcomes[0].why or "")
    quoted = S.numbers_in(row.ours_as_written.split("against", 1)[1].replace("T1-01", ""))
    limits = {S.fmt(d.estimate) for d in j.derived if d.quantity == "limit_nav_err_after_km"}
    assert len(quoted) == 2 and set(quoted) <= limits, (row.ours_as_written, limits)
