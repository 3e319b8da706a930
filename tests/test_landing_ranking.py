"""B-X1 ranking / paired statistics (paper B, beyond). The B-X2 ablations are parameter
studies now: tests/test_studies.py."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from opnav.landing.ranking import (bootstrap_mean_interval, competition_rank, headline,
                                   paired_difference, paired_t_interval, ranking_table)


# ------------------------------------------------------------ paired statistics

def test_paired_t_known_answer():
    # d = 1..5: mean 3, s = sqrt(2.5), se = sqrt(0.5), t_{0.975, 4} = 2.776445
    m, lo, hi, p = paired_t_interval([1, 2, 3, 4, 5])
    half = 2.7764451051977987 * math.sqrt(0.5)
    assert m == 3.0
    assert lo == pytest.approx(3 - half, rel=1e-12)
    assert hi == pytest.approx(3 + half, rel=1e-12)
    # t = 3 / sqrt(0.5) = 4.2426 with 4 dof: two-sided p = 0.01324
    assert p == pytest.approx(0.013236, abs=2e-6)


def test_paired_t_matches_scipy_ttest_rel():
    rng = np.random.default_rng(1)
    a = rng.normal(10, 2, 40)
    b = a + rng.normal(0.3, 0.5, 40)
    m, lo, hi, p = paired_t_interval(a - b, 0.9)
    ref = stats.ttest_rel(a, b)
    ci = ref.confidence_interval(0.9)
    assert (lo, hi) == pytest.approx((ci.low, ci.high), rel=1e-10)
    assert p == pytest.approx(ref.pvalue, rel=1e-10)


@settings(max_examples=300, deadline=None)
@given(n=st.integers(2, 2_000_000), level=st.floats(1e-6, 1 - 1e-6),
       d=st.floats(-1e6, 1e6, allow_subnormal=False), s=st.floats(1e-9, 1e6))
def test_paired_t_is_scipy_stats_t_bit_for_bit(n, level, d, s):
    # paired_t_interval calls scipy.special (stdtrit, stdtr) rather than importing
    # scipy.stats (0.4 CPU-s a job); its quantile and p-value are scipy.stats.t's bits
    from opnav.landing import ranking

    q_ref = float(stats.t.ppf(0.5 + level / 2.0, n - 1))
    p_ref = float(2.0 * stats.t.sf(abs(d) / s, n - 1))
    assert float(ranking.special.stdtrit(n - 1, 0.5 + level / 2.0)) == q_ref or math.isnan(q_ref)
    assert float(2.0 * ranking.special.stdtr(n - 1, -(abs(d) / s))) == p_ref


@settings(max_examples=100, deadline=None)
@given(x=st.lists(st.floats(-1e3, 1e3, allow_subnormal=False), min_size=2, max_size=50),
       level=st.floats(0.5, 0.999))
def test_paired_t_interval_uses_scipy_stats_bits(x, level):
    m, lo, hi, p = paired_t_interval(x, level)
    d = np.asarray(x, float)
    sd = float(d.std(ddof=1))
    if sd == 0.0:
        return
    se = sd / math.sqrt(d.size)
    q = float(stats.t.ppf(0.5 + level / 2.0, d.size - 1))
    assert (lo, hi) == (m - q * se, m + q * se)
    assert p == float(2.0 * stats.t.sf(abs(m) / se, d.size - 1))


def test_paired_t_degenerate_and_errors():
    assert paired_t_interval([2.0, 2.0, 2.0]) == (2.0, 2.0, 2.0, 0.0)
    assert paired_t_interval([0.0, 0.0]) == (0.0, 0.0, 0.0, 1.0)
    m, lo, hi, p = paired_t_interval([1.5])
    assert m == 1.5 and math.isnan(lo) and math.isnan(hi)
    with pytest.raises(ValueError):
        paired_t_interval([])
    with pytest.raises(ValueError):
        paired_t_interval([1.0, np.nan])
    with pytest.raises(ValueError, match="same runs"):
        paired_difference([1, 2, 3], [1, 2])


def test_pairing_removes_shared_run_spread():
    """Large run-to-run spread shared by both methods: the paired interval is
    narrow and excludes 0, the unpaired (Welch) one does not."""
    rng = np.random.default_rng(3)
    base = rng.lognormal(5, 1, 60)            # run difficulty, common to both
    a = base + 2.0 + rng.normal(0, 0.5, 60)
    b = base + rng.normal(0, 0.5, 60)
    d = paired_difference(a, b, n_boot=500)
    assert 0 < d.t_lo < 2.0 < d.t_hi < 2.6
    assert d.boot_lo > 0
    welch = stats.ttest_ind(a, b, equal_var=False)
    assert welch.pvalue > 0.05 and d.p < 1e-10
    assert d.a_lower_pct < 5.0 and d.equal_pct == 0.0


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=3, max_size=40),
       st.floats(-50, 50, allow_nan=False))
def test_bootstrap_interval_shift_equivariant(d, c):
    d = np.asarray(d)
    lo, hi = bootstrap_mean_interval(d, 200, seed=5)
    lo2, hi2 = bootstrap_mean_interval(d + c, 200, seed=5)
    assert lo <= hi
    assert d.min() - 1e-9 <= lo and hi <= d.max() + 1e-9
    assert lo2 == pytest.approx(lo + c, abs=1e-6) and hi2 == pytest.approx(hi + c, abs=1e-6)


# --------------------------------------------------------------------- ranking

def test_competition_rank_ties():
    assert list(competition_rank([3.0, 1.0, 2.0, 2.0])) == [4, 1, 2, 2]
    assert list(competition_rank([5.0, 5.0, 5.0])) == [1, 1, 1]
    assert list(competition_rank([2.0, np.nan, 1.0, np.nan])) == [2, 3, 1, 3]
    # within the relative tolerance: a tie; outside: not
    assert list(competition_rank([1.0, 1.0 + 1e-12, 2.0], rtol=1e-9)) == [1, 1, 3]
    assert list(competition_rank([1.0, 1.0 + 1e-12, 2.0])) == [1, 2, 3]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(0, 5), min_size=1, max_size=12))
def test_competition_rank_property(v):
    r = competition_rank(v)
    v = np.asarray(v)
    for i in range(len(v)):
        assert r[i] == 1 + np.sum(v < v[i])       # standard competition ranking


def _fake_mc(rms_scale, runs, plan_us, seed):
    """A gathered Monte-Carlo dict with position errors scaled per run."""
    rng = np.random.default_rng(seed)
    n, k = len(runs), 5
    err = np.ones((n, k, 3)) * np.asarray(rms_scale, float)[:, None, None]
    z = np.zeros((n, k, 3))
    plan_run = np.repeat(runs, 3)
    return {"run_index": np.asarray(runs), "t": np.arange(k, dtype=float), "err_r": err, "err_v": z,
            "err_th_deg": z, "err_rpy_deg": z, "nees_r": np.ones((n, k)), "nees_v": np.ones((n, k)),
            "n_landmarks": np.full(n, 4), "plan_ns": np.full(3 * n, plan_us * 1e3),
            "plan_cpu_ns": (plan_us * 1e3 * (1 + 0.01 * rng.random(3 * n))).astype(np.int64),
            "plan_evals": np.full(3 * n, 10), "plan_run": plan_run,
            "plan_t": np.tile([1.0, 2.0, 3.0], n), "plan_index": np.tile([1, 2, 3], n)}


def _records(data):
    """The fake Monte Carlos as records (their hand-made planning times left out: ``_timing``)."""
    import dataclasses

    from opnav.landing.records import MonteCarlo

    names = {f.name for f in dataclasses.fields(MonteCarlo)}
    return {m: MonteCarlo(**{k: v for k, v in d.items() if k in names}) for m, d in data.items()}


def worded(h):
    """The headline as B-X1-summary.json holds it (its fields and its words)."""
    from opnav.core.tables import json_ready
    from opnav.report.landing.ranking_text import worded_headline

    return json_ready(worded_headline(h))


def _timing(data):
    """The replay result of the fake Monte Carlos' planning times (same calls)."""
    from opnav.landing.timing import from_times

    first = next(iter(data.values()))
    return from_times({m: d["plan_ns"] for m, d in data.items()},
                      {m: d["plan_cpu_ns"] for m, d in data.items()}, first["plan_run"])


