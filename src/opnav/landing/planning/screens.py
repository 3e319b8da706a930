"""The planner's screens and its tie rule: which candidates may be scored (in view, the known
landmark usable), which detected landmark lies nearest a ground point (a bucket grid over the
field), and which of several scores wins.

The tie rule (:func:`best_index`): candidates whose score (minimised) lies within
:data:`TIE_RTOL` times |best| of the best are tied, and the lowest position wins. The compiled
and reference paths agree to round-off (~1e-12 relative: the closed form against LAPACK's
smallest structural singular value), far inside it; mineig's plateau (spread ~2e-15,
``opnav.landing.metrics``) is one tie. Units: m.
"""
from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel
from opnav.landing.planning.layout import (G_H, G_NX, G_NY, G_X0, G_Y0, Q_BS_ON, Q_BSL, Q_C, Q_KNOWN_OK,
                                           Q_MINRANGE)

#: the tie rule's relative tolerance (module docstring)
TIE_RTOL = 1e-9


@kernel
def in_view(d0, d1, d2, rho, q) -> bool:
    """A landmark at offset d = p - C (m), |d| = rho, beyond min_range and in front
    of the camera (d . boresight > 0, when the check is on)."""
    if not rho > q[Q_MINRANGE]:
        return False
    return q[Q_BS_ON] == 0.0 or d0 * q[Q_BSL] + d1 * q[Q_BSL + 1] + d2 * q[Q_BSL + 2] > 0.0


@kernel
def candidate_ok(d0, d1, d2, rho, q) -> bool:
    """The candidate validity rule: the candidate in view and the known landmark usable."""
    return q[Q_KNOWN_OK] != 0.0 and in_view(d0, d1, d2, rho, q)


@kernel
def valid_points(q, pts):
    """:func:`candidate_ok` of each row of ``pts`` (n, 3) (m)."""
    ok = np.empty(pts.shape[0], np.bool_)
    for j in range(pts.shape[0]):
        d0, d1, d2 = pts[j, 0] - q[Q_C], pts[j, 1] - q[Q_C + 1], pts[j, 2] - q[Q_C + 2]
        ok[j] = candidate_ok(d0, d1, d2, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), q)
    return ok


@kernel
def best_index(scores) -> int:
    """The tie rule: the first position whose score (minimised) lies within
    :data:`TIE_RTOL` relative of the smallest finite score; -1 if none is finite."""
    best = math.inf
    for s in scores:
        if s < best:
            best = s
    if not math.isfinite(best):
        return -1
    lim = _tie_limit(best)
    for j in range(scores.size):
        if scores[j] <= lim:
            return j
    return -1


@kernel
def _tie_limit(best) -> float:
    """The tie rule's bound: scores <= best + TIE_RTOL |best| are tied with ``best``."""
    return best + TIE_RTOL * abs(best) if math.isfinite(best) else best


@kernel
def _nearest_of(x, y, xyz, det, exclude) -> int:
    best, bd = -1, math.inf
    for i in det:
        if i == exclude:
            continue
        dx, dy = xyz[i, 0] - x, xyz[i, 1] - y
        d2 = dx * dx + dy * dy
        if d2 < bd or (d2 == bd and i < best):
            best, bd = i, d2
    return best


@kernel
def nearest(x, y, xyz, det, exclude, grid, cells) -> int:
    """The landmark of ``det`` (sorted field indices) nearest to (x, y) (m) by
    dx^2 + dy^2, less ``exclude``, exact ties to the smaller index; -1 if none.
    Rings of grid buckets (:func:`field_grid`) outward until no unsearched bucket
    can hold a nearer one (the bound shrunk by 1e-9 buckets); a query whose
    rings hold more than 64 undetected landmarks scores ``det`` directly."""
    if det.size <= 32:
        return _nearest_of(x, y, xyz, det, exclude)
    x0, y0, h = grid[G_X0], grid[G_Y0], grid[G_H]
    nx, ny = int(grid[G_NX]), int(grid[G_NY])
    cx = min(max(int((x - x0) // h), 0), nx - 1)
    cy = min(max(int((y - y0) // h), 0), ny - 1)
    nc = nx * ny
    best, bd, rejected, r = -1, math.inf, 0, 0
    while True:
        for xx in range(max(cx - r, 0), min(cx + r, nx - 1) + 1):
            for yy in range(max(cy - r, 0), min(cy + r, ny - 1) + 1):
                if max(abs(xx - cx), abs(yy - cy)) != r:
                    continue
                c = xx * ny + yy
                for t in range(cells[c], cells[c + 1]):
                    i = cells[nc + 1 + t]
                    dx, dy = xyz[i, 0] - x, xyz[i, 1] - y
                    d2 = dx * dx + dy * dy
                    if d2 < bd or (d2 == bd and i < best):
                        k = np.searchsorted(det, i)              # detected?
                        if i != exclude and k < det.size and det[k] == i:
                            best, bd = i, d2
                        else:
                            rejected += 1
        lb = math.inf                                  # distance to the unsearched buckets
        if cx + r < nx - 1:
            lb = x0 + (cx + r + 1) * h - x
        if cx - r > 0:
            lb = min(lb, x - (x0 + (cx - r) * h))
        if cy + r < ny - 1:
            lb = min(lb, y0 + (cy + r + 1) * h - y)
        if cy - r > 0:
            lb = min(lb, y - (y0 + (cy - r) * h))
        if lb == math.inf:
            return best
        lb -= 1e-9 * h
        if best >= 0 and lb > 0 and bd < lb * lb:
            return best
        if rejected > 64:
            return _nearest_of(x, y, xyz, det, exclude)
        r += 1


def field_grid(xyz: np.ndarray, per_cell: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The bucket grid of :func:`nearest` over the (x, y) of ``xyz`` (n, 3), m:
    ``grid`` = [x0, y0, h, nx, ny] and ``cells`` = [start (nx ny + 1), items]
    (int64, the field indices of bucket c at items[start[c]:start[c+1]], increasing)."""
    xy = np.asarray(xyz, float)[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float(max(hi - lo))
    m = max(1, int(math.ceil(math.sqrt(len(xy) / per_cell))))
    h = span / m if span > 0 else 1.0
    nx, ny = int((hi[0] - lo[0]) // h) + 1, int((hi[1] - lo[1]) // h) + 1
    c = (np.minimum(((xy[:, 0] - lo[0]) // h).astype(np.int64), nx - 1) * ny
         + np.minimum(((xy[:, 1] - lo[1]) // h).astype(np.int64), ny - 1))
    order = np.argsort(c, kind="stable")
    start = np.searchsorted(c[order], np.arange(nx * ny + 1))
    return (np.array([lo[0], lo[1], h, nx, ny], float),
            np.concatenate([start, order]).astype(np.int64))
