"""Landmark field on flat ground and nearest-landmark queries (SPEC B.2).

Landmarks are drawn uniformly on the plane z = 0 of {L} over the square
``[-half_width, +half_width]^2`` (m), plus optionally a part around the site
whose density grows as the inverse square of the distance to it
(:func:`near_site_xy`, config ``landing.landmarks.near_site``), from their own
seed (the same field for every Monte-Carlo run and every method). The
planner's nearest-landmark pick is ``planning.screens.nearest`` (a bucket grid built
once per field, ``planning.screens.field_grid``); :func:`nearest_brute_force` is its
reference (every candidate scored, exact ties to the smaller index).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from opnav.landing.setup import NearSite

__all__ = ["LandmarkField", "make_field", "near_site_xy", "nearest_brute_force"]


def nearest_brute_force(xy: np.ndarray, x: float, y: float, members: np.ndarray | None = None,
                        exclude=()) -> int:
    """Reference for ``planning.screens.nearest``: every candidate scored, the
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


def make_field(half_width_m: float, count: int, seed: int, near_site: NearSite | None = None
               ) -> LandmarkField:
    """Random field: ``count`` landmarks uniform on the square of half width
    ``half_width_m`` (m), plus, if ``near_site`` (``setup.NearSite``) has a
    positive count, that many around the site (:func:`near_site_xy`, out to
    ``half_width_m``); ``seed`` fixes both (the uniform part is the same with
    or without the near-site part)."""
    if half_width_m <= 0 or count < 1:
        raise ValueError(f"landing.landmarks: need half_width_m > 0 and count >= 1, got "
                         f"{half_width_m}, {count}")
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0xB1A7]))
    xy = rng.uniform(-half_width_m, half_width_m, size=(int(count), 2))
    if near_site is not None and int(near_site.count) > 0:
        rng_near = np.random.default_rng(np.random.SeedSequence([int(seed), 0xB1A8]))
        xy = np.vstack([xy, near_site_xy(int(near_site.count), float(near_site.r_min_m),
                                         float(half_width_m), rng_near)])
    return LandmarkField(xyz=np.column_stack([xy, np.zeros(len(xy))]))