def test_ranking_table_ties_and_paired_difference():
    runs = np.arange(6)
    base = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    data = {"depth": _fake_mc(base, runs, 100.0, 0),
            "svd": _fake_mc(base + 1.0, runs, 800.0, 1),
            "gdop": _fake_mc(base + 1.0, runs, 900.0, 2),     # same errors as svd: a tie
            "random": _fake_mc(base * 0.5, runs, 50.0, 3)}
    data["svd"]["plan_beta"] = np.tile([0.01, -0.03, np.nan], 6)   # optimum's angle to the velocity, rad
    df = ranking_table(_records(data), _timing(data), "depth", n_boot=100)
    t = df.set_index("method")
    # median |beta| over the calls with an optimum (mutation tried: no abs fails); none recorded: NaN
    assert t.loc["svd", "median_abs_beta_deg"] == pytest.approx(math.degrees(0.02))
    assert math.isnan(t.loc["depth", "median_abs_beta_deg"])
    assert t.loc["random", "rank_accuracy"] == 1
    assert t.loc["depth", "rank_accuracy"] == 2
    assert t.loc["svd", "rank_accuracy"] == t.loc["gdop", "rank_accuracy"] == 3
    assert list(t["rank_time"].loc[["random", "depth", "svd", "gdop"]]) == [1, 2, 3, 4]
    # error norm = sqrt(3) * scale: svd - depth = sqrt(3) exactly in every run
    assert t.loc["svd", "d_rms_pos_vs_ref_mean"] == pytest.approx(math.sqrt(3))
    assert t.loc["svd", "d_rms_pos_vs_ref_t_lo"] == pytest.approx(math.sqrt(3))
    assert t.loc["svd", "vs_ref"] == "worse" and t.loc["random", "vs_ref"] == "better"
    assert t.loc["svd", "ref_better_pct"] == 100.0
    assert t.loc["depth", "d_rms_pos_vs_ref_mean"] == 0.0 and t.loc["depth", "vs_ref"] == "reference"
    assert t.loc["svd", "same_pick_as_ref_pct"] == 100.0
    h = worded(headline(df, "depth"))
    assert h["best_accuracy_method"] == "random" and h["fastest_method"] == "random"
    assert h["reference_rank_accuracy"] == 2
    assert set(h["reference_more_accurate_than"]) == {"svd", "gdop"}
    assert h["reference_faster_than"] == ["svd", "gdop"] or set(h["reference_faster_than"]) == {"svd", "gdop"}


