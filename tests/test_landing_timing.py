"""Planning time by replay (opnav.landing.timing): the replay is the descent's
call (same picks), deterministic and order independent, and the consumers
(B-T3, B-X1 ranking, B-F7) read the replayed times."""

import copy

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from opnav.core.config import load_config
from opnav.landing import records, timing, timing_summary
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import run_chunk
from opnav.report.landing import timing_text
from opnav.report.landing.summary import summary_table
from landing_helpers import scenario_setups

METHODS = ("depth", "svd", "random", "center")


@pytest.fixture(scope="module")
def recorded():
    """One run of each method in the interior scenario (quick profile)."""
    cfg = scenario_setups(load_config(overlays=["config/quick.yaml"])["landing"])["interior"]
    rec = {m: run_chunk(cfg, m, [1]) for m in METHODS}
    return build_scenario(cfg), rec


@given(st.integers(0, 2**63), st.integers(1, 50))
@settings(max_examples=25, deadline=None)
def test_rng_words_restore_the_stream(seed, n_draws):
    g = np.random.default_rng(seed)
    g.integers(7, size=n_draws % 5)          # leave it mid-stream (has_uint32 either way)
    g.random(n_draws % 3)
    w = records.rng_words(g)
    h = records.rng_from_words(w)
    np.testing.assert_array_equal(g.integers(1000, size=n_draws), h.integers(1000, size=n_draws))


@given(st.integers(0, 5000), st.integers(0, 6000))
def test_select_calls_evenly_spaced_distinct(n, m):
    idx = timing.select_calls(n, m)
    want = n if m == 0 or m >= n else m
    assert len(idx) == want and len(np.unique(idx)) == want
    assert np.all(np.diff(idx) > 0) and (want == 0 or (idx[0] == 0 and idx[-1] < n))


@pytest.mark.slow
def test_replay_reproduces_every_recorded_pick(recorded):
    """Every own call replayed (max_calls = 0): the replayed pick is the recorded one."""
    scn, rec = recorded
    tm = timing.replay(scn, {m: rec[m] for m in ("depth", "random", "center")},
                       ["depth", "random", "center"], max_calls=0)
    n = sum(len(rec[m].plan_index) for m in ("depth", "random", "center"))
    assert len(tm.source) == n and tm.checked.sum() == n
    assert tm.mismatch.tolist() == [0, 0, 0]
    assert (tm.wall_ns > 0).all() and (tm.cpu_ns >= 0).all()


@pytest.mark.slow  # ~1.3 CPU-s (issue 56: the default run <= 90 s)
def test_the_pick_check_can_fail(recorded):
    """Replaying from the wrong filter step (the wrong image) or without the
    excluded landmark changes picks: the check counts them."""
    scn, rec = recorded
    for key, bad in (("plan_step", lambda x: x + 3), ("plan_exclude", lambda x: np.full_like(x, -1))):
        d = rec["depth"].replace(**{key: bad(getattr(rec["depth"], key))})
        tm = timing.replay(scn, {"depth": d}, ["depth"], max_calls=0)
        assert tm.mismatch[0] > 0, key


@pytest.mark.slow
def test_replay_deterministic_and_order_independent(recorded):
    """Same inputs, same picks, whatever the method order or the subset; the
    methods are timed on both paths (compiled, the paper's definition) with the same picks; the rotation puts
    every variant first in turn within its path's pass."""
    scn, rec = recorded
    a = timing.replay(scn, rec, list(METHODS), max_calls=12)
    b = timing.replay(scn, rec, list(METHODS)[::-1], max_calls=12)
    full = timing.replay(scn, rec, ["svd"], max_calls=0)
    assert a.mismatch.sum() == 0 and b.mismatch.sum() == 0
    for m in METHODS:
        ja = timing_summary.variant_index(a, m, "main")
        jb = timing_summary.variant_index(b, m, "main")
        np.testing.assert_array_equal(a.pick[:, ja], b.pick[:, jb], err_msg=m)
    for m in ("depth", "svd"):     # compiled and the paper's definition pick alike here
        np.testing.assert_array_equal(a.pick[:, timing_summary.variant_index(a, m, "alt")],
                                      a.pick[:, timing_summary.variant_index(a, m, "main")])
    # the subset's calls are the full pool's calls at the selected indices
    sel = timing.select_calls(int(a.n_pool), 12)
    pool_src = np.concatenate([np.full(len(rec[m].plan_index), i) for i, m in enumerate(METHODS)])
    np.testing.assert_array_equal(a.source, pool_src[sel])
    svd_calls = a.source == list(METHODS).index("svd")
    # (the full replay's rows are every source's calls in pool order: find svd's)
    row = {(int(s), int(c)): q for q, (s, c) in enumerate(zip(full.source, full.call))}
    src_svd = list(METHODS).index("svd")
    np.testing.assert_array_equal(a.pick[svd_calls, timing_summary.variant_index(a, "svd", "main")],
                                  full.pick[[row[(src_svd, int(c))] for c in a.call[svd_calls]], 0])
    # one pass per (path, compiled or interpreted): a variant's slot is its place among
    # its own pass's variants, and each of them comes first in turn
    keys = timing.pass_keys(timing.variants(list(METHODS), scn.planner))
    assert keys == [(0, 0), (1, 1), (0, 0), (1, 1), (0, 1), (0, 1)]   # depth, svd: main + alt; pickers
    for key in set(keys):
        g = np.flatnonzero([k == key for k in keys])
        assert set(a.slot[:g.size, g[0]]) == set(range(g.size)), key


