"""Planning time by replay (paper B sec. 3, Fig. 7 and the time reduction of
Table 3; SPEC B.4).

Description
-----------
The descent (``opnav.landing.descent.run_descent``) records, per planning
call, everything ``planner.plan`` takes (``opnav.landing.records``): the filter
step (the truth pose, hence the camera's detected landmarks, follows from the
scenario), the estimate ``PlanState(r, v, a, R_LtoB, P)``, the excluded current
landmark and the state of the run's picker stream. Timing is then done apart
from the filter's own work; the descent itself times nothing.

Replay (:func:`replay`): the recorded calls of the Monte Carlo of every
method are pooled (in method order, then run, then call); a deterministic
subset of at most ``max_calls`` of them, evenly spaced by pool index
(:func:`select_calls`), is replayed through every method's planning call
(``planner.plan``) on both paths (the configured one, ``compiled``: the kernels
a lander's computer would run, and ``planner.alternative_path``, ``paper``: the
paper's definition interpreted, CasADi H and LAPACK SVD), one
call at a time in one process. The variants on the paper's definition that are
not the configured path (``alt`` when ``eval_path`` is ``compiled``; an edge call
of an H baseline scores every detected landmark through CasADi, a fraction of a second)
are timed on a subset of the replayed calls only: at most
``max_calls_paper`` of them, evenly spaced over the replayed calls by the same
rule (``select_calls(n_replayed, max_calls_paper)`` over replay positions, so the
subset spans the descent; 0 or at least the replayed calls: all of them). The
calls outside it are not run on those variants and marked untimed (``timed``
false; ``wall_ns`` = ``cpu_ns`` = ``n_evals`` = ``slot`` = -1, ``pick`` = -2);
every consumer below reads timed entries only, and a comparison of two variants
(``timing_summary.time_reduction``) uses the calls timed on both. So a median on the
configured path rests on every replayed call, one on the paper's definition
on the subset (``method_summary``: ``timed_calls``, ``timed_calls_paper``).
Passes and order rule (:func:`pass_keys`): the variants are timed in separate
passes over the calls, first the configured path on every replayed call, then
the other path on its subset, and within a path the compiled searches before the
interpreted code (the paper's definition, the pickers); on the
``t``-th call of a pass that pass's variants run in their configured order
rotated left by ``t`` (never ordered by a clock), so slow drifts of the machine
(frequency, other processes) fall on every method alike and every variant comes
first in turn. Every call is timed warm, right after an untimed call of the same variant on
the same inputs (its pick), so that it measures its own work and not the caches the call
before it evicted, and as the mean of back-to-back repetitions: the count doubles (1, 2, 4,
...) until the bracket's CPU time reaches :data:`CLOCK_SHARE_INV` (25) times the clock's own
cost, measured per replay (:func:`clock_cost_ns`: two perf_counter_ns and two thread_time_ns
readings, comparable with a compiled call itself); so the clock is below 5 % of every timed
bracket (``timing_summary.clock_share`` reports it; the interpreted calls, milliseconds,
need one). The passes, the rotation and the warm call exist because the order of the
variants and the cache state left by the call before moved the compiled times more than
the methods did (docs/performance.md, "Measurements formerly in docstrings (planning
time)"). ``svd_lapack`` (a real LAPACK SVD of the same H, compiled) is timed beside svd's
closed form (:data:`COMPILED_ONLY`). Every method is timed on the same states, so the
comparison is paired per call. Each call is timed by ``time.perf_counter_ns`` (wall) and
``time.thread_time_ns`` (CPU time of the calling thread, which other
processes do not inflate), with the image's detected landmarks given (the
feature detector's list, computed from the truth pose before the clock starts,
as in the descent) and without the pick-ratio diagnostic: a compiled call
around the kernel's call itself (``planner.compiled_call``, what a lander's
computer runs: the whole planning call, numba's argument dispatch included),
its pick from the untimed call before it; interpreted code around
``planner.plan``. The Python wrapper around the compiled call (the
``PlanResult`` the Monte Carlo keeps) is the harness's, not the planner's, and is
left out (:func:`call_overhead` measures it). The garbage collector is held during the timed calls
(collected between calls). One untimed warm-up call per variant precedes the
timing (imports, caches).

Check: the replayed pick of the method whose descent recorded the call, on
the configured path, must equal the recorded pick; mismatches are counted per
method (``mismatch``; nonzero means the replay is not the descent's call).

Units: times ns in the arrays, us in the summaries. A replay is written and
read by ``records.save`` / ``records.load`` (also ``timing.save`` / ``timing.load``);
what is read from it (medians, reductions and their intervals, depth against each SVD, the
clock's share, the method sentence) is :mod:`opnav.landing.timing_summary`.
"""