def test_ranking_refuses_unpaired_runs():
    a = _fake_mc(np.ones(3), np.arange(3), 1.0, 0)
    b = _fake_mc(np.ones(3), np.arange(1, 4), 1.0, 0)
    with pytest.raises(ValueError, match="not paired"):
        ranking_table(_records({"depth": a, "svd": b}), _timing({"depth": a, "svd": a}))
    with pytest.raises(ValueError, match="reference"):
        ranking_table(_records({"svd": a}), _timing({"svd": a}), reference="depth")


def test_headline_feeds_manuscript_macros():
    """B-X1-summary.json flattens into distinct LaTeX macros (no collisions)."""
    import json

    from opnav.report.manuscript import macros_from_summary

    runs = np.arange(5)
    data = {"depth": _fake_mc(np.arange(1.0, 6.0), runs, 100.0, 0),
            "svd": _fake_mc(np.arange(1.0, 6.0) * (1 + 1e-5), runs, 800.0, 1),
            "logdet": _fake_mc(np.arange(2.0, 7.0), runs, 900.0, 2)}
    data["depth"]["plan_beta"] = np.full(15, math.radians(60.0))
    data["logdet"]["plan_beta"] = np.full(15, -math.radians(2.5))
    df = ranking_table(_records(data), _timing(data), "depth", n_boot=50, rtol=1e-3)
    t = df.set_index("method")
    assert t.loc["svd", "rank_accuracy"] == t.loc["depth", "rank_accuracy"] == 1   # within 0.1 %
    h = json.loads(json.dumps(worded(headline(df, "depth"))))
    macros = macros_from_summary(h, "BXone")
    assert macros and all(k.isalpha() for k in macros)
    # svd is 1e-5 worse in EVERY run: a shared rank (tolerance) but a significant paired difference
    assert h["reference_more_accurate_than_text"] == "svd, logdet"
    assert h["reference_less_accurate_than_text"] == "none"
    # methods with a recorded optimum, in accuracy order (svd has none: left out)
    assert h["median_abs_beta_text"] == "depth 60 deg, logdet 2.5 deg"


