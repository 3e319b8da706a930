"""Landmark field on flat ground and nearest-landmark queries (SPEC B.2).

Landmarks are drawn uniformly on the plane z = 0 of {L} over the square
``[-half_width, +half_width]^2`` (m), from their own seed (the same field for
every Monte-Carlo run and every method). A 2-D ``scipy.spatial.cKDTree`` on
(x, y) answers the planner's nearest-landmark query.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["LandmarkField", "make_field"]


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


def make_field(half_width_m: float, count: int, seed: int) -> LandmarkField:
    """Uniform random field of ``count`` landmarks; ``seed`` fixes it."""
    if half_width_m <= 0 or count < 1:
        raise ValueError(f"landing.landmarks: need half_width_m > 0 and count >= 1, got "
                         f"{half_width_m}, {count}")
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0xB1A7]))
    xy = rng.uniform(-half_width_m, half_width_m, size=(int(count), 2))
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    return LandmarkField(xyz=xyz, tree=cKDTree(xy))