from __future__ import annotations

import functools
import gc
import math
import os
import time

import numpy as np

from opnav.landing.records import RECORD_KEYS, load, rng_from_words, save

__all__ = ["select_calls", "COMPILED_ONLY", "timed_methods", "variants", "pass_keys", "paper_limited", "replay",
           "CLOCK_SHARE_INV", "clock_cost_ns", "replay_own", "from_times", "call_overhead", "save", "load"]


# ----------------------------------------------------------------- replay

def select_calls(n_pool: int, max_calls: int, key: str = "landing.timing.max_calls") -> np.ndarray:
    """Pool indices replayed: all if ``max_calls`` is 0 or at least ``n_pool``,
    else ``max_calls`` indices evenly spaced over the pool (``floor(i n / m)``,
    distinct, increasing; deterministic). ``key`` names the limit in the error."""
    n, m = int(n_pool), int(max_calls)
    if m < 0:
        raise ValueError(f"{key} must be >= 0, got {m}")
    if m == 0 or m >= n:
        return np.arange(n, dtype=np.int64)
    return (np.arange(m, dtype=np.int64) * n) // m


#: methods timed on the compiled path only (their paper path is another method's: svd_lapack's
#: is svd's, the CasADi H and LAPACK SVD)
COMPILED_ONLY = ("svd_lapack",)


def timed_methods(flown) -> list[str]:
    """The methods a replay times: the ``flown`` ones (whose Monte Carlo records the calls),
    then :data:`COMPILED_ONLY` (timed on those calls, no Monte Carlo of their own). The main
    and the replication timing both take their list from here."""
    flown = list(flown)
    return flown + [m for m in COMPILED_ONLY if m not in flown]


def variants(methods, cfg, alt: bool = True) -> list[tuple[str, str, object]]:
    """The timed (method, path, PlannerConfig): every method on ``cfg``'s path
    (``"main"``), and, unless ``alt`` is false, every method with a search on the
    other path (``"alt"``, ``planner.alternative_path``: compiled <-> the paper's
    definition; for ``logdet_nav``, ``planning.reference`` in numpy)."""
    from opnav.landing.planner import PICKERS, alternative_path

    alt_cfg = alternative_path(cfg)
    out = []
    for m in methods:
        out.append((m, "main", cfg))
        if alt and m not in PICKERS and m not in COMPILED_ONLY:
            out.append((m, "alt", alt_cfg))
    return out


def pass_keys(var) -> list[tuple[int, int]]:
    """Per variant of :func:`variants`, the pass that times it (module docstring):
    ``(0, .)`` the configured path, ``(1, .)`` the other one; ``(., 0)`` a compiled
    search (a method of ``planning.layout.KINDS`` on the compiled path), ``(., 1)`` interpreted
    code (the paper's definition, the pickers). Passes run in
    ascending key order."""
    from opnav.landing.planner import compiled_kind

    return [(int(p != "main"), int(compiled_kind(m, c) < 0)) for m, p, c in var]


def paper_limited(var) -> np.ndarray:
    """Per variant of :func:`variants`, whether ``landing.timing.max_calls_paper``
    limits it: the paper's definition on the other path (``alt`` with
    ``eval_path == "paper"``); the configured path is always timed on every
    replayed call (it carries the pick check)."""
    return np.array([p == "alt" and c.eval_path == "paper" for _, p, c in var], bool)


