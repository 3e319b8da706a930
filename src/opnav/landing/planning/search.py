"""Paper B's planning call, compiled (SPEC B.3, sec. 2.2, eq. 26): the objective of a kind at
a ground point and along the plane, the golden-section search, the edge rule, the call
(:func:`plan_core`) and its entry point for one run (:func:`plan_run`). ``opnav.landing.planner``
says the steps; :func:`interpreted` runs the same source with a Python objective (the paper
path: ``reference.paper_objective``).

Objectives are minimised: the depth error (m), or minus a metric (larger is better for every
metric). ``+inf`` where the line of sight misses the ground, at beta = 0 (no parallax) and for
invalid candidates; never NaN.
"""
from __future__ import annotations

import math
import types

import numpy as np

from opnav.core.compiled import kernel
from opnav.landing.planning.depth import baseline, depth_error, error_radius
from opnav.landing.planning.geometry import ground_point, plane, plane_depth, visible_interval
from opnav.landing.planning.hmetrics import h_lapack, h_metric, metric_constants
from opnav.landing.planning.information import nav_constants, planned
from opnav.landing.planning.layout import (C_BS, C_GRID, C_KFOV, C_MINRANGE, C_NSIGMA, C_PKNOWN, C_RBC,
                                           C_TOL, C_TS, DEPTH, LOGDET, LOGDET_NAV, NG, NO_INTERVAL, NOUT,
                                           O_BETA, O_EDGE, O_F, O_NEVAL, O_PICK, O_STATUS, O_XYZ, OK, Q_B,
                                           Q_C, Q_KIND, Q_NK, Q_R, Q_RE, Q_U, Q_VHAT, Q_XK, SVD_LAPACK,
                                           ZERO_BASELINE)
from opnav.landing.planning.screens import best_index, candidate_ok, in_view, nearest

#: the golden ratio's inverse, the bracket's shrink per evaluation
INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


@kernel
def score_point(p0, p1, p2, q) -> float:
    """The objective (minimised) of kind q[Q_KIND] at the ground point p (m): the depth
    error (eq. 23-25 at the landmark's range) or minus an H baseline or B-X1
    metric (+inf where the candidate is invalid)."""
    d0, d1, d2 = p0 - q[Q_C], p1 - q[Q_C + 1], p2 - q[Q_C + 2]
    rho = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    kind = int(q[Q_KIND])
    if kind == DEPTH:
        if not (p2 < q[Q_C + 2]) or rho <= 0.0:
            return math.inf
        v0, v1, v2 = q[Q_VHAT], q[Q_VHAT + 1], q[Q_VHAT + 2]
        c0, c1, c2 = d1 * v2 - d2 * v1, d2 * v0 - d0 * v2, d0 * v1 - d1 * v0  # d x v_hat
        return depth_error(rho, (d0 * v0 + d1 * v1 + d2 * v2) / rho,
                           math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) / rho, q[Q_B], q[Q_RE])
    if LOGDET <= kind <= LOGDET_NAV:
        return planned(kind, d0, d1, d2, rho, q) if in_view(d0, d1, d2, rho, q) else math.inf
    if not candidate_ok(d0, d1, d2, rho, q):
        return math.inf
    if kind == SVD_LAPACK:
        return -h_lapack(q[Q_C:Q_C + 3], q[Q_R:Q_R + 9].reshape((3, 3)), q[Q_NK:Q_NK + 3], d0, d1, d2)
    y = 1.0 / rho
    w0, w1, w2 = d0 * y, d1 * y, d2 * y
    u0, u1, u2 = q[Q_U], q[Q_U + 1], q[Q_U + 2]
    c0, c1, c2 = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
    return -h_metric(kind, q[Q_XK], y, u0 * w0 + u1 * w1 + u2 * w2, c0 * c0 + c1 * c1 + c2 * c2)


@kernel
def objective(beta, q) -> float:
    """The objective at signed beta: the depth error (eq. 23-25 at the law-of-sines
    range), or :func:`score_point` at the ground point (eq. 26)."""
    if int(q[Q_KIND]) == DEPTH:
        d = plane_depth(beta, q)
        return depth_error(d, math.cos(beta), abs(math.sin(beta)), q[Q_B], q[Q_RE]) if d < math.inf else d
    hit, x, y, z = ground_point(beta, q)
    return score_point(x, y, z, q) if hit else math.inf


@kernel
def score_points(q, xyz, cand):
    """:func:`score_point` of landmarks ``xyz[cand]`` (minimised)."""
    out = np.empty(cand.size)
    for j in range(cand.size):
        i = cand[j]
        out[j] = score_point(xyz[i, 0], xyz[i, 1], xyz[i, 2], q)
    return out


@kernel
def evaluations(q, betas, xyz, cand, reps) -> float:
    """The objective at ``betas`` and :func:`score_points` of ``cand``, ``reps``
    times (the evaluations of a planning call, timed alone by ``timing.call_overhead``)."""
    s = 0.0
    for _ in range(reps):
        for b in betas:
            s += objective(b, q)
        if cand.size:
            s += score_points(q, xyz, cand).sum()
    return s


