"""How many optima the depth error has over the visible angles (paper B, Fig. 5; claim B-C8).

Paper B searches the depth error (eq. 19-25) by golden section because, it says, the error
"has only one optimum" over the viewing angles. The search is run on each side of the velocity
(the visible interval split at beta = 0, :func:`opnav.landing.planner.visible_intervals`), so
the premise is: on each side, one local minimum (interior, or at an end when the error is
monotone there). :func:`count_minima` counts them on a grid of ``n_grid`` angles across a
side; :func:`call_minima` does so for one recorded planning call of the Monte Carlo (the same
inputs the timing replay reads: estimated position, velocity, acceleration, attitude and
covariance, ``opnav.landing.records``) with the reference depth error
(:func:`opnav.landing.planning.reference.signed_depth_error`) and the planner's own baseline
and error radius; :func:`count_calls` does so for every recorded call and
:func:`count_summary` states the result (the B-summary's ``optima`` block, the claims' evidence).

A grid point where the error is infinite (no parallax, no ground) is left out; ties within a
relative ``1e-12`` are not minima (a flat run is one minimum at most). Units: rad, m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.landing.planning.depth import baseline, error_radius
from opnav.landing.planning.geometry import plane_geometry
from opnav.landing.planning.layout import DegenerateGeometry
from opnav.landing.planning.reference import signed_depth_error
from opnav.landing.records import MonteCarlo

#: two values closer than this (relative) are a tie, not a descent
TIE_RTOL = 1e-12


def count_minima(f: np.ndarray) -> int:
    """The number of local minima of a sampled curve ``f`` (finite values only; an end counts
    when the curve rises away from it). A monotone curve has one (at an end), a U shape one,
    a W shape two; a constant curve one."""
    f = np.asarray(f, float)
    f = f[np.isfinite(f)]
    if f.size == 0:
        return 0
    if f.size == 1:
        return 1
    tol = TIE_RTOL * np.maximum(np.abs(f[:-1]), np.abs(f[1:]))
    d = np.diff(f)
    s = np.where(d > tol, 1, np.where(d < -tol, -1, 0))     # +1 rising, -1 falling, 0 flat
    s = s[s != 0]                                             # flats carry the previous trend
    if s.size == 0:
        return 1
    # a minimum where falling turns to rising, plus the ends when the curve rises away from them
    n = int(np.sum((s[:-1] == -1) & (s[1:] == 1)))
    n += int(s[0] == 1)
    n += int(s[-1] == -1)
    return n


def side_grids(lo: float, hi: float, n_grid: int) -> np.ndarray:
    """``n_grid`` signed angles (rad) strictly inside a visible sub-interval [lo, hi]."""
    return np.linspace(lo, hi, int(n_grid) + 2)[1:-1]


def call_minima(state, cfg, camera, n_grid: int) -> list[int] | None:
    """Local minima of the depth error on each visible side of one planning call (``state``: a
    ``planner.PlanState``; ``cfg``: its ``PlannerConfig``; ``camera``: the scenario's);
    None where the call has no plane, no baseline or no error radius (the planner's fallback)."""
    from opnav.landing.planner import visible_intervals

    v, a = np.asarray(state.v, float), np.asarray(state.a, float)
    b = baseline(v, a, float(cfg.t_s))
    r_e = error_radius(np.asarray(state.P, float)[3:6, 3:6], float(cfg.t_s), float(cfg.n_sigma_v))
    if not (b > 0 and r_e > 0):
        return None
    try:
        geom = plane_geometry(state.r, v)
    except DegenerateGeometry:
        return None
    out = []
    for lo, hi in visible_intervals(geom, state.R_LtoB, camera, cfg.margin_px):
        if not hi > lo:
            continue
        betas = side_grids(lo, hi, n_grid)
        out.append(count_minima(signed_depth_error(betas, geom, b, r_e)))
    return out


@dataclass(frozen=True)
class OptimaCounts:
    """The minima of every counted call (:func:`count_calls`): per call the minima on each side of
    the velocity, the calls left out (no plane or baseline), the calls recorded and the angles a
    side."""

    per_call: list[list[int]]
    skipped: int
    n_recorded: int
    n_grid: int


@dataclass(frozen=True)
class OptimaSummary:
    """B-C8's count of one scenario (:func:`count_summary`; ``optima/<camera>.json``): calls
    counted, calls with more than one local minimum on a side, the most minima on a side of one
    call, the sides counted, the calls left out and recorded, and the angles a side. Its sentence is
    the report layer's (``opnav.report.landing.optima_text``)."""

    scenario: str
    method: str
    n_calls: int
    calls_multi_minimum: int
    max_minima_per_call: int
    sides_counted: int
    calls_skipped: int
    n_recorded: int
    n_grid: int


def count_calls(scn, data: MonteCarlo, n_grid: int, max_calls: int = 0) -> OptimaCounts:
    """Every recorded planning call of one Monte Carlo (``data``: the gathered record of the
    depth method, ``montecarlo.gather``) in scenario ``scn`` (``descent.build_scenario``):
    per call the minima on each side. ``max_calls``: at most that many calls, evenly spaced
    (0: all)."""
    from opnav.landing.planner import PlanState

    n = len(data.plan_step)
    idx = np.arange(n) if not max_calls or max_calls >= n else np.unique(
        np.round(np.linspace(0, n - 1, int(max_calls))).astype(int))
    per_call, skipped = [], 0
    for i in idx:
        st = PlanState(data.plan_r[i], data.plan_v[i], data.plan_a[i], data.plan_R[i], data.plan_P[i])
        m = call_minima(st, scn.planner, scn.camera, n_grid)
        if m is None or not m:
            skipped += 1
            continue
        per_call.append(m)
    return OptimaCounts(per_call, skipped, int(n), int(n_grid))


def count_summary(counts: OptimaCounts, scenario: str, method: str = "depth") -> OptimaSummary:
    """The optima count of one scenario for the summary and the claims: calls counted, calls
    with more than one local minimum on a side (``calls_multi_minimum``), the most minima on a
    side of one call, the sides counted and the calls left out (no plane or baseline)."""
    per = counts.per_call
    return OptimaSummary(scenario=scenario, method=method, n_calls=len(per),
                         calls_multi_minimum=int(sum(1 for m in per if max(m) > 1)),
                         max_minima_per_call=int(max((max(m) for m in per), default=0)),
                         sides_counted=int(sum(len(m) for m in per)), calls_skipped=int(counts.skipped),
                         n_recorded=int(counts.n_recorded), n_grid=int(counts.n_grid))
