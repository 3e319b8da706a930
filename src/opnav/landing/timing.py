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

Independent replays and the call's two parts (issue 53): a microsecond call's time is a part
every method shares (numba's dispatch, argument unpacking, the plane, the visible interval, the
searches' and the edge rule's own steps) plus evaluations x the cost of one, and the shared part
moves with the machine (3 to 5.5 us between replays of the same calls) while the methods'
difference per call does not, so a percentage reduction read from one replay moves with it. The
compiled calls the timing claims read are therefore replayed several times, each replay in a fresh
process (:func:`replays_in_processes`: its own address-space layout, hash seed and caches; a fork
would share them) run alone on the machine, and each timed compiled call is followed by its
evaluations timed alone inside the kernel (``decompose``: :func:`evaluation_inputs` finds the
angles and candidates the call evaluates; :func:`null_dispatch_ns` times numba's dispatch alone);
the other variants (milliseconds a call) are timed once, beside other jobs, on the same calls, and
:func:`merge` puts them in one replay-shaped dict. pyperf (CPython's benchmark runner) spawns 20
worker processes for the same reason; here a process costs about 1.2 CPU-s before its first
timed call (imports, the compiled kernels, the scenario), so a few replays of many calls each
are used instead of many processes of few calls.

Check: the replayed pick of the method whose descent recorded the call, on
the configured path, must equal the recorded pick; mismatches are counted per
method (``mismatch``; nonzero means the replay is not the descent's call).

Units: times ns in the arrays, us in the summaries. A replay is written and
read by ``records.save`` / ``records.load`` (also ``timing.save`` / ``timing.load``);
what is read from it (medians, reductions and their intervals, depth against each SVD, the
clock's share, the method sentence) is :mod:`opnav.landing.timing_summary`.
"""

from __future__ import annotations

import dataclasses
import functools
import gc
import math
import os
import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from opnav.landing.records import RECORD_KEYS, MonteCarlo, Replay, load as _load_arrays, rng_from_words
from opnav.landing.records import save as _save_arrays
from opnav.landing.setup import Setup

__all__ = ["select_calls", "COMPILED_ONLY", "timed_methods", "variants", "pass_keys", "paper_limited", "replay",
           "evaluation_inputs", "null_dispatch_ns", "merge", "REPLAY_BEST_OF", "COLD_OK_NS", "CALL_INPUT_KEYS", "load_calls", "ReplaySpec", "run_spec", "replay_spec", "replays_in_processes",
           "CLOCK_SHARE_INV", "clock_cost_ns", "replay_own", "from_times", "call_overhead", "CallOverhead", "Replay",
           "save", "load"]


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


def variants(methods, cfg, alt=True, main=None) -> list[tuple[str, str, object]]:
    """The timed (method, path, PlannerConfig): every method on ``cfg``'s path
    (``"main"``; only those of ``main`` if given), and, unless ``alt`` is false, every
    method with a search on the other path (``"alt"``, ``planner.alternative_path``:
    compiled <-> the paper's definition; for ``logdet_nav``, ``planning.reference`` in
    numpy; only those of ``alt`` if it is a collection of methods). A user's own method
    (landing.custom_methods) runs the same code on both paths: timed on ``"main"`` only."""
    from opnav.landing.methods import BUILTIN
    from opnav.landing.planner import PICKERS, alternative_path

    alt_cfg = alternative_path(cfg)
    out = []
    for m in methods:
        if main is None or m in main:
            out.append((m, "main", cfg))
        if (alt is True or (alt and not isinstance(alt, bool) and m in alt)) \
                and m not in PICKERS and m not in COMPILED_ONLY and m in BUILTIN:
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


def _pool(recorded: dict[str, MonteCarlo]) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(source method position, call position within its Monte Carlo) of every recorded call."""
    names = list(recorded)
    src, pos = [], []
    for i, m in enumerate(names):
        d = recorded[m]
        missing = [k for k in RECORD_KEYS if not d.has(k)]
        if missing:
            raise ValueError(f"Monte Carlo of {m!r} holds no planning inputs ({', '.join(missing)}): "
                             "rebuild it with this version")
        n = len(d.plan_step)
        for k in ("plan_r", "plan_v", "plan_a", "plan_R", "plan_P"):
            if len(getattr(d, k)) != n or not np.isfinite(getattr(d, k)).all():
                raise ValueError(f"Monte Carlo of {m!r}: recorded {k} not finite or not one per call")
        src.append(np.full(n, i, np.int64))
        pos.append(np.arange(n, dtype=np.int64))
    return (np.concatenate(src) if src else np.zeros(0, np.int64),
            np.concatenate(pos) if pos else np.zeros(0, np.int64), names)


def evaluation_inputs(method: str, state, camera, field_, cfg, exclude: int, detected: np.ndarray):
    """What the compiled planning call of ``method`` evaluates, for timing its evaluations alone:
    ``(q, betas, cand, n_evals)`` with ``q`` the call's per-run constants, ``betas`` (rad) the
    angles its golden-section searches evaluate, in order, and ``cand`` the landmarks its edge rule
    scores (empty when the optimum is inside the image), found by running the call's own steps
    (``planning.search.plan_core``) with an interpreted search whose objective records its
    argument (the compiled objective still computes every value, so the path is the kernel's);
    ``n_evals = betas.size + cand.size``, the call's own count, and ``xyz`` the field as the kernel
    takes it. None if the call has no search
    (no compiled kind, or a degenerate geometry: the fallback evaluates nothing)."""
    from opnav.landing import planner as pl
    from opnav.landing.planning import layout as L, search as K

    kind = pl.compiled_kind(method, cfg)
    if kind < 0:
        return None
    res, q = pl.plan_one(method, state, camera, field_, cfg, int(exclude), detected)
    if not math.isfinite(res.beta):
        return None
    q = np.array(q)
    betas: list[float] = []

    def spy(b, q, betas=betas, objective=K.objective):
        betas.append(b)
        return objective(b, q)

    xyz, c, cells = pl._setup(field_, cfg, camera)
    out = np.zeros(L.NOUT)
    core = K.interpreted(K.plan_core, golden_section=K.interpreted(K.golden_section, objective=spy))
    core(q, camera.R_BtoC @ state.R_LtoB, c[L.C_KFOV], c[L.C_TOL], xyz, detected, int(exclude),
         c[L.C_GRID:L.C_GRID + L.NG], cells, out)
    cand = detected[detected != int(exclude)] if out[L.O_EDGE] > 0 else np.zeros(0, np.int64)
    return q, np.array(betas, float), np.ascontiguousarray(cand, np.int64), len(betas) + cand.size, xyz


def null_dispatch_ns(args: tuple, n: int = 2000, repeats: int = 5) -> float:
    """Thread CPU (ns) of one call of a compiled kernel that does nothing, called with ``args`` (a
    compiled planning call's arguments, ``planner.compiled_call(...).args``): numba's argument
    dispatch and the call itself, the part of a compiled call no kernel work can remove (the
    smallest of ``repeats`` means over ``n`` calls, the loop's own cost subtracted)."""
    import numba

    null = numba.njit(lambda *a: None)      # not cached: a harness, compiled once a replay (~0.1 s)
    null(*args)
    thread = time.thread_time_ns
    best = math.inf
    for _ in range(repeats):
        a = thread()
        for _ in range(n):
            null(*args)
        b = thread()
        for _ in range(n):
            pass
        c = thread()
        best = min(best, ((b - a) - (c - b)) / n)
    return float(best)


def replay(scn, recorded: dict[str, MonteCarlo], methods, max_calls: int = 0, alt=True,
           max_calls_paper: int = 0, main=None, decompose: bool = False, best_of: int = 1,
           warm_compiled: bool = True) -> Replay:
    """Replay recorded planning calls through every method (module docstring).

    ``scn``: the descent's scenario (``descent.build_scenario``); ``recorded``:
    method -> gathered Monte Carlo (``records.MonteCarlo``, its calls), the sources of
    the calls; ``methods``: the methods timed. Returns the :class:`~opnav.landing.records.Replay`
    of arrays: per replayed call
    ``source`` (position in ``sources``), ``run``, ``call`` (position in its
    source's calls), ``step``; per call and variant ``wall_ns``, ``cpu_ns``,
    ``pick``, ``n_evals``, ``slot`` (position in that call's order), ``timed``
    (false: not run, the entries -1, pick -2); per variant ``variant_method``,
    ``variant_path``, ``variant_eval_path``; per method of ``methods``
    ``mismatch`` (recorded pick != replayed pick, own calls) and ``checked``
    (own calls replayed); ``n_pool``, ``max_calls``, ``max_calls_paper``.
    ``alt = False`` times the configured evaluation path only (a collection of methods: the
    other path of those only); ``main``, if given, the methods timed on the configured path
    (default: all); ``max_calls_paper`` limits the paper's-definition variants on the other path
    to that many of the replayed calls, evenly spaced (0: all; module docstring).
    ``decompose``: each timed compiled call is followed by a bracket timing its objective
    evaluations alone inside the kernel (``planning.search.evaluations`` at the call's own
    angles and edge candidates, :func:`evaluation_inputs`): ``eval_ns`` (thread CPU, ns, -1
    where not timed) beside ``cpu_ns``; the call's shared part is ``cpu_ns - eval_ns``
    (``timing_summary.decomposition``), and ``dispatch_ns`` is numba's dispatch alone
    (:func:`null_dispatch_ns` with the first compiled call's arguments). ``best_of``: a compiled
    call's bracket is timed that many times back to back and the least thread CPU kept (the bracket
    the machine disturbed least: other processes only ever add to a call's time).
    ``warm_compiled = False``: a compiled call is first run once, timed; if that took at least
    :data:`COLD_OK_NS` of thread CPU (a call of milliseconds, which the caches the call before it
    left barely move), that run is its time and its pick is read from the kernel's own result
    (``planner.plan`` only where the kernel's status sends the planner to its fallback): half the
    cost of a warm call and a timed one. Shorter calls are timed warm as above (the run served as
    their warm-up).
    """
    from opnav.landing.methods import eval_path
    from opnav.landing.planner import PlanState, compiled_call, plan

    methods = list(methods)
    if not methods:
        raise ValueError("replay: no methods to time")
    src, pos, names = _pool(recorded)
    sel = select_calls(len(src), max_calls)
    var = variants(methods, scn.planner, alt, main)
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
    eval_ns = np.full((nc, nv), -1, np.int64)
    dispatch = math.nan
    own = {m: (names.index(m) if m in names else -1) for m in methods}
    mismatch = np.zeros(len(methods), np.int64)
    checked = np.zeros(len(methods), np.int64)
    run = np.zeros(nc, np.int64)
    step = np.zeros(nc, np.int64)

    def inputs(q):
        d = recorded[names[src[sel[q]]]]
        i = pos[sel[q]]
        k = int(d.plan_step[i])
        r_t, R_t = tr.r[k], tr.R_LtoB[k]

        def visible(pts, margin=margin, r_t=r_t, R_t=R_t):
            return cam.in_view((np.asarray(pts) - r_t) @ R_t.T, margin)

        state = PlanState(d.plan_r[i], d.plan_v[i], d.plan_a[i], d.plan_R[i], d.plan_P[i])
        ex = int(d.plan_exclude[i])
        return (d, i, k, state, visible, {ex} if ex >= 0 else set(),
                np.flatnonzero(visible(xyz)), d.plan_rng[i])

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
                run[q] = int(d.plan_run[i]) if d.has("plan_run") else -1
                step[q] = k
                order = group[timed_[q, group]]
                for s_, v in enumerate(np.roll(order, -(t % len(order)))):
                    m, _, cfg = var[v]
                    res = cold = call = None
                    if key[1] == 0 and not warm_compiled:     # a call of milliseconds: timed as it comes
                        call = compiled_call(m, state, cam, field_, cfg, next(iter(exclude), -1), det)
                        t0 = perf()
                        c0 = thread()
                        call()
                        c1 = thread()
                        t1 = perf()
                        if c1 - c0 >= COLD_OK_NS:
                            cold = (t1 - t0, c1 - c0)
                            res = _kernel_result(call)
                    if cold is not None:
                        wall[q, v], cpu[q, v], reps[q, v] = cold[0], cold[1], 1
                    else:
                        # the pick from an untimed call (the descent's stream for a picker), then the
                        # timed call: the kernel's call (compiled) or plan() (interpreted), warm
                        res = plan(m, state, cam, field_, visible, cfg, exclude=exclude,
                                   rng=rng_from_words(words), detected=det, diagnose=False)
                        if call is None and key[1] == 0:
                            call = compiled_call(m, state, cam, field_, cfg, next(iter(exclude), -1), det)
                        elif call is None:
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
                        for _ in range(int(best_of) - 1 if key[1] == 0 else 0):   # the least disturbed bracket
                            t0 = perf()
                            c0 = thread()
                            for _ in range(n_rep):
                                call()
                            c1 = thread()
                            t1 = perf()
                            if (c1 - c0) // n_rep < cpu[q, v]:
                                wall[q, v], cpu[q, v] = (t1 - t0) // n_rep, (c1 - c0) // n_rep
                        reps[q, v] = n_rep
                    if res is None:        # the kernel's status sent the planner to its fallback
                        res = plan(m, state, cam, field_, visible, cfg, exclude=exclude,
                                   rng=rng_from_words(words), detected=det, diagnose=False)
                    if decompose and key[1] == 0:
                        ev = evaluation_inputs(m, state, cam, field_, cfg, next(iter(exclude), -1), det)
                        if ev is not None and ev[3] == res.n_evals:
                            eval_ns[q, v] = _time_evaluations(ev, clock_ns)
                        if math.isnan(dispatch):
                            dispatch = null_dispatch_ns(call.args)
                    pick[q, v], evals[q, v], slot[q, v] = res.index, res.n_evals, s_
                if t % 64 == 63:
                    gc.collect()
    finally:
        blas.restore_original_limits()
        if gc_was:
            gc.enable()
    for j, m in enumerate(methods):
        mine = src[sel] == own[m]
        v = next((x for x, (mm, path, _) in enumerate(var) if mm == m and path == "main"), None)
        if v is not None and own[m] >= 0 and mine.any():     # checked where the configured path is timed
            recorded_pick = recorded[m].plan_index[pos[sel][mine]]
            checked[j] = int(mine.sum())
            mismatch[j] = int(np.sum(pick[mine, v] != recorded_pick))
    return Replay(sources=np.array(names), methods=np.array(methods),
                  source=src[sel], call=pos[sel], run=run, step=step,
                  wall_ns=wall, cpu_ns=cpu, pick=pick, n_evals=evals, slot=slot,
                  timed=timed_, eval_ns=eval_ns, dispatch_ns=np.float64(dispatch),
                  variant_method=np.array([v[0] for v in var]),
                  variant_path=np.array([v[1] for v in var]),
                  # a user's own method: its path named (methods.eval_path: the search interpreted, the score
                  # compiled or not)
                  variant_eval_path=np.array([eval_path(v[0], v[2]) for v in var]),
                  mismatch=mismatch, checked=checked, reps=reps, clock_ns=np.float64(clock_ns),
                  load_avg=np.array([load_start, os.getloadavg()[0]]), n_cpu=np.int64(os.cpu_count() or 0),
                  n_pool=np.int64(len(src)), max_calls=np.int64(max_calls),
                  max_calls_paper=np.int64(max_calls_paper))


def _kernel_result(call):
    """(pick, n_evals) of a compiled planning call just run (``planner.compiled_call``: its last
    argument's tail is ``plan_run``'s out) as a ``PlanResult``-like record, or None where its status
    is not OK (the planner's fallback then picks, ``planner.plan_one``)."""
    import types

    from opnav.landing.planning import layout as L

    out = call.args[-1][-L.NOUT:]
    if int(out[L.O_STATUS]) != L.OK:
        return None
    return types.SimpleNamespace(index=int(out[L.O_PICK]), n_evals=int(out[L.O_NEVAL]))


def _time_evaluations(ev, clock_ns: float) -> int:
    """Thread CPU (ns) of a call's objective evaluations alone (:func:`evaluation_inputs`' ``ev``),
    inside the kernel (``planning.search.evaluations``, one dispatch a bracket): the repetition
    count doubles from 8 until the bracket is at least :data:`CLOCK_SHARE_INV` times the clock
    and 50 times a dispatch (~1 us: under 2 % of the bracket), as the call's own timing."""
    from opnav.landing.planning.search import evaluations

    q, betas, cand, _, xyz = ev
    thread = time.thread_time_ns
    n_rep = 8
    evaluations(q, betas, xyz, cand, 1)                       # warm, as the timed call
    while True:
        c0 = thread()
        evaluations(q, betas, xyz, cand, n_rep)
        c1 = thread()
        if (c1 - c0 >= max(CLOCK_SHARE_INV * clock_ns, 50_000)) or n_rep >= MAX_REPS:
            return int((c1 - c0) // n_rep)
        n_rep *= 2


#: ``replay(warm_compiled=False)``: a compiled call's first run at least this long (ns, thread CPU) is
#: its time, without a warm call before it. Site-tilt, 40 calls, medians warm / first run (twice each,
#: load ~9): logdet 11.27, 11.30 / 10.64, 10.99 ms; logdet_nav 13.34, 11.14 / 11.83, 12.11;
#: svd_lapack 25.82, 26.12 / 25.62, 26.08 (alike); but mineig 0.27, 0.26 / 0.33, 0.30 ms and svd_w
#: 0.70, 0.49 / 0.76, 0.82 ms (a first run of a sub-millisecond call is 15-25 % slower): 2 ms
COLD_OK_NS = 2_000_000

#: brackets of a compiled call in the claims' replays, the least kept (``replay(best_of=...)``): on
#: the 2-core VM at load 14-16, 20 interior calls x 3 replays read depth vs SVD 28.4 % (sd between
#: replays 0.9) with one bracket and 29.1 % (0.6) with the least of 3 (docs/performance.md)
REPLAY_BEST_OF = 3

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


def save(path, tm: Replay) -> None:
    """Write a replay (the file edge: ``records.save`` of :meth:`Replay.arrays`, ``.npz``, atomically)."""
    _save_arrays(path, tm.arrays())


def _load_one(path) -> Replay:
    return Replay.from_arrays(_load_arrays(path))


def _is_replay(tm: Replay) -> bool:
    """Whether ``tm`` is one of the claims' replays (its ``part`` is ``"replay"``)."""
    return tm.part is not None and str(tm.part) == "replay"


def load(path) -> Replay:
    """A replay saved by :func:`save` (``records.load``), or, given several paths (a Snakemake input
    list), their :func:`merge`: the files whose ``part`` is ``"replay"`` (the claims' replays, in
    the given order) with the one other file (the variants timed once) as ``extra``."""
    if isinstance(path, (str, os.PathLike)):
        return _load_one(path)
    parts = [_load_one(p) for p in path]
    reps = [t for t in parts if _is_replay(t)]
    other = [t for t in parts if not _is_replay(t)]
    if len(other) > 1:
        raise ValueError(f"timing.load: {len(other)} files are not replays of the claims' calls; at most one may be")
    if not reps:
        return other[0]
    return merge(reps, other[0] if other else None)


_ROW_KEYS = Replay.ROW_KEYS
_CELL_KEYS = Replay.CELL_KEYS
_CELL_FILL = {"timed": False, "pick": -2}


def merge(replays: list[Replay], extra: Replay | None = None) -> Replay:
    """One replay of several independent replays of the same calls (separate
    processes, :func:`replay` each) and, optionally, one more replay ``extra`` of other variants
    on the same calls (the millisecond calls and the paper's definition, timed once).

    Rows are (replay, call): replay ``r``'s calls occupy rows ``r n .. (r + 1) n - 1`` (``replay``
    holds ``r`` per row); ``extra``'s variants are timed on replay 0's rows only (untimed
    elsewhere, ``timed`` false). So every consumer of a replay (medians, paired reductions, the
    figures) reads all timed rows unchanged, the replays' variants pooled over their replays; the
    replays apart are ``timing_summary.planning_time_evidence``'s. Per replay: ``replay_clock_ns``,
    ``replay_load_avg`` (start, end), ``replay_dispatch_ns``; ``extra``'s load average is
    ``extra_load_avg``. Pick checks add up. The replays must have the same calls and variants,
    ``extra`` the same calls and none of their variants."""
    if not replays:
        raise ValueError("timing.merge: no replay")
    first = replays[0]
    key = lambda tm: [(str(m), str(p)) for m, p in zip(tm.variant_method, tm.variant_path)]  # noqa: E731
    for tm in replays[1:] + ([extra] if extra is not None else []):
        if not all(np.array_equal(getattr(tm, k), getattr(first, k)) for k in ("source", "call")) \
                or int(tm.n_pool) != int(first.n_pool) or list(tm.sources) != list(first.sources):
            raise ValueError("timing.merge: the replays did not replay the same recorded calls")
    for tm in replays[1:]:
        if key(tm) != key(first):
            raise ValueError("timing.merge: the replays did not time the same variants")
    if extra is not None and set(key(extra)) & set(key(first)):
        raise ValueError("timing.merge: the extra replay times a variant of the replays again")
    parts = list(replays) + ([extra] if extra is not None else [])
    var = [v for tm in parts[:1] + parts[len(replays):] for v in key(tm)]
    nv, nc, nr = len(var), len(first.source), len(replays)
    paper_of = extra if extra is not None else first
    out = {"sources": first.sources, "n_pool": first.n_pool, "max_calls": first.max_calls,
           "max_calls_paper": paper_of.max_calls_paper if paper_of.has("max_calls_paper") else np.int64(0)}
    for k in _ROW_KEYS:
        out[k] = np.concatenate([np.asarray(getattr(tm, k)) for tm in replays])
    out["replay"] = np.repeat(np.arange(nr, dtype=np.int64), nc)
    for k in _CELL_KEYS:
        dtype = bool if k == "timed" else np.int64
        arr = np.full((nc * nr, nv), _CELL_FILL.get(k, -1), dtype)
        for r, tm in enumerate(replays):
            if tm.has(k):
                arr[r * nc:(r + 1) * nc, :len(key(first))] = getattr(tm, k)
        if extra is not None and extra.has(k):
            arr[:nc, len(key(first)):] = getattr(extra, k)
        out[k] = arr
    for k in ("variant_method", "variant_path", "variant_eval_path"):
        out[k] = np.concatenate([np.asarray(getattr(tm, k)) for tm in [first] + ([extra] if extra is not None else [])])
    methods = list(dict.fromkeys(str(m) for tm in parts for m in tm.methods))
    out["methods"] = np.array(methods)
    for k in ("mismatch", "checked"):
        out[k] = np.zeros(len(methods), np.int64)
        for tm in parts:
            for m, x in zip(tm.methods, getattr(tm, k)):
                out[k][methods.index(str(m))] += int(x)
    nan2 = [math.nan] * 2
    out["n_replays"] = np.int64(nr)
    out["replay_clock_ns"] = np.array([float(tm.clock_ns) if tm.has("clock_ns") else math.nan for tm in replays])
    out["clock_ns"] = np.float64(np.nanmax(out["replay_clock_ns"]) if nr else math.nan)
    out["replay_dispatch_ns"] = np.array([float(tm.dispatch_ns) if tm.has("dispatch_ns") else math.nan
                                          for tm in replays])
    out["replay_load_avg"] = np.array([np.asarray(tm.load_avg if tm.has("load_avg") else nan2, float)[:2]
                                       for tm in replays])
    out["load_avg"] = np.array([np.nanmin(out["replay_load_avg"][:, 0]), np.nanmax(out["replay_load_avg"][:, 1])])
    out["n_cpu"] = np.int64(first.n_cpu if first.has("n_cpu") else 0)
    if extra is not None:
        out["extra_load_avg"] = np.asarray(extra.load_avg if extra.has("load_avg") else nan2, float)[:2]
        out["extra_clock_ns"] = np.float64(extra.clock_ns if extra.has("clock_ns") else math.nan)
    # the clock's cost of the bracket each row was timed in (clock_share): a replay's own
    out["row_clock_ns"] = np.repeat(out["replay_clock_ns"], nc)
    return Replay(**out)


#: what a replay reads of a Monte-Carlo file: the recorded inputs, the pick (the check) and the run
CALL_INPUT_KEYS = RECORD_KEYS + ("plan_index", "plan_run")


def load_calls(path) -> MonteCarlo:
    """The recorded planning calls of a Monte-Carlo file (its record holding :data:`CALL_INPUT_KEYS`
    only; a compressed ``.npz`` is read per array, so the runs' time series are not decompressed)."""
    import zipfile

    from opnav.core.snakeio import corrupt_intermediate

    try:
        with np.load(path, allow_pickle=False) as z:
            return MonteCarlo(**{k: z[k] for k in CALL_INPUT_KEYS if k in z.files})
    except FileNotFoundError:
        raise
    except (zipfile.BadZipFile, EOFError, ValueError, OSError, KeyError) as exc:
        raise corrupt_intermediate(path, exc) from exc


@dataclass(frozen=True)
class ReplaySpec:
    """What :func:`run_spec` replays: the scenario (``setup``, the landing setup it is built from,
    or ``scenario_pickle``, the file a parent of several replay processes built it into once,
    :func:`replays_in_processes`), the recorded calls (``mc``: ``(method, gathered Monte-Carlo
    file)`` pairs in the pool's order), the methods timed and :func:`replay`'s variants and
    limits. JSON only for a replay in another process (:meth:`as_json`, :meth:`from_json`: the
    scenario then travels pickled, never as config)."""

    mc: tuple
    methods: tuple
    max_calls: int
    alt: bool | tuple = True
    main: tuple | None = None
    max_calls_paper: int = 0
    decompose: bool = False
    best_of: int = 1
    warm_compiled: bool = True
    setup: Setup | None = None
    scenario_pickle: str | None = None

    def scenario(self):
        """The spec's scenario: unpickled from :attr:`scenario_pickle`, else built from :attr:`setup`."""
        if self.scenario_pickle:
            import pickle

            with open(self.scenario_pickle, "rb") as f:
                return pickle.load(f)
        from opnav.landing.descent import build_scenario

        return build_scenario(self.setup)

    def as_json(self) -> str:
        """The spec for a replay process (its scenario pickled: no setup)."""
        import json

        if not self.scenario_pickle:
            raise ValueError("ReplaySpec.as_json: a replay process reads its scenario from scenario_pickle")
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "setup"}
        return json.dumps(d)

    @classmethod
    def from_json(cls, text: str) -> "ReplaySpec":
        import json

        tuples = {"mc": lambda v: tuple(tuple(x) for x in v), "methods": tuple,
                  "alt": lambda v: v if isinstance(v, bool) else tuple(v),
                  "main": lambda v: None if v is None else tuple(v)}
        return cls(**{k: tuples.get(k, lambda v: v)(v) for k, v in json.loads(text).items()})


def run_spec(spec: ReplaySpec) -> Replay:
    """:func:`replay` of a spec (:func:`replay_spec`): its scenario, the recorded calls read from
    its ``mc`` files (the pool's order; :func:`load_calls`), the variants and limits as given."""
    recorded = {m: load_calls(path) for m, path in spec.mc}
    alt = spec.alt
    return replay(spec.scenario(), recorded, list(spec.methods), int(spec.max_calls),
                  alt=alt if isinstance(alt, bool) else list(alt), max_calls_paper=int(spec.max_calls_paper),
                  main=None if spec.main is None else list(spec.main),
                  decompose=bool(spec.decompose), best_of=int(spec.best_of),
                  warm_compiled=bool(spec.warm_compiled))


def replay_spec(setup: Setup, mc, methods, max_calls: int, *, alt=True, main=None,
                max_calls_paper: int = 0, decompose: bool = False, best_of: int = 1,
                warm_compiled: bool = True) -> ReplaySpec:
    """What :func:`run_spec` replays (``setup``: the scenario's landing setup; ``mc``: method ->
    gathered Monte-Carlo file)."""
    return ReplaySpec(mc=tuple((str(m), str(p)) for m, p in dict(mc).items()), methods=tuple(methods),
                      max_calls=int(max_calls), alt=alt if isinstance(alt, bool) else tuple(alt),
                      main=None if main is None else tuple(main), max_calls_paper=int(max_calls_paper),
                      decompose=bool(decompose), best_of=int(best_of), warm_compiled=bool(warm_compiled),
                      setup=setup)


def replays_in_processes(spec: ReplaySpec, n: int, workdir, log=None) -> list[Replay]:
    """``n`` independent replays of ``spec``, each in a fresh Python process run one after the
    other (its own address-space layout, hash seed and caches: pyperf's reason for spawning
    worker processes, CONVENTIONS.md; a fork would share this process's layout), each process
    writing its replay to ``workdir``; returns them in order. ``log``: a logger for each
    process's output (its own ``job resources`` line: kernels loaded and compiled)."""
    import subprocess
    import sys
    from pathlib import Path

    import opnav

    if int(n) < 1:
        raise ValueError(f"landing.timing.n_replays must be >= 1, got {n}")
    work = Path(workdir)
    work.mkdir(parents=True, exist_ok=True)
    if not spec.scenario_pickle:          # built once here, read by every replay process
        import pickle

        scn = spec.scenario()
        spec = dataclasses.replace(spec, scenario_pickle=str(work / "scenario.pkl"))
        with open(spec.scenario_pickle, "wb") as f:
            pickle.dump(scn, f, protocol=pickle.HIGHEST_PROTOCOL)
    spec_path = work / "spec.json"
    spec_path.write_text(spec.as_json())
    env = dict(os.environ)
    root = str(Path(opnav.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH", "")) if p)
    out = []
    for r in range(int(n)):
        target = work / f"replay{r}.npz"
        proc = subprocess.run([sys.executable, "-c", "import sys; from opnav.landing.timing import _replay_process; "
                               "_replay_process(sys.argv[1], sys.argv[2])", str(spec_path), str(target)],
                              env=env, capture_output=True, text=True)
        if log is not None:
            for line in (proc.stdout + proc.stderr).splitlines():
                log.info("replay %d: %s", r, line)
        if proc.returncode:
            raise RuntimeError(f"timing replay {r} failed (exit {proc.returncode}): "
                               + (proc.stderr.strip().splitlines() or ["no output"])[-1])
        out.append(_load_one(target).replace(part=np.array("replay")))   # load() merges these as replays
    return out


def _replay_process(spec_path: str, target: str) -> None:
    """One replay in this process (:func:`replays_in_processes`' child): :func:`run_spec` of the
    JSON spec, saved to ``target``; prints its resource line."""
    from opnav.core.snakeio import resource_line

    save(target, run_spec(ReplaySpec.from_json(open(spec_path).read())))
    print(resource_line(), flush=True)


def replay_own(scn, data, method: str, max_calls: int = 0) -> Replay:
    """Replay a Monte Carlo's (``records.MonteCarlo``) or one descent's (``records.Descent``,
    its calls counted as run 0) own calls through its own method, configured evaluation path
    only (parameter studies, the CLI: no other methods to interleave with)."""
    d = data if isinstance(data, MonteCarlo) else MonteCarlo.of_descent(data, 0)
    return replay(scn, {method: d}, [method], max_calls, alt=False)


def from_times(wall_ns: Mapping, cpu_ns: Mapping, run, n_evals: int = 0) -> Replay:
    """A :func:`replay`-shaped record from given per-call times (ns) per
    method, all on the configured path, calls of one source with run indices
    ``run`` (for tests and times measured elsewhere)."""
    methods = list(wall_ns)
    n, k = len(run), len(methods)
    return Replay(sources=np.array(methods[:1]), methods=np.array(methods),
                  source=np.zeros(n, np.int64), call=np.arange(n, dtype=np.int64),
                  run=np.asarray(run, np.int64), step=np.zeros(n, np.int64),
                  wall_ns=np.column_stack([np.asarray(wall_ns[m]) for m in methods]).astype(np.int64),
                  cpu_ns=np.column_stack([np.asarray(cpu_ns[m]) for m in methods]).astype(np.int64),
                  pick=np.full((n, k), -2, np.int64), n_evals=np.full((n, k), int(n_evals), np.int64),
                  slot=np.zeros((n, k), np.int64), timed=np.ones((n, k), bool),
                  variant_method=np.array(methods),
                  variant_path=np.array(["main"] * k), variant_eval_path=np.array(["main"] * k),
                  mismatch=np.zeros(k, np.int64), checked=np.zeros(k, np.int64),
                  n_pool=np.int64(n), max_calls=np.int64(0), max_calls_paper=np.int64(0))


@dataclass(frozen=True, eq=False)
class CallOverhead:
    """:func:`call_overhead`'s measurement, per replayed call (ns): the whole compiled call
    (``call_ns``), its objective evaluations alone (``evals_ns``), their count (``n_evals``),
    whether the optimum was on an edge (``edge``), ``planner.plan`` once cold (``cold_ns``) and hot
    (``wrapped_ns``), and ``overhead_ratio = (call - evals) / evals``."""

    call_ns: np.ndarray
    evals_ns: np.ndarray
    n_evals: np.ndarray
    edge: np.ndarray
    cold_ns: np.ndarray
    wrapped_ns: np.ndarray
    overhead_ratio: np.ndarray


def call_overhead(scn, recorded: dict, method: str = "depth", max_calls: int = 0,
                  repeats: int = 3, reps: int = 50) -> CallOverhead:
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
    sel = select_calls(len(d.plan_step), max_calls)
    cam, field_, tr = scn.camera, scn.field, scn.truth
    cfg = dataclasses.replace(scn.planner, eval_path="compiled")
    thread = time.thread_time_ns
    rows = []
    gc_was = gc.isenabled()
    gc.disable()
    try:
        for i in sel:
            k = int(d.plan_step[i])
            det = np.flatnonzero(cam.in_view((field_.xyz - tr.r[k]) @ tr.R_LtoB[k].T, cfg.margin_px))
            st = pl.PlanState(d.plan_r[i], d.plan_v[i], d.plan_a[i], d.plan_R[i], d.plan_P[i])
            ex = int(d.plan_exclude[i])
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
    return CallOverhead(call_ns=call_ns, evals_ns=evals_ns, n_evals=n_ev.astype(np.int64),
                        edge=edge.astype(bool), cold_ns=cold, wrapped_ns=wrapped, overhead_ratio=ratio)