def test_tied_order_is_by_method_name_not_timing():
    """B-X1 rebuilt with the same errors but other timings (as every rebuild has):
    the same table order and headline orders, ties listed by method name."""
    runs = np.arange(6)
    base = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])

    def build(times):
        data = {m: _fake_mc(base + (0.0 if m in ("depth", "svd", "cond") else 1.0), runs, times[m], i)
                for i, m in enumerate(["svd", "depth", "mineig", "cond", "gdop"])}
        df = ranking_table(_records(data), _timing(data), "depth", n_boot=20, rtol=1e-3)
        return df, worded(headline(df, "depth"))

    df1, h1 = build({"svd": 900.0, "depth": 100.0, "mineig": 50.0, "cond": 400.0, "gdop": 60.0})
    df2, h2 = build({"svd": 10.0, "depth": 700.0, "mineig": 800.0, "cond": 5.0, "gdop": 900.0})
    assert list(df1["method"]) == list(df2["method"]) == ["cond", "depth", "svd", "gdop", "mineig"]
    assert h1["ranking_by_accuracy"] == h2["ranking_by_accuracy"] == list(df1["method"])
    # a three-way tie is reported as a tie, never as the alphabetically first name
    assert h1["best_accuracy_method"] == h2["best_accuracy_method"] == "cond = depth = svd"
    assert h1["best_accuracy_methods"] == ["cond", "depth", "svd"] and h1["best_accuracy_tie"]
    assert h1["reference_more_accurate_than_text"] == h2["reference_more_accurate_than_text"] == "gdop, mineig"


def _calls_data(runs, times, idx, beta, err):
    """A hand-made gathered result: planning calls and per-run error tracks."""
    n = len(err)
    e = np.zeros((n, 3, 3))
    e[:, :, 0] = np.asarray(err, float)[:, None]
    return {"run_index": np.arange(n), "plan_run": np.asarray(runs), "plan_t": np.asarray(times, float),
            "plan_index": np.asarray(idx), "plan_beta": np.asarray(beta, float),
            "err_r": e, "err_v": e, "err_th_deg": e, "nees_r": np.ones((n, 3)), "nees_v": np.ones((n, 3)),
            "n_landmarks": np.ones(n, int)}


def _calls_record(*args):
    from opnav.landing.records import MonteCarlo

    return MonteCarlo(**_calls_data(*args))


def test_pair_comparison_on_hand_made_calls():
    from opnav.landing.ranking import pair_comparison

    a = _calls_record([0, 0, 1, 1], [1, 4, 1, 4], [5, 6, 7, 8], [0.1, 0.2, 0.3, 0.4], [1.0, 2.0])
    b = _calls_record([0, 0, 1, 1], [1, 4, 1, 4], [5, 9, 7, 9], [0.1, 0.25, 0.3, 0.5], [2.0, 4.0])
    pc = pair_comparison(a, b)
    assert pc.same_pick_pct == pytest.approx(50.0)
    # |dbeta| = 0, 0.05, 0, 0.1 rad: median 0.025 rad
    assert pc.median_abs_dbeta_deg == pytest.approx(np.degrees(0.025))
    assert pc.diffs["final_pos"].m == pytest.approx(-1.5)          # (1-2 + 2-4) / 2
    assert pc.diffs["final_pos"].rel_pct == pytest.approx(-50.0)    # of b's mean 3 m
    assert pc.diffs["final_pos"].lo_m < -1.5 < pc.diffs["final_pos"].hi_m
    cols = dict(pc.columns())                                   # B-T3's pairs, by column
    assert cols["d_final_pos_m"] == pc.diffs["final_pos"].m and cols["same_pick_pct"] == pc.same_pick_pct


def test_first_runs_keeps_the_paired_runs_and_their_calls():
    """B-X1 with fewer runs for its own methods (landing.extra.n_runs): every method is cut to
    runs 0..n-1, tracks and planning calls alike; a method lacking one of them is refused."""
    from opnav.landing.montecarlo import first_runs

    a = _calls_data([0, 0, 1, 1, 2], [1, 4, 1, 4, 1], [5, 6, 7, 8, 9], [0.1, 0.2, 0.3, 0.4, 0.5],
                    [1.0, 2.0, 3.0])
    for k in ("updated", "lm_updated", "cut_alt_m", "err_rpy_deg", "sig_r", "sig_v", "sig_th_deg",
              "sig_yaw_deg", "init_error"):
        a.setdefault(k, np.zeros((3, 1)))
    from opnav.landing.records import CALL_KEYS

    for k in CALL_KEYS:
        a.setdefault(k, np.zeros(5))
    from opnav.landing.records import MonteCarlo

    a = MonteCarlo(**a)
    b = first_runs(a, 2)
    assert list(b.run_index) == [0, 1] and list(b.plan_run) == [0, 0, 1, 1]
    assert list(b.plan_index) == [5, 6, 7, 8] and b.err_r.shape[0] == 2
    with pytest.raises(ValueError, match="lacks some of runs 0..3"):
        first_runs(a, 4)
