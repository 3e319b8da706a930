"""A user's own numba-compiled metric on the compiled path: the planning call's kernels compiled
again with the user's score as the objective (issue 58; ``opnav.landing.methods``).

The call is :func:`~opnav.landing.planning.search.plan_core`'s own source (the visible interval,
the golden-section search, the edge rule, the nearest landmark), compiled by numba with the
names it calls for the objective (``golden_section``'s ``objective``, ``edge_pick``'s
``score_points``) replaced by kernels that build the user's record
(``opnav.landing.methods.Candidate``) from the call's constants and call the user's function:
the same steps as the interpreted path (``search.interpreted``), run as a lander's computer
would. :func:`build` makes them once per user function and process (numba compiles them
without the on-disk cache, a few CPU-seconds a process); :func:`plan_run` is the call for one
run, as ``search.plan_run`` is for a built-in kind.

The record's fields live in the call's ``q`` after its fixed slots (``layout.Q_TAB``: the
per-image tables of the planned-information kinds, which a user's metric does not use):
:data:`X_R` ... (:data:`NX` slots). A NaN score is counted in ``q[X_NAN]`` (the search goes on
with +inf there); the caller raises (``planner.plan_one``), as the interpreted path does.
"""
from __future__ import annotations

import functools
import math
import types

import numpy as np

from opnav.landing.planning import layout as L
from opnav.landing.planning.candidate import Candidate

# the record's slots of q (from layout.Q_TAB): estimate r, v, a (3 each), R_LtoB (9), P (144, the
# symmetric part), the site (3), R_BtoC (9), sigma_b, noise scale, t_s, n_obs; the NaN count
X_R = L.Q_TAB
X_V, X_A, X_RLB, X_P = X_R + 3, X_R + 6, X_R + 9, X_R + 18
X_SITE, X_RBC = X_P + 144, X_P + 147
X_SIG, X_NS, X_TS, X_NOBS, X_NAN = X_RBC + 9, X_RBC + 10, X_RBC + 11, X_RBC + 12, X_RBC + 13
NX = X_NAN + 1 - X_R


def work_size() -> int:
    """Length of :func:`plan_run`'s ``work`` (q with the record's slots, then out)."""
    return L.Q_TAB + NX + L.NOUT


def _njit(fn, **names):
    """The kernel ``fn``'s source with the names ``names`` replaced, compiled (no on-disk cache:
    its globals are this process's user function)."""
    import numba

    py = fn.py_func
    g = {**py.__globals__, **names}
    return numba.njit(cache=False, fastmath=False)(types.FunctionType(py.__code__, g, py.__name__, py.__defaults__,
                                                                    py.__closure__))


@functools.lru_cache(maxsize=16)
def build(user_fn):
    """The compiled call of ``user_fn`` (a numba dispatcher taking a ``methods.Candidate``):
    :func:`plan_run`'s kernel. Compiles on first call; raises what numba raises if the user's
    function does not compile inside it."""
    import numba

    from opnav.landing.planning import geometry, screens, search

    for k in (search.plan_core, search.golden_section, search.edge_pick, geometry.ground_point,
              geometry.plane, geometry.visible_interval, screens.best_index, screens.nearest):
        if not isinstance(k, numba.core.registry.CPUDispatcher):
            k.dispatcher()          # the proxies typed as their dispatchers (core.compiled)
    ground_point, plane = geometry.ground_point, geometry.plane
    jit = numba.njit(cache=False, fastmath=False)

    @jit
    def score_at(q, x, y, z):
        p = np.empty(3)
        p[0], p[1], p[2] = x, y, z
        rec = Candidate(p, q[X_R:X_R + 3].copy(), q[X_V:X_V + 3].copy(), q[X_A:X_A + 3].copy(),
                        q[X_RLB:X_RLB + 9].copy().reshape((3, 3)), q[X_P:X_P + 144].copy().reshape((12, 12)),
                        q[X_SITE:X_SITE + 3].copy(), q[X_RBC:X_RBC + 9].copy().reshape((3, 3)),
                        q[X_SIG], q[X_NS], q[X_TS], int(q[X_NOBS]))
        s = float(user_fn(rec))
        if s != s or s == -math.inf:
            q[X_NAN] += 1.0
            return math.inf
        return s

    @jit
    def objective(beta, q):
        hit, x, y, z = ground_point(beta, q)
        return score_at(q, x, y, z) if hit else math.inf

    @jit
    def score_points(q, xyz, cand):
        out = np.empty(cand.size)
        for j in range(cand.size):
            i = cand[j]
            out[j] = score_at(q, xyz[i, 0], xyz[i, 1], xyz[i, 2])
        return out

    golden = _njit(search.golden_section, objective=objective)
    edge = _njit(search.edge_pick, score_points=score_points)
    core = _njit(search.plan_core, golden_section=golden, edge_pick=edge)

    @jit
    def run(est, c, xyz, det, exclude, cells, work):
        r, v, a, R_LtoB, P = est
        q, out = work[:work.size - L.NOUT], work[work.size - L.NOUT:]
        q[X_NAN] = 0.0
        st = plane(r, v, q)
        if st != L.OK:
            out[L.O_NEVAL], out[L.O_STATUS] = 0, st
            return
        for i in range(3):
            q[X_R + i], q[X_V + i], q[X_A + i] = r[i], v[i], a[i]
            q[X_SITE + i] = c[L.C_PKNOWN + i]
        for i in range(3):
            for j in range(3):
                q[X_RLB + 3 * i + j] = R_LtoB[i, j]
                q[X_RBC + 3 * i + j] = c[L.C_RBC + 3 * i + j]
        for i in range(12):
            for j in range(12):
                q[X_P + 12 * i + j] = 0.5 * (P[i, j] + P[j, i])
        q[X_SIG], q[X_NS], q[X_TS], q[X_NOBS] = c[L.C_SIGMA], c[L.C_NOISE], c[L.C_TS], c[L.C_NOBS]
        M = np.zeros((3, 3))
        for i in range(3):
            for j in range(3):
                for k in range(3):
                    M[i, j] += c[L.C_RBC + 3 * i + k] * R_LtoB[k, j]
        core(q, M, c[L.C_KFOV], c[L.C_TOL], xyz, det, exclude, c[L.C_GRID:L.C_GRID + L.NG], cells, out)

    return run


def plan_run(user_fn, est, c, xyz, det, exclude, cells, work) -> None:
    """The compiled planning call of ``user_fn`` for one run (``search.plan_run``'s arguments but
    the kind; ``work`` of :func:`work_size`): ``work``'s out as ``search.plan_run`` fills it, the
    NaN scores counted in ``q[X_NAN]``."""
    build(user_fn)(est, c, xyz, det, exclude, cells, work)