def _fake_timing(wall_us: dict, cpu_us: dict, runs):
    """A replay result with given per-call times (us) per method (main path)."""
    return timing.from_times({m: np.asarray(v) * 1e3 for m, v in wall_us.items()},
                             {m: np.asarray(v) * 1e3 for m, v in cpu_us.items()}, runs, n_evals=7)


def test_time_reduction_known_answer_and_paired_bootstrap():
    rng = np.random.default_rng(0)
    b = rng.lognormal(6.0, 0.5, 200)
    runs = np.repeat(np.arange(20), 10)
    tm = _fake_timing({"depth": b / 2, "svd": b}, {"depth": b / 2, "svd": b}, runs)
    red, sd = timing_summary.time_reduction(tm, "depth", "svd", n_boot=100)
    assert red == pytest.approx(50.0, abs=0.01)
    assert sd < 0.01          # paired: every resample halves the median exactly
    red_cpu, sd_cpu = timing_summary.time_reduction(tm, "svd", "depth", clock="cpu", n_boot=0)
    assert red_cpu == pytest.approx(-100.0, abs=0.05) and np.isnan(sd_cpu)


def test_b_t3_and_ranking_read_the_replayed_times(recorded):
    """The tables' time columns are the replay's, not the descent's clocks, and on one clock
    (thread CPU, timing_summary.CLOCK; the wall times given here differ and must not show): with
    replayed times that make svd 4x faster than depth, B-T3 reports a negative reduction and the
    ranking puts svd first in time."""
    from opnav.landing.ranking import ranking_table

    _, rec = recorded
    data = {m: copy.copy(rec[m]) for m in ("depth", "svd")}
    n = 40
    runs = np.repeat(np.arange(8), 5)
    tm = _fake_timing({"depth": np.full(n, 400.0), "svd": np.full(n, 100.0)},
                      {"depth": np.full(n, 380.0), "svd": np.full(n, 90.0)}, runs)
    t = summary_table(data, tm, published_reduction_vs_svd=29.03).set_index("method")
    assert t.loc["depth", "median_plan_time_us"] == pytest.approx(380.0)
    assert t.loc["svd", "median_plan_cpu_us"] == pytest.approx(90.0)
    assert t.loc["depth", "time_reduction_vs_svd_pct"] == pytest.approx(100 * (1 - 380 / 90))
    assert t.loc["depth", "cpu_time_reduction_vs_svd_pct"] == pytest.approx(100 * (1 - 380 / 90))
    assert t.loc["depth", "timed_calls"] == n
    r = ranking_table(data, tm, "depth", n_boot=0).set_index("method")
    assert r.loc["svd", "rank_time"] == 1 and r.loc["depth", "rank_time"] == 2
    assert r.loc["svd", "cpu_time_ratio_to_ref"] == pytest.approx(90 / 380)
    with pytest.raises(ValueError, match="did not time"):
        summary_table({**data, "center": rec["center"]}, tm)