@kernel
def golden_section(q, a, b, tol):
    """Minimise ``objective(x, q)`` on [a, b] by golden-section search: the bracket shrinks
    by 1/phi per evaluation until shorter than ``tol``; returns (x, f(x), n_evals),
    x the best evaluated point (+inf values allowed)."""
    c = b - INVPHI * (b - a)
    d = a + INVPHI * (b - a)
    fc, fd = objective(c, q), objective(d, q)
    n = 2
    while (b - a) > tol:
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - INVPHI * (b - a)
            fc = objective(c, q)
        else:
            a, c, fc = c, d, fd
            d = a + INVPHI * (b - a)
            fd = objective(d, q)
        n += 1
    return (c, fc, n) if fc <= fd else (d, fd, n)


@kernel
def edge_pick(q, xyz, det, exclude):
    """The edge rule: (pick, landmarks scored): every detected landmark less
    ``exclude`` scored (:func:`score_points`), the tie rule picks (-1: none finite)."""
    cand = det[det != exclude]
    j = best_index(score_points(q, xyz, cand))
    return (cand[j] if j >= 0 else -1), cand.size


@kernel
def plan_core(q, M, kfov, tol, xyz, det, exclude, grid, cells, out) -> None:
    """One planning call in the plane ``q`` (status q-independent: the caller checked the
    plane): visible sub-intervals, a golden-section search (:func:`golden_section`) on each
    (the first wins exact ties), the optimum's ground point (eq. 26); edge rule: an optimum
    within ``tol`` of an end of its sub-interval lies outside the image, so every detected
    landmark is scored and the tie rule picks (:func:`edge_pick`); else, or if none scores
    finite, the detected landmark nearest to the ground point (``screens.nearest``).
    ``out`` (``layout.O_PICK`` ...) = [pick, beta, f, n_evals, edge, x, y, z, status]; no
    interval: status NO_INTERVAL, the rest left to the caller's fallback."""
    n, lo0, hi0, lo1, hi1 = visible_interval(q, M, kfov)
    out[O_STATUS] = OK if n else NO_INTERVAL
    if n == 0:
        out[O_NEVAL] = 0
        return
    bx, bf, ba, bb, ne = math.nan, math.inf, 0.0, 0.0, 0
    for s in range(n):
        a, b = (lo0, hi0) if s == 0 else (lo1, hi1)
        x, fx, k = golden_section(q, a, b, tol)
        ne += k
        if fx < bf or math.isnan(bx):
            bx, bf, ba, bb = x, fx, a, b
    hit, gx, gy, gz = ground_point(bx, q)
    edge = min(bx - ba, bb - bx) <= tol
    pick, m = edge_pick(q, xyz, det, exclude) if edge else (-1, 0)
    ne += m
    if pick < 0:
        pick = nearest(gx, gy, xyz, det, exclude, grid, cells)
    out[O_PICK], out[O_BETA], out[O_F], out[O_NEVAL] = pick, bx, bf, ne
    out[O_EDGE] = 1.0 if edge else 0.0
    out[O_XYZ], out[O_XYZ + 1], out[O_XYZ + 2] = gx, gy, gz


@kernel
def plan_run(kind, est, c, xyz, det, exclude, cells, work) -> None:
    """:func:`plan_core` of a compiled objective ``kind`` (``layout.KINDS``) for one run from
    the estimate ``est`` (``layout.Estimate``: r, v, a, R_LtoB, the prior P 12 x 12) with the
    per-field constants ``c`` (``layout.NC`` slots, ``layout.C_TS`` ...: the search's, the
    camera's, the known landmark, the landmark grid of ``xyz``'s buckets ``cells``
    (``screens.field_grid``), sigma_b (rad: the B-X1 kinds' bearing noise; the filter's is its
    noise scale times it) and the planned-information kinds' filter model
    (``information.nav_constants``)); ``work`` (``layout.work_size`` of obs_per_landmark)
    receives q and out (its last ``layout.NOUT`` slots; status last, 0 ok)."""
    r, v, a, R_LtoB, P = est
    q, out = work[:work.size - NOUT], work[work.size - NOUT:]
    st = plane(r, v, q)
    q[Q_KIND] = kind
    if st == OK and kind == DEPTH:
        q[Q_B], q[Q_RE] = baseline(v, a, c[C_TS]), error_radius(P[3:6, 3:6], c[C_TS], c[C_NSIGMA])
        if not q[Q_B] > 0:
            st = ZERO_BASELINE
    elif st == OK:
        metric_constants(r, R_LtoB, c[C_BS:C_BS + 3], 1.0, c[C_PKNOWN:C_PKNOWN + 3], c[C_MINRANGE], q)
        if LOGDET <= kind <= LOGDET_NAV:
            nav_constants(est, c, q)
        elif kind == SVD_LAPACK:                      # the attitude and site of the H it builds
            for i in range(9):
                q[Q_R + i] = R_LtoB[i // 3, i % 3]
            for i in range(3):
                q[Q_NK + i] = c[C_PKNOWN + i]
    if st != OK:
        out[O_NEVAL], out[O_STATUS] = 0, st
        return
    M = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            for k in range(3):
                M[i, j] += c[C_RBC + 3 * i + k] * R_LtoB[k, j]
    plan_core(q, M, c[C_KFOV], c[C_TOL], xyz, det, exclude, c[C_GRID:C_GRID + NG], cells, out)


def interpreted(fn, **names):
    """The kernel ``fn``'s Python source run by the interpreter, with the module
    names ``names`` (kernels it calls) replaced: the same steps with a Python
    objective (the planner's paper path: ``reference.paper_objective``)."""
    py = fn.py_func
    return types.FunctionType(py.__code__, {**py.__globals__, **names}, py.__name__, py.__defaults__,
                              py.__closure__)
