"""Landmark field on flat ground and nearest-landmark queries (SPEC B.2).

Landmarks are drawn uniformly on the plane z = 0 of {L} over the square
``[-half_width, +half_width]^2`` (m), plus optionally a part around the site
whose density grows as the inverse square of the distance to it
(:func:`near_site_xy`, config ``landing.landmarks.near_site``), from their own
seed (the same field for every Monte-Carlo run and every method). Two spatial indexes on (x, y), both
built once per field:

* a 2-D ``scipy.spatial.cKDTree`` (``tree``): the batched planner's query of
  many ideal points at once;
* a uniform grid of buckets (:class:`GridIndex`, ``grid``): the per-call
  planner's query of one point among the image's detected landmarks, in
  plain Python floats. For one point it costs a few microseconds where a
  ``cKDTree.query`` costs about 15 us of call overhead (measured,
  benchmarks/bench_planning.py), and it breaks exact distance ties by the
  smaller landmark index (tests/test_landing_landmarks.py checks it against
  a brute-force search).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

__all__ = ["LandmarkField", "make_field", "near_site_xy", "GridIndex", "nearest_brute_force"]


class GridIndex:
    """Uniform square buckets over points (x, y) (m) for the nearest point to one
    query, optionally among a subset (``members``) and less a few excluded.

    Nearest means the smallest squared horizontal distance ``dx*dx + dy*dy``
    (float64), exact ties broken by the smaller index: the same total order as
    :func:`nearest_brute_force`. About ``per_cell`` points per bucket; each
    bucket also holds the points of its 3 x 3 neighbourhood, so the usual
    query is one loop over ~9 ``per_cell`` points and one membership test
    (``per_cell`` 1: 2.8 us per planning query of the interior scenario, 2:
    3.2 us, 0.6: 3.6 us, measured; building it for 20000 points: 0.13 s).
    Otherwise rings of buckets are searched outward until no unsearched bucket
    can hold a nearer point (the bound is shrunk by ``1e-9`` bucket widths, so
    rounding in the bucket assignment can only widen the search).
    """

    #: non-member points tried in the ring search before it scores the members
    #: directly (a query point far from every member: the image's detected
    #: landmarks lie elsewhere)
    MAX_REJECTED = 64
    #: member lists this short are scored one by one (no buckets)
    FEW = 32

    def __init__(self, xy: np.ndarray, per_cell: float = 1.0):
        xy = np.asarray(xy, float).reshape(-1, 2)
        if not len(xy) or not np.isfinite(xy).all():
            raise ValueError("GridIndex: need at least one point, all finite")
        n = len(xy)
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        span = float(max(hi[0] - lo[0], hi[1] - lo[1]))
        m = max(1, int(math.ceil(math.sqrt(n / per_cell))))
        h = span / m if span > 0 else 1.0
        nx = int((hi[0] - lo[0]) // h) + 1
        ny = int((hi[1] - lo[1]) // h) + 1
        cx = np.minimum(((xy[:, 0] - lo[0]) // h).astype(np.int64), nx - 1)
        cy = np.minimum(((xy[:, 1] - lo[1]) // h).astype(np.int64), ny - 1)
        cells: list[list] = [[] for _ in range(nx * ny)]
        for i, (c, x, y) in enumerate(zip((cx * ny + cy).tolist(), xy[:, 0].tolist(),
                                          xy[:, 1].tolist())):
            cells[c].append((i, x, y))
        self.cells = [tuple(c) for c in cells]
        x0, y0, inf, pad = float(lo[0]), float(lo[1]), math.inf, 1e-9 * h
        blocks = []
        for a in range(nx):
            for b in range(ny):
                blk = []
                for aa in range(max(a - 1, 0), min(a + 2, nx)):
                    for bb in range(max(b - 1, 0), min(b + 2, ny)):
                        blk.extend(self.cells[aa * ny + bb])
                # the block's sides beyond which buckets remain (else -+inf), moved
                # inward by the pad
                blocks.append((tuple(blk), x0 + (a - 1) * h + pad if a > 1 else -inf,
                               x0 + (a + 2) * h - pad if a < nx - 2 else inf,
                               y0 + (b - 1) * h + pad if b > 1 else -inf,
                               y0 + (b + 2) * h - pad if b < ny - 2 else inf))
        self.blocks = blocks
        self.pts = [tuple(p) for p in xy.tolist()]
        self.x0, self.y0, self.h = x0, y0, float(h)
        self.nx, self.ny = nx, ny
        self.xy = xy

    def _bound(self, cx: int, cy: int, r: int, x: float, y: float) -> float:
        """Lower bound (m) of the distance from (x, y) to any bucket outside the
        square of buckets within ``r`` of (cx, cy); inf if none is outside."""
        x0, y0, h = self.x0, self.y0, self.h
        lb = math.inf
        if cx + r < self.nx - 1:
            lb = x0 + (cx + r + 1) * h - x
        if cx - r > 0:
            lb = min(lb, x - (x0 + (cx - r) * h))
        if cy + r < self.ny - 1:
            lb = min(lb, y0 + (cy + r + 1) * h - y)
        if cy - r > 0:
            lb = min(lb, y - (y0 + (cy - r) * h))
        return lb

    def nearest(self, x: float, y: float, members: np.ndarray | None = None,
                exclude=()) -> int:
        """Index of the point nearest to (x, y) (m) among ``members`` (field
        indices in increasing order, e.g. ``np.flatnonzero`` of a mask; None:
        every point) less ``exclude`` (a set of indices); -1 if none is left."""
        x, y = float(x), float(y)
        if members is not None and len(members) <= self.FEW:
            return self._among(x, y, members.tolist(), exclude)
        h = self.h
        cx = min(max(int((x - self.x0) // h), 0), self.nx - 1)
        cy = min(max(int((y - self.y0) // h), 0), self.ny - 1)
        # fast path: the nearest of the 3 x 3 block, if accepted and conclusive
        blk, xlo, xhi, ylo, yhi = self.blocks[cx * self.ny + cy]
        best_d2, best_i = math.inf, -1
        for i, lx, ly in blk:
            dx = lx - x
            dy = ly - y
            d2 = dx * dx + dy * dy
            if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                best_d2, best_i = d2, i
        lb = min(x - xlo, xhi - x, y - ylo, yhi - y)   # (_bound at r = 1, padded)
        if best_i >= 0 and (lb == math.inf or (lb > 0 and best_d2 < lb * lb)):
            if self._accept(best_i, members, exclude):
                return best_i
            # the block's points nearer than the bound, nearest first (ties by index)
            near = sorted((d2, i) for i, lx, ly in blk
                          if (d2 := (lx - x) * (lx - x) + (ly - y) * (ly - y)) < lb * lb)
            for d2, i in near[1:]:
                if self._accept(i, members, exclude):
                    return i
        return self._ring_search(x, y, cx, cy, members, exclude)

    def _among(self, x: float, y: float, members: list, exclude) -> int:
        """The nearest of a short list of members, scored one by one (-1 if none)."""
        pts = self.pts
        best_d2, best_i = math.inf, -1
        for i in members:
            if i in exclude:
                continue
            lx, ly = pts[i]
            dx = lx - x
            dy = ly - y
            d2 = dx * dx + dy * dy
            if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                best_d2, best_i = d2, i
        return best_i

    @staticmethod
    def _accept(i: int, members, exclude) -> bool:
        if i in exclude:
            return False
        if members is None:
            return True
        p = int(members.searchsorted(i))
        return p < len(members) and int(members[p]) == i

    def _ring_search(self, x, y, cx, cy, members, exclude) -> int:
        nx, ny, cells = self.nx, self.ny, self.cells
        best_d2, best_i = math.inf, -1
        rejected = 0
        r = 0
        while True:
            if r == 0:
                ring = [(cx, cy)]
            else:
                ring = []
                lo_x, hi_x = max(cx - r, 0), min(cx + r, nx - 1)
                for yy in (cy - r, cy + r):
                    if 0 <= yy < ny:
                        ring.extend((xx, yy) for xx in range(lo_x, hi_x + 1))
                lo_y, hi_y = max(cy - r + 1, 0), min(cy + r - 1, ny - 1)
                for xx in (cx - r, cx + r):
                    if 0 <= xx < nx:
                        ring.extend((xx, yy) for yy in range(lo_y, hi_y + 1))
            for xx, yy in ring:
                for i, lx, ly in cells[xx * ny + yy]:
                    dx = lx - x
                    dy = ly - y
                    d2 = dx * dx + dy * dy
                    if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                        if self._accept(i, members, exclude):
                            best_d2, best_i = d2, i
                        else:
                            rejected += 1
            lb = self._bound(cx, cy, r, x, y)
            if lb == math.inf:
                return best_i
            lb -= 1e-9 * self.h
            if best_i >= 0 and lb > 0 and best_d2 < lb * lb:
                return best_i
            if members is not None and rejected > self.MAX_REJECTED:
                return nearest_brute_force(self.xy, x, y, members, exclude)
            r += 1


def nearest_brute_force(xy: np.ndarray, x: float, y: float, members: np.ndarray | None = None,
                        exclude=()) -> int:
    """Reference for :meth:`GridIndex.nearest`: every candidate scored, the
    smallest ``dx*dx + dy*dy`` (float64), ties by the smaller index; -1 if none."""
    idx = np.arange(len(xy)) if members is None else np.asarray(members, np.int64)
    if len(exclude):
        idx = idx[~np.isin(idx, np.fromiter(exclude, np.int64))]
    if not idx.size:
        return -1
    dx = xy[idx, 0] - float(x)
    dy = xy[idx, 1] - float(y)
    d2 = dx * dx + dy * dy
    at = np.flatnonzero(d2 == d2.min())
    return int(idx[at].min())


@dataclass(frozen=True)
class LandmarkField:
    xyz: np.ndarray        # (n, 3) m, z = 0
    tree: cKDTree          # on xyz[:, :2]

    def nearest(self, point_L: np.ndarray, k: int) -> np.ndarray:
        """Indices of the ``k`` landmarks nearest (horizontally) to ``point_L``,
        nearest first."""
        k = min(int(k), len(self.xyz))
        _, idx = self.tree.query(np.asarray(point_L, float)[:2], k=k)
        return np.atleast_1d(idx)

    @cached_property
    def grid(self) -> GridIndex:
        """The bucket index of the (x, y) (built on first use, then kept)."""
        return GridIndex(self.xyz[:, :2])


def near_site_xy(count: int, r_min_m: float, r_max_m: float, rng: np.random.Generator) -> np.ndarray:
    """``count`` landmarks (x, y) (m) around the site at the {L} origin whose
    horizontal distance ``r`` is log-uniform on ``[r_min_m, r_max_m]`` and whose
    azimuth is uniform: density ``count / (2 pi r^2 ln(r_max / r_min))`` per m^2.
    A camera at altitude ``h`` near the site sees a ground patch of size ~``h``
    at distances ~``h``, so it holds about the same number of these landmarks at
    every altitude down to ~``r_min_m``: the field follows the descent, and
    landmarks stay in view until the vision updates end."""
    if count < 0 or not 0 < r_min_m < r_max_m:
        raise ValueError(f"landing.landmarks.near_site: need count >= 0 and 0 < r_min_m < "
                         f"half_width_m, got {count}, {r_min_m}, {r_max_m}")
    r = r_min_m * (r_max_m / r_min_m) ** rng.uniform(0.0, 1.0, int(count))
    az = rng.uniform(-math.pi, math.pi, int(count))
    return np.column_stack([r * np.cos(az), r * np.sin(az)])


def make_field(half_width_m: float, count: int, seed: int, near_site: dict | None = None
               ) -> LandmarkField:
    """Random field: ``count`` landmarks uniform on the square of half width
    ``half_width_m`` (m), plus, if ``near_site`` (``{count, r_min_m}``) has a
    positive count, that many around the site (:func:`near_site_xy`, out to
    ``half_width_m``); ``seed`` fixes both (the uniform part is the same with
    or without the near-site part)."""
    if half_width_m <= 0 or count < 1:
        raise ValueError(f"landing.landmarks: need half_width_m > 0 and count >= 1, got "
                         f"{half_width_m}, {count}")
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0xB1A7]))
    xy = rng.uniform(-half_width_m, half_width_m, size=(int(count), 2))
    if near_site and int(near_site["count"]) > 0:
        rng_near = np.random.default_rng(np.random.SeedSequence([int(seed), 0xB1A8]))
        xy = np.vstack([xy, near_site_xy(int(near_site["count"]), float(near_site["r_min_m"]),
                                         float(half_width_m), rng_near)])
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    # scipy.spatial imported here: the Snakefile parse imports this module (through the
    # planner's method registry) and builds no field
    from scipy.spatial import cKDTree

    return LandmarkField(xyz=xyz, tree=cKDTree(xy))