def test_b_f7_boxes_are_the_replayed_times():
    import matplotlib

    matplotlib.use("Agg")
    from opnav.report.landing.plots import fig_planning_time

    runs = np.repeat(np.arange(4), 5)
    tm = _fake_timing({"depth": np.full(20, 123.0), "svd": np.full(20, 4567.0)},
                      {"depth": np.full(20, 120.0), "svd": np.full(20, 4000.0)}, runs)
    fig = fig_planning_time(tm, ["depth", "svd"], 29.03)
    ax = fig.axes[0]
    notes = sorted(t.get_text() for t in ax.texts)
    assert notes == ["120", "4000"]               # thread CPU, the one clock (wall: 123, 4567)
    assert "97.0 % less" in ax.get_title()        # 100 (1 - 120 / 4000)


# ----------------------------------------------------- the paper path's subset

@given(st.integers(0, 400), st.integers(0, 500), st.integers(0, 600))
def test_paper_subset_is_select_calls_over_the_replayed_calls(n_pool, m, mp):
    """The paper path's calls are ``select_calls`` over the replay positions:
    evenly spaced (gaps differ by at most one), deterministic, 0 or >= the
    replayed calls = all of them, never more than the replayed calls."""
    nc = len(timing.select_calls(n_pool, m))
    sub = timing.select_calls(nc, mp, "landing.timing.max_calls_paper")
    want = nc if mp == 0 or mp >= nc else mp
    assert len(sub) == want and np.all(np.diff(sub) > 0)
    assert want == 0 or (sub[0] == 0 and sub[-1] < nc)
    if want > 1:
        gaps = np.diff(np.append(sub, nc))
        assert gaps.max() - gaps.min() <= 1
    np.testing.assert_array_equal(sub, timing.select_calls(nc, mp))


def test_bad_max_calls_paper_names_the_key():
    from opnav.core.config import validate_config
    from opnav.core.errors import ConfigError

    with pytest.raises(ValueError, match="landing.timing.max_calls_paper must be >= 0"):
        timing.select_calls(10, -1, "landing.timing.max_calls_paper")
    cfg = load_config()
    assert cfg["landing"]["timing"]["max_calls_paper"] >= 0
    bad = copy.deepcopy(cfg)
    bad["landing"]["timing"]["max_calls_paper"] = -2
    with pytest.raises(ConfigError, match=r"^invalid config key 'landing.timing.max_calls_paper'"):
        validate_config(bad)
    bad["landing"]["timing"]["max_calls_paper"] = 2.5
    with pytest.raises(ConfigError, match="landing.timing.max_calls_paper"):
        validate_config(bad)


def test_replay_times_the_paper_path_on_its_subset_only(recorded):
    """max_calls_paper = 4 of 12 replayed calls: the compiled variants run on
    every call, the paper-path ones on the 4 evenly spaced calls only (the
    others marked -1 / pick -2, not run), each path in its own pass; the
    rotation rule puts every variant first in turn within its pass; picks equal
    the full replay's."""
    scn, rec = recorded
    a = timing.replay(scn, rec, list(METHODS), max_calls=12, max_calls_paper=4)
    full = timing.replay(scn, rec, list(METHODS), max_calls=12, max_calls_paper=0)
    sub = timing.select_calls(12, 4)
    paper = (a.variant_path == "alt") & (a.variant_eval_path == "paper")
    np.testing.assert_array_equal(paper, timing.paper_limited(timing.variants(list(METHODS), scn.planner)))
    assert paper.sum() == 2 and set(a.variant_eval_path[paper]) == {"paper"}
    tmd = a.timed
    assert tmd[:, ~paper].all()
    np.testing.assert_array_equal(np.flatnonzero(tmd[:, paper].all(axis=1)), sub)
    assert not tmd[np.setdiff1d(np.arange(12), sub)][:, paper].any()
    off = ~tmd
    assert (a.wall_ns[off] == -1).all() and (a.cpu_ns[off] == -1).all()
    assert (a.pick[off] == -2).all() and (a.slot[off] == -1).all() and (a.n_evals[off] == -1).all()
    assert (a.wall_ns[tmd] > 0).all()
    np.testing.assert_array_equal(a.pick[tmd], full.pick[tmd])
    assert full.timed.all() and a.mismatch.sum() == 0
    # passes (timing.pass_keys): compiled searches of the configured path, its
    # interpreted pickers, then the paper's definition on its subset; the t-th call
    # of a pass runs that pass's variants rotated left by t
    keys = timing.pass_keys(timing.variants(list(METHODS), scn.planner))
    for key in sorted(set(keys)):
        g = np.flatnonzero([k == key for k in keys])
        calls = sub if key[0] == 1 else np.arange(12)
        firsts = [int(g[np.flatnonzero(a.slot[q, g] == 0)[0]]) for q in calls]
        assert firsts == [int(g[t % g.size]) for t in range(len(calls))], key
        assert (a.slot[np.ix_(calls, g)] < g.size).all()
    s = timing_summary.method_summary(a)
    assert s.timed_calls == 12 and s.timed_calls_paper == 4 and s.max_calls_paper == 4
    assert "on 4 of them" in timing_text.method_text(a)
    assert timing_summary.method_summary(full).timed_calls_paper == 12