def _pool(recorded: dict) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(source method position, call position within its Monte Carlo) of every recorded call."""
    names = list(recorded)
    src, pos = [], []
    for i, m in enumerate(names):
        d = recorded[m]
        missing = [k for k in RECORD_KEYS if k not in d]
        if missing:
            raise ValueError(f"Monte Carlo of {m!r} holds no planning inputs ({', '.join(missing)}): "
                             "rebuild it with this version")
        n = len(d["plan_step"])
        for k in ("plan_r", "plan_v", "plan_a", "plan_R", "plan_P"):
            if len(d[k]) != n or not np.isfinite(d[k]).all():
                raise ValueError(f"Monte Carlo of {m!r}: recorded {k} not finite or not one per call")
        src.append(np.full(n, i, np.int64))
        pos.append(np.arange(n, dtype=np.int64))
    return (np.concatenate(src) if src else np.zeros(0, np.int64),
            np.concatenate(pos) if pos else np.zeros(0, np.int64), names)


def replay(scn, recorded: dict[str, dict], methods, max_calls: int = 0, alt: bool = True,
           max_calls_paper: int = 0) -> dict:
    """Replay recorded planning calls through every method (module docstring).

    ``scn``: the descent's scenario (``descent.build_scenario``); ``recorded``:
    method -> gathered Monte-Carlo dict (``montecarlo.gather``), the sources of
    the calls; ``methods``: the methods timed. Returns arrays: per replayed call
    ``source`` (position in ``sources``), ``run``, ``call`` (position in its
    source's calls), ``step``; per call and variant ``wall_ns``, ``cpu_ns``,
    ``pick``, ``n_evals``, ``slot`` (position in that call's order), ``timed``
    (false: not run, the entries -1, pick -2); per variant ``variant_method``,
    ``variant_path``, ``variant_eval_path``; per method of ``methods``
    ``mismatch`` (recorded pick != replayed pick, own calls) and ``checked``
    (own calls replayed); ``n_pool``, ``max_calls``, ``max_calls_paper``.
    ``alt = False`` times the configured evaluation path only;
    ``max_calls_paper`` limits the paper's-definition variants on the other path
    to that many of the replayed calls, evenly spaced (0: all; module docstring).
    """
    from opnav.landing.planner import PlanState, compiled_call, plan

    methods = list(methods)
    if not methods:
        raise ValueError("replay: no methods to time")
    src, pos, names = _pool(recorded)
    sel = select_calls(len(src), max_calls)
    var = variants(methods, scn.planner, alt)
    nv, nc = len(var), len(sel)
    limited = paper_limited(var)
    timed_ = np.ones((nc, nv), bool)
    timed_[:, limited] = False
    sub = select_calls(nc, max_calls_paper, "landing.timing.max_calls_paper")
    timed_[np.ix_(sub, np.flatnonzero(limited))] = True
    cam, field_, xyz = scn.camera, scn.field, scn.field.xyz
    tr = scn.truth
    margin = scn.planner.margin_px
    wall = np.full((nc, nv), -1, np.int64)
    cpu = np.full((nc, nv), -1, np.int64)
    pick = np.full((nc, nv), -2, np.int64)
    evals = np.full((nc, nv), -1, np.int64)
    slot = np.full((nc, nv), -1, np.int64)
    own = {m: (names.index(m) if m in names else -1) for m in methods}
    mismatch = np.zeros(len(methods), np.int64)
    checked = np.zeros(len(methods), np.int64)
    run = np.zeros(nc, np.int64)
    step = np.zeros(nc, np.int64)

    def inputs(q):
        d = recorded[names[src[sel[q]]]]
        i = pos[sel[q]]
        k = int(d["plan_step"][i])
        r_t, R_t = tr.r[k], tr.R_LtoB[k]

        def visible(pts, margin=margin, r_t=r_t, R_t=R_t):
            return cam.in_view((np.asarray(pts) - r_t) @ R_t.T, margin)

        state = PlanState(d["plan_r"][i], d["plan_v"][i], d["plan_a"][i], d["plan_R"][i], d["plan_P"][i])
        ex = int(d["plan_exclude"][i])
        return (d, i, k, state, visible, {ex} if ex >= 0 else set(),
                np.flatnonzero(visible(xyz)), d["plan_rng"][i])

    perf, thread = time.perf_counter_ns, time.thread_time_ns
    clock_ns = clock_cost_ns()
    load_start = os.getloadavg()[0]         # other processes on the cores: stated with the times
    reps = np.full((nc, nv), -1, np.int64)
    if nc:
        _, _, _, state, visible, exclude, det, words = inputs(0)
        for m, _, cfg in var:                                     # warm-up, untimed
            plan(m, state, cam, field_, visible, cfg, exclude=exclude, rng=rng_from_words(words),
                 detected=det, diagnose=False)
    # thread CPU time must see all of a call's work: BLAS and LAPACK (numpy's, the paper path's
    # SVDs and products) on this thread only, whatever the environment gives (a job with more
    # threads, or a run by hand: OpenBLAS starts one thread per core)
    from threadpoolctl import threadpool_limits

    blas = threadpool_limits(limits=1)
    gc_was = gc.isenabled()
    gc.collect()
    gc.disable()
    # one pass per pass key (module docstring: path, then compiled before interpreted);
    # the t-th call of a pass runs that pass's variants in their configured order
    # rotated left by t
    keys = pass_keys(var)
    seen: dict = {}
    try:
        for key in sorted(set(keys)):
            group = np.flatnonzero(np.array([k == key for k in keys]))
            calls = [q for q in range(nc) if timed_[q, group].any()]
            for t, q in enumerate(calls):
                if q not in seen:           # built once per call, whatever the passes
                    seen[q] = inputs(q)
                d, i, k, state, visible, exclude, det, words = seen[q]
                run[q] = int(d["plan_run"][i]) if "plan_run" in d else -1
                step[q] = k
                order = group[timed_[q, group]]
                for s_, v in enumerate(np.roll(order, -(t % len(order)))):
                    m, _, cfg = var[v]
                    # the pick from an untimed call (the descent's stream for a picker), then
                    # the timed call: the kernel's call (compiled) or plan() (interpreted), warm
                    res = plan(m, state, cam, field_, visible, cfg, exclude=exclude,
                               rng=rng_from_words(words), detected=det, diagnose=False)
                    if key[1] == 0:
                        call = compiled_call(m, state, cam, field_, cfg, next(iter(exclude), -1), det)
                    else:
                        call = functools.partial(plan, m, state, cam, field_, visible, cfg, exclude=exclude,
                                                 rng=rng_from_words(words), detected=det, diagnose=False)
                    n_rep = 1
                    while True:                     # back to back until the clock is < 5 % (REPS_RULE)
                        t0 = perf()
                        c0 = thread()
                        for _ in range(n_rep):
                            call()
                        c1 = thread()
                        t1 = perf()
                        if c1 - c0 >= CLOCK_SHARE_INV * clock_ns or n_rep >= MAX_REPS:
                            break
                        n_rep *= 2
                    wall[q, v], cpu[q, v] = (t1 - t0) // n_rep, (c1 - c0) // n_rep
                    reps[q, v] = n_rep
                    pick[q, v], evals[q, v], slot[q, v] = res.index, res.n_evals, s_
                if t % 64 == 63:
                    gc.collect()
    finally:
        blas.restore_original_limits()
        if gc_was:
            gc.enable()
    for j, m in enumerate(methods):
        mine = src[sel] == own[m]
        v = next(x for x, (mm, path, _) in enumerate(var) if mm == m and path == "main")
        if own[m] >= 0 and mine.any():
            recorded_pick = recorded[m]["plan_index"][pos[sel][mine]]
            checked[j] = int(mine.sum())
            mismatch[j] = int(np.sum(pick[mine, v] != recorded_pick))
    return {"sources": np.array(names), "methods": np.array(methods),
            "source": src[sel], "call": pos[sel], "run": run, "step": step,
            "wall_ns": wall, "cpu_ns": cpu, "pick": pick, "n_evals": evals, "slot": slot,
            "timed": timed_,
            "variant_method": np.array([v[0] for v in var]),
            "variant_path": np.array([v[1] for v in var]),
            "variant_eval_path": np.array([v[2].eval_path for v in var]),
            "mismatch": mismatch, "checked": checked, "reps": reps, "clock_ns": np.float64(clock_ns),
            "load_avg": np.array([load_start, os.getloadavg()[0]]), "n_cpu": np.int64(os.cpu_count() or 0),
            "n_pool": np.int64(len(src)), "max_calls": np.int64(max_calls),
            "max_calls_paper": np.int64(max_calls_paper)}


#: the clock's share of a timed bracket stays at most 1 / CLOCK_SHARE_INV (4 %, inside 5 %): a call is
#: repeated back to back, doubling the count, until the bracket's CPU time reaches
#: CLOCK_SHARE_INV times the clock's own cost (:func:`clock_cost_ns`); the time is the mean
#: of that bracket's calls (the shorter brackets before it are its warm-up)
CLOCK_SHARE_INV, MAX_REPS = 25, 1 << 16


def clock_cost_ns(n: int = 2000, repeats: int = 5) -> float:
    """The cost (ns, thread CPU) of one empty timing bracket as :func:`replay` uses it (two
    ``perf_counter_ns`` and two ``thread_time_ns`` calls): the smallest of ``repeats`` means
    over ``n`` brackets."""
    perf, thread = time.perf_counter_ns, time.thread_time_ns
    best = math.inf
    for _ in range(repeats):
        a = thread()
        for _ in range(n):
            perf()
            thread()
            thread()
            perf()
        best = min(best, (thread() - a) / n)
    return float(best)


def replay_own(scn, data: dict, method: str, max_calls: int = 0) -> dict:
    """Replay a Monte-Carlo dict's (or one ``run_descent`` output's) own calls
    through its own method, configured evaluation path only (parameter
    studies, the CLI: no other methods to interleave with)."""
    d = dict(data)
    if "plan_run" not in d:
        d["plan_run"] = np.zeros(len(d["plan_index"]), np.int64)
    return replay(scn, {method: d}, [method], max_calls, alt=False)


def from_times(wall_ns: dict, cpu_ns: dict, run, n_evals: int = 0) -> dict:
    """A :func:`replay`-shaped result from given per-call times (ns) per
    method, all on the configured path, calls of one source with run indices
    ``run`` (for tests and times measured elsewhere)."""
    methods = list(wall_ns)
    n, k = len(run), len(methods)
    return {"sources": np.array(methods[:1]), "methods": np.array(methods),
            "source": np.zeros(n, np.int64), "call": np.arange(n, dtype=np.int64),
            "run": np.asarray(run, np.int64), "step": np.zeros(n, np.int64),
            "wall_ns": np.column_stack([np.asarray(wall_ns[m]) for m in methods]).astype(np.int64),
            "cpu_ns": np.column_stack([np.asarray(cpu_ns[m]) for m in methods]).astype(np.int64),
            "pick": np.full((n, k), -2, np.int64), "n_evals": np.full((n, k), int(n_evals), np.int64),
            "slot": np.zeros((n, k), np.int64), "timed": np.ones((n, k), bool),
            "variant_method": np.array(methods),
            "variant_path": np.array(["main"] * k), "variant_eval_path": np.array(["main"] * k),
            "mismatch": np.zeros(k, np.int64), "checked": np.zeros(k, np.int64),
            "n_pool": np.int64(n), "max_calls": np.int64(0), "max_calls_paper": np.int64(0)}


def call_overhead(scn, recorded: dict, method: str = "depth", max_calls: int = 0,
                  repeats: int = 3, reps: int = 50) -> dict:
    """The compiled planning call's overhead beyond its objective evaluations, by replay.

    For each selected recorded call of ``recorded[method]`` (:func:`select_calls`)
    on the compiled path: the whole compiled call (``planner.compiled_call``, as :func:`replay`
    times it; ``call_ns``: ``reps`` calls in a row, thread CPU clock, the minimum of
    ``repeats`` averages) and its
    objective evaluations alone (``evals_ns``: ``planning.search.evaluations`` at the betas
    the call's searches evaluate, recorded by an interpreted pass of the same
    search, plus the detected landmarks an edge call scores; timed inside the
    kernel, ``reps`` times, so no call overhead is counted as evaluations). Returns
    per call ``call_ns``, ``evals_ns``, ``n_evals``, ``edge``, ``cold_ns``
    (``planner.plan`` once, cold: the Python wrapper included), ``wrapped_ns`` (``planner.plan``
    hot, as ``call_ns``) and ``overhead_ratio = (call - evals) / evals``."""
    import dataclasses

    from opnav.landing.planning import search as K
    from opnav.landing.planning.geometry import plane_geometry
    from opnav.landing import planner as pl

    d = recorded[method]
    sel = select_calls(len(d["plan_step"]), max_calls)
    cam, field_, tr = scn.camera, scn.field, scn.truth
    cfg = dataclasses.replace(scn.planner, eval_path="compiled")
    thread = time.thread_time_ns
    rows = []
    gc_was = gc.isenabled()
    gc.disable()
    try:
        for i in sel:
            k = int(d["plan_step"][i])
            det = np.flatnonzero(cam.in_view((field_.xyz - tr.r[k]) @ tr.R_LtoB[k].T, cfg.margin_px))
            st = pl.PlanState(d["plan_r"][i], d["plan_v"][i], d["plan_a"][i], d["plan_R"][i], d["plan_P"][i])
            ex = int(d["plan_exclude"][i])
            exclude = {ex} if ex >= 0 else set()
            c0 = thread()
            res = pl.plan(method, st, cam, field_, None, cfg, exclude=exclude, detected=det, diagnose=False)
            cold = thread() - c0
            call_ = pl.compiled_call(method, st, cam, field_, cfg, ex, det)
            _, q = pl.plan_one(method, st, cam, field_, cfg, ex, det)
            if not np.isfinite(res.beta):
                continue
            betas = []

            def spy(b, q, betas=betas):
                betas.append(b)
                return K.objective(b, q)

            search = K.interpreted(K.golden_section, objective=spy)
            for lo, hi in pl.visible_intervals(plane_geometry(st.r, st.v), st.R_LtoB, cam, cfg.margin_px):
                search(q, lo, hi, cfg.tol_rad)
            cand = det[det != ex] if res.edge else np.zeros(0, np.int64)
            xyz = np.ascontiguousarray(field_.xyz)
            bs = np.array(betas)
            call = ev = wrapped = math.inf
            for _ in range(max(int(repeats), 1)):
                c0 = thread()
                for _ in range(reps):
                    call_()
                c1 = thread()
                K.evaluations(q, bs, xyz, cand, reps)
                c2 = thread()
                for _ in range(reps):
                    pl.plan(method, st, cam, field_, None, cfg, exclude=exclude, detected=det, diagnose=False)
                c3 = thread()
                call, ev = min(call, (c1 - c0) / reps), min(ev, (c2 - c1) / reps)
                wrapped = min(wrapped, (c3 - c2) / reps)
            rows.append((call, ev, len(betas) + cand.size, res.edge, cold, wrapped))
    finally:
        if gc_was:
            gc.enable()
    call_ns, evals_ns, n_ev, edge, cold, wrapped = ((np.array(x) for x in zip(*rows)) if rows
                                                    else [np.zeros(0)] * 6)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (call_ns - evals_ns) / evals_ns
    return {"call_ns": call_ns, "evals_ns": evals_ns, "n_evals": n_ev.astype(np.int64),
            "edge": edge.astype(bool), "cold_ns": cold, "wrapped_ns": wrapped, "overhead_ratio": ratio}
