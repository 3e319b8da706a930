"""The planner's nearest-landmark pick (screens.nearest: a uniform grid of
buckets, screens.field_grid) against a brute-force search over every candidate:
the same landmark for any query point, subset of detected landmarks and
excluded landmark, exact distance ties included (broken by the smaller index)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st

from opnav.landing.landmarks import make_field, nearest_brute_force
from opnav.landing.planning import screens


def _lattice_field(n_side: int, step: float, seed: int) -> np.ndarray:
    """Landmarks on an integer lattice (every query has exact ties), shuffled so
    that index order is not spatial order, plus a few exact duplicates."""
    g = np.arange(n_side) * step
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    rng = np.random.default_rng(seed)
    xy = xy[rng.permutation(len(xy))]
    return np.concatenate([xy, xy[rng.integers(len(xy), size=5)]])


def test_brute_force_reference_breaks_ties_by_index():
    xy = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [3.0, 3.0]])
    assert nearest_brute_force(xy, 0.0, 0.0) == 0                      # three tied: the first
    assert nearest_brute_force(xy, 0.0, 0.0, np.array([1, 2, 3])) == 1
    assert nearest_brute_force(xy, 0.0, 0.0, np.array([1, 2, 3]), {1}) == 2
    assert nearest_brute_force(xy, 0.0, 0.0, np.array([3]), {3}) == -1


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), per_cell=st.sampled_from([0.5, 1.0, 2.0, 5.0]),
       frac=st.sampled_from([1.0, 0.3, 0.02, 0.0]), lattice=st.booleans())
def test_grid_nearest_equals_brute_force(seed, per_cell, frac, lattice):
    """Query points on landmarks, on bucket boundaries, halfway between lattice
    points (exact ties), random and far outside the field; detected subsets
    from all to none; with and without an excluded landmark."""
    rng = np.random.default_rng(seed)
    xy = (_lattice_field(12, 25.0, seed) if lattice else
          rng.uniform(-1000.0, 1000.0, size=(int(rng.integers(1, 400)), 2)))
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    grid, cells = screens.field_grid(xyz, per_cell)
    x0, y0, h, nx, ny = grid
    n = len(xy)
    members = np.flatnonzero(rng.random(n) < frac) if frac < 1.0 else np.arange(n)
    edges_x = x0 + h * rng.integers(-1, int(nx) + 2, size=6)
    edges_y = y0 + h * rng.integers(-1, int(ny) + 2, size=6)
    q = np.concatenate([
        xy[rng.integers(n, size=6)],                                      # on landmarks
        np.stack([edges_x, edges_y], 1),                                  # bucket corners
        np.stack([edges_x, rng.uniform(-1000, 1000, 6)], 1),              # bucket edges
        0.5 * (xy[rng.integers(n, size=6)] + xy[rng.integers(n, size=6)]),  # midpoints: ties
        rng.uniform(-1500.0, 1500.0, size=(10, 2)),
        rng.uniform(-1.0, 1.0, size=(3, 2)) * 1e5,                         # far outside
    ])
    for x, y in q.tolist():
        for ex in (-1, int(rng.integers(n))):
            want = nearest_brute_force(xy, x, y, members, {ex} - {-1})
            assert screens.nearest(x, y, xyz, members, np.int64(ex), grid, cells) == want, (x, y, ex)


def test_grid_nearest_many_rejections_falls_back_exactly():
    """A query far from the only detected landmarks (more non-detected ones on
    the way than the ring search tries) still gets the nearest detected one."""
    f = make_field(1000.0, 2000, seed=4)
    far = np.argsort(np.hypot(*f.xyz[:, :2].T))[-3:]                  # three in a far corner
    members = np.sort(far).astype(np.int64)
    grid, cells = screens.field_grid(f.xyz)
    assert screens.nearest(0.0, 0.0, f.xyz, members, np.int64(-1), grid, cells) == nearest_brute_force(
        f.xyz[:, :2], 0.0, 0.0, members)


def test_compiled_nearest_pick_agrees_with_brute_force_on_ties():
    """The planner's pick (screens.nearest: bucket grid, ring search) equals the
    brute force on a lattice field with exact ties, for many points and excluded
    landmarks, detected lists from most to few landmarks, points far outside."""
    xy = _lattice_field(15, 10.0, 7)
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    grid, cells = screens.field_grid(xyz)
    rng = np.random.default_rng(3)
    for frac in (1.0, 0.5, 0.05):
        det = np.flatnonzero(rng.random(len(xy)) < frac)
        pts = np.concatenate([xy[rng.integers(len(xy), size=20)] + 5.0 * rng.integers(-1, 2, (20, 2)),
                              rng.uniform(-300, 480, (20, 2))])
        ex = np.where(rng.random(len(pts)) < 0.5, rng.choice(det, len(pts)), -1)
        for j, (x, y) in enumerate(pts.tolist()):
            e = {int(ex[j])} if ex[j] >= 0 else set()
            want = nearest_brute_force(xy, x, y, det, e)
            assert screens.nearest(x, y, xyz, det, int(ex[j]), grid, cells) == want, (frac, j, x, y)