def _subset_timing(n=40, every=4):
    """Fake replay: depth and svd on main (all n calls) and on alt (every
    ``every``-th call); the untimed alt entries hold -1 (as the replay writes)."""
    runs = np.repeat(np.arange(8), n // 8)
    main_d, main_s = np.full(n, 100.0), np.full(n, 400.0)
    alt_d = np.where(np.arange(n) % 2 == 0, 1000.0, 3000.0)      # subset calls (even) cost 1000
    alt_s = np.full(n, 5000.0)
    alt_s[np.arange(n) % every != 0] = 50.0                        # not on the subset
    tm = timing.from_times({"depth": main_d * 1e3, "svd": main_s * 1e3, "depth@": alt_d * 1e3,
                            "svd@": alt_s * 1e3},
                           {"depth": main_d * 1e3, "svd": main_s * 1e3, "depth@": alt_d * 1e3,
                            "svd@": alt_s * 1e3}, runs, n_evals=7)
    tm = tm.replace(variant_method=np.array(["depth", "svd", "depth", "svd"]),
                    variant_path=np.array(["main", "main", "alt", "alt"]),
                    variant_eval_path=np.array(["compiled", "compiled", "paper", "paper"]),
                    methods=np.array(["depth", "svd"]), mismatch=np.zeros(2, np.int64),
                    checked=np.zeros(2, np.int64), max_calls_paper=np.int64(n // every))
    sub = np.arange(n) % every == 0
    tm.timed[~sub, 2:] = False
    for k in ("wall_ns", "cpu_ns", "n_evals", "slot"):
        getattr(tm, k)[~sub, 2:] = -1
    tm.n_evals[sub, 2:] = 31
    return tm, sub


def test_consumers_ignore_untimed_entries(recorded):
    """Medians, evaluations, quantiles, per-run medians, B-T3, B-F7 and the
    method summary read only the timed entries: the -1 entries (three quarters
    of the paper path's calls) would drag every paper-path median to -1 us."""
    import matplotlib

    matplotlib.use("Agg")
    from opnav.report.landing.plots import fig_planning_time

    tm, sub = _subset_timing()
    assert timing_summary.median_us(tm, "svd", "alt") == pytest.approx(5000.0)
    assert timing_summary.median_us(tm, "depth", "alt", clock="cpu") == pytest.approx(1000.0)
    assert timing_summary.times_ns(tm, "svd", "alt").size == sub.sum()
    assert timing_summary.median_evals(tm, "svd", "alt") == 31 and timing_summary.median_evals(tm, "svd") == 7
    assert timing_summary.timed_calls(tm, "svd", "alt") == 10 and timing_summary.timed_calls(tm, "svd") == 40
    f = timing_text.summary_frame(tm).set_index(["method", "path"])
    assert f.loc[("svd", "alt"), "calls"] == 10 and f.loc[("svd", "alt"), "cpu_p05_us"] == pytest.approx(5000)
    assert f.loc[("depth", "alt"), "median_evals"] == 31
    assert set(timing_summary.per_run_median_us(tm, "svd", path="alt").values()) == {5000.0}
    assert timing_summary.method_summary(tm).timed_calls_paper == 10
    _, rec = recorded
    t = summary_table({m: copy.copy(rec[m]) for m in ("depth", "svd")}, tm).set_index("method")
    assert t.loc["svd", "median_plan_time_alt_us"] == pytest.approx(5000.0)
    assert t.loc["depth", "timed_calls_alt"] == 10 and t.loc["depth", "timed_calls"] == 40
    assert t.loc["depth", "time_reduction_vs_svd_alt_pct"] == pytest.approx(80.0)
    fig = fig_planning_time(tm, ["depth", "svd"], 29.03)
    assert sorted(x.get_text() for x in fig.axes[0].texts) == ["100", "1000", "400", "5000"]
    assert "80.0 %" in fig.axes[0].get_title() and "10 of the calls" in fig.axes[0].get_xlabel()
    leg = fig.axes[0].get_legend()                 # which box is which path: filled, hollow hatched
    assert [t.get_text() for t in leg.get_texts()] == ["compiled", "paper"]
    boxes = [p for p in fig.axes[0].patches if p.get_hatch()]
    assert len(boxes) == 2 and all(p.get_facecolor()[:3] == (1.0, 1.0, 1.0) for p in boxes)


def test_reductions_across_paths_use_the_common_subset():
    """depth compiled (every call) vs svd paper (the subset): the medians come
    from the calls timed on both; the main-path depth times outside the subset
    (here 1 us) would move the result if they were used."""
    tm, sub = _subset_timing()
    tm.cpu_ns[~sub, 0] = 1000                                   # 1 us off the subset
    red, sd = timing_summary.time_reduction(tm, "depth", "svd", path_a="main", path_b="alt", n_boot=50)
    assert red == pytest.approx(100 * (1 - 100 / 5000)) and sd == pytest.approx(0.0, abs=1e-9)
    assert timing_summary.time_reduction(tm, "depth", "svd", path_a="alt", path_b="alt", n_boot=0)[0] \
        == pytest.approx(80.0)
    assert timing_summary.median_us(tm, "depth") == pytest.approx(1.0)      # its own median: every call
    tm.timed[:, 3] = False
    assert np.isnan(timing_summary.time_reduction(tm, "depth", "svd", path_b="alt")[0])


def test_compiled_calls_are_timed_warm_and_interpreted_ones_once(recorded, monkeypatch):
    """Every compiled search is timed as the kernel's call itself (planner.compiled_call,
    without the Python wrapper), run right after an untimed planner.plan of the same
    variant on the same inputs (its pick; and its time is its own work, not the caches
    its predecessor evicted); interpreted variants (the paper's definition, the pickers)
    run planner.plan for the pick, then in the timed brackets. Counted by wrapping both: per
    variant, one warm-up plan, then per timed call plan + compiled_call (compiled) or plan +
    1 + 2 + ... + reps plans (interpreted: the doubling brackets)."""
    from opnav.landing import planner

    scn, rec = recorded
    seen = []
    real, real_call = planner.plan, planner.compiled_call

    def counting(m, state, camera, field_, visible, cfg, **kw):
        seen.append((m, cfg.eval_path, "plan"))
        return real(m, state, camera, field_, visible, cfg, **kw)

    def counting_call(m, state, camera, field_, cfg, exclude, detected):
        seen.append((m, cfg.eval_path, "kernel"))
        call = real_call(m, state, camera, field_, cfg, exclude, detected)
        assert call is not None
        return call

    monkeypatch.setattr(planner, "plan", counting)
    monkeypatch.setattr(planner, "compiled_call", counting_call)
    a = timing.replay(scn, rec, list(METHODS), max_calls=6, max_calls_paper=3)
    var = timing.variants(list(METHODS), scn.planner)
    keys = timing.pass_keys(var)
    for v, ((m, _, cfg), key) in enumerate(zip(var, keys)):
        n_timed = int(a.timed[:, v].sum())
        compiled = key[1] == 0
        reps = a.reps[a.timed[:, v], v]
        assert (reps >= 1).all()
        # the pick's untimed plan, then the timed brackets (1, 2, 4, ... calls back to back)
        timed_plans = 0 if compiled else int(np.sum(2 * reps - 1))
        assert seen.count((m, cfg.eval_path, "plan")) == 1 + n_timed + timed_plans, (m, cfg.eval_path)
        assert seen.count((m, cfg.eval_path, "kernel")) == (n_timed if compiled else 0), (m, cfg.eval_path)
    for i, (m, p, what) in enumerate(seen):      # each kernel call right after its own plan
        if what == "kernel":
            assert seen[i - 1] == (m, p, "plan")
    # the compiled calls of a pass come before any interpreted one (passes in key order)
    body = seen[len(var):]
    first_interp = next(i for i, (m, p, _) in enumerate(body) if not (m in ("depth", "svd") and p == "compiled"))
    assert all(not (m in ("depth", "svd") and p == "compiled") for m, p, _ in body[first_interp:])


def test_less_time_text_says_more_for_a_negative_reduction():
    """B-F7's title and the manuscript's sentence: a negative reduction is more time."""
    from opnav.report.landing.timing_text import less_time_text

    assert less_time_text(34.2) == "34.2 % less"
    assert less_time_text(-137.4) == "137.4 % more"
    assert less_time_text(0.0) == "0.0 % less"
    assert less_time_text(float("nan")) == "n/a"


def test_the_timed_compiled_call_is_the_planning_call(recorded):
    """What the replay times for a compiled method (planner.compiled_call) computes the pick,
    optimum and evaluations planner.plan returns, on every recorded call of depth and svd
    (the kernel's out vector after the timed call); None for interpreted variants."""
    from opnav.landing.planning import layout
    from opnav.landing import planner

    scn, rec = recorded
    cam, field_, tr = scn.camera, scn.field, scn.truth
    for m in ("depth", "svd"):
        d = rec[m]
        for i in range(len(d.plan_step)):
            k = int(d.plan_step[i])
            det = np.flatnonzero(cam.in_view((field_.xyz - tr.r[k]) @ tr.R_LtoB[k].T, scn.planner.margin_px))
            st = planner.PlanState(d.plan_r[i], d.plan_v[i], d.plan_a[i], d.plan_R[i], d.plan_P[i])
            ex = int(d.plan_exclude[i])
            res = planner.plan(m, st, cam, field_, None, scn.planner, exclude={ex} - {-1}, detected=det,
                               diagnose=False)
            call = planner.compiled_call(m, st, cam, field_, scn.planner, ex, det)
            call()
            out = call.args[-1][-layout.NOUT:]
            if out[layout.O_STATUS] == layout.OK:
                assert (int(out[0]), int(out[3])) == (res.index, res.n_evals)
                assert out[1] == res.beta
        assert planner.compiled_call(m, st, cam, field_, planner.alternative_path(scn.planner), ex, det) is None


def test_repetitions_keep_the_clock_below_5_pct_of_a_recorded_call(recorded, tmp_path):
    """Issue 43 item 2: each replayed call is timed as the mean of back-to-back repetitions,
    enough that the clock's own cost (measured, ``timing.clock_cost_ns``) is below 5 % of the
    timed bracket, on every recorded call of the compiled depth and svd (3-6 us a call: one
    bracket alone would be a third clock). Mutation tried: CLOCK_SHARE_INV = 0 (one call per
    bracket) fails."""
    scn, rec = recorded
    a = timing.replay(scn, rec, ["depth", "svd", "svd_lapack"], max_calls=8, alt=False)
    cs = timing_summary.clock_share(a)
    assert 0 < a.clock_ns < 50_000
    assert cs.share_pct_max < 5.0
    ok = a.timed & (a.reps > 0)
    assert np.all(a.reps[ok] * a.cpu_ns[ok] >= 0.95 * timing.CLOCK_SHARE_INV * a.clock_ns)
    assert cs.reps_max > 1                                   # a compiled call needs repeating
    assert "below 5 %" in timing_text.method_text(a)
    # the machine's load during the replay is kept and stated with the times (other processes
    # on the cores lengthen microsecond calls), and survives the file round trip
    import os

    assert a.load_avg.shape == (2,) and np.all(np.isfinite(a.load_avg)) and a.n_cpu == os.cpu_count()
    lo, hi = a.load_avg
    assert f"load average was {lo:.1f} at the start and {hi:.1f} at the end" in timing_text.method_text(a)
    timing.save(tmp_path / "t.npz", a)
    assert timing_text.method_text(timing.load(tmp_path / "t.npz")) == timing_text.method_text(a)
    # the closed form and the LAPACK SVD of the same H pick alike
    v = list(a.variant_method)
    assert np.array_equal(a.pick[:, v.index("svd")], a.pick[:, v.index("svd_lapack")])


def test_main_and_replication_timing_time_one_list():
    """Each timing is two jobs per scenario: the replays (alone: every core) of the compiled calls
    the timing claims read (B_REPLAYED = landing.mc.methods), and an ordinary job (never every
    core) timing the other variants once. The main one times B-X1's methods plus the timed-only
    kinds (svd_lapack: ``timing.timed_methods``, one list), on the recorded calls of what it flies;
    the replication only what its claims read (B_REPLAYED, both paths), on the calls of what it
    flies. Mutations: a replay rule without every core, the replication timing B_TIMED."""
    import re
    from pathlib import Path

    assert timing.timed_methods(["depth", "svd"]) == ["depth", "svd", "svd_lapack"]
    assert timing.timed_methods(["svd_lapack", "depth"]) == ["svd_lapack", "depth"]
    rules = Path(__file__).resolve().parents[1] / "workflow" / "rules"
    text = {p.name: p.read_text() for p in rules.glob("*.smk")}
    assert "B_TIMED = timed_methods(X1_METHODS)" in text["landing_timing.smk"]
    assert "B_REPLAYED = list(B_METHODS)" in text["landing_timing.smk"]

    def block(name, rule):
        return re.search(rf"rule {rule}:\n(.*?)(?=\n\s*rule |\Z)", text[name], re.S).group(1)

    for name, rule, flown, timed in (("landing_timing.smk", "landing_timing", "X1_METHODS", "B_TIMED"),
                                     ("replication.smk", "replication_landing_timing", "REP_B_FLOWN", "B_REPLAYED")):
        reps, other = block(name, rule + "_replays"), block(name, rule)
        for b in (reps, other):
            assert re.search(rf"mc=lambda wc: b_mc\(wc.bscn, {flown}\)", b), (name, rule)
            assert re.search(rf"\bflown={flown}\b", b), (name, rule)
        assert re.search(r"\breplayed=B_REPLAYED\b", reps)
        # the millisecond job does not wait for the replays (it runs as soon as its Monte Carlo is
        # there, beside other jobs); the summaries read both
        assert re.search(rf"\bmethods={timed}\b", other) and "replays=" not in other
        # the replays run alone (threads: every core), so no other job shares the cores they time on;
        # the millisecond calls run beside other jobs
        assert re.search(r"^\s*threads: all_cores\(\)", reps, re.M), (name, rule)
        assert "threads:" not in other, (name, rule)
    # the replication flies B_METHODS and B_EQ_METHODS (its Monte Carlo rules): its timing replays
    # those calls but times only the claims' methods (no B-X1 method, no svd_lapack)
    assert "timing=lambda wc: expand(B_TIMING, bscn=wc.bscn)" in block("landing.smk", "landing_summary")
    assert "timing=lambda wc: expand(B_TIMING, bscn=wc.bscn)" in block("landing_extra.smk", "landing_x1_summary")
    assert ("timing=[*rules.replication_landing_timing_replays.output.replays, "
            "*rules.replication_landing_timing.output]") in block("replication.smk", "replication_landing_summary")
    rep = text["replication.smk"]
    assert "REP_B_FLOWN = list(dict.fromkeys([*B_METHODS, *B_EQ_METHODS]))" in rep
    assert re.search(r"for m in B_METHODS\]", rep) and re.search(r"for m in B_EQ_METHODS\]", rep)
    assert "B_TIMED" not in rep
    # no second copy of the list: the timed-only kinds are named in the package only
    assert not [n for n, t in text.items() if "svd_lapack" in t]


@pytest.mark.slow
def test_replay_keeps_blas_on_its_own_thread(recorded, monkeypatch):
    """The thread CPU clock sees a call's work only on the calling thread, so the replay runs
    BLAS/LAPACK single-threaded whatever the caller set (a job given all cores, a run by hand:
    OpenBLAS starts one thread per core), and restores the caller's setting. Mutation tried:
    without the limit the planning calls see the caller's 2 threads and it fails."""
    from threadpoolctl import threadpool_info, threadpool_limits

    from opnav.landing import planner

    seen = []
    plan = planner.plan

    def spying(*a, **k):
        seen.append(max((i["num_threads"] for i in threadpool_info()), default=1))
        return plan(*a, **k)

    monkeypatch.setattr(planner, "plan", spying)
    scn, rec = recorded
    with threadpool_limits(limits=2):
        timing.replay(scn, rec, ["depth"], max_calls=2, alt=False)
        after = max((i["num_threads"] for i in threadpool_info()), default=1)
    assert seen and set(seen[1:]) == {1}, seen      # the first: the warm-up, before the limit
    assert after == 2 or not threadpool_info()
