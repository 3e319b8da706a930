"""Landmark planner: golden-section search over the visible interval, then the
nearest visible landmark (paper B sec. 2.2, eq. 26; SPEC B.3).

Description
-----------
Every method runs the SAME search; only the scalar objective differs:

1. the vertical plane through the lander that holds the estimated velocity
   (``opnav.landing.depth_error.plane_geometry``), parametrised by the signed
   angle ``beta`` between velocity and line of sight;
2. the visible interval: the ``beta`` whose line of sight meets the ground and
   lies inside the camera's field of view (with the planning margin) under the
   *estimated* attitude, computed exactly as an intersection of half circles
   (:func:`visible_intervals`); it is split at ``beta = 0``
   (no parallax there, the depth error is infinite), giving at most two
   sub-intervals;
3. a golden-section search (:func:`golden_section`, tolerance ``tol_rad``) on
   each sub-interval; the better of the two optima wins;
4. ``beta*`` is mapped to its ground point (eq. 26: the ideal direction) and
   the landmark nearest to it (horizontal distance, exact ties to the smaller
   index) among those actually detected in the image (truly inside the field
   of view with the margin) is chosen, however far (the optimum is planned
   from the estimated pose); no landmark only if the image holds none. One
   call asks the field's bucket index (``LandmarkField.grid``); the batched
   planner asks the ``cKDTree`` for the ``knn`` nearest of every run at once
   and scores a run's detected landmarks directly when those do not settle it
   (the same order: distance, then index).

Objectives (minimised) are built by a table of factories, :data:`OBJECTIVES`:
``depth`` is the depth estimation error (eq. 23-25,
:func:`~opnav.landing.depth_error.depth_error_scalar`, tested against the
vectorised :func:`~opnav.landing.depth_error.depth_error`); every
name of :data:`opnav.landing.metrics.METRIC_NAMES` (``svd``, ``gdop``,
``cond``, ``logdet``, ``mineig``) is the negated metric at the ground point of
``beta`` (``metrics.make_metric``; larger is better there). Methods without a
search (e.g. a random pick) can be added to :data:`PICKERS`. Adding a method
is adding one entry.

How a baseline metric is evaluated inside the search is ``eval_path``:
``matrix_scalar`` (default: the Jacobian H of eq. 14-18, checked against its
CasADi derivation, then one LAPACK SVD of the 6 x 12 H per candidate, the
matrix computation the paper describes, with minimal call overhead),
``numpy_H`` (the batch numpy route, called with one candidate), ``reference``
(a compiled CasADi Function call per candidate), ``casadi_map``, or
``closed_form`` (the metrics module's closed-form singular values, a finding
beyond the paper, see ``opnav.landing.metrics``).

Timing: :func:`plan` measures its whole call with ``time.perf_counter_ns`` and
counts objective evaluations, so a timing comparison rests on both. The
per-call path is kept lean because its overhead beyond the objective
evaluations is a target (issue 14: at most 2x the evaluations for ``depth``,
``benchmarks/bench_planning.py`` prints it): scalar float arithmetic where
the measured numpy call overhead on 3-vectors exceeded the arithmetic
(plane, visible interval, eq. 19/22 constants, eq. 26 ground point), the
candidate list sorted only where the edge rule or the diagnostic needs it,
and the bucket index for the one nearest-landmark query.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from opnav.landing.camera import Camera
from opnav.landing import metrics
from opnav.landing.depth_error import (DegenerateGeometry, PlaneGeometry, baseline, depth_error_at_points,
                                       depth_error_scalar, error_radius, ground_point_scalar,
                                       plane_geometry)
from opnav.landing.landmarks import LandmarkField, nearest_brute_force
from opnav.rotations import cross

__all__ = ["golden_section", "visible_intervals", "PlanState", "PlanResult", "PlannerConfig",
           "plan", "plan_batch", "golden_section_batch", "OBJECTIVES", "PICKERS",
           "available_methods", "depth_objective"]

INVPHI = (math.sqrt(5.0) - 1.0) / 2.0      # 1/phi = 0.618...
_EYE6 = np.eye(6)


def golden_section(fun: Callable[[float], float], a: float, b: float, tol: float
                   ) -> tuple[float, float, int]:
    """Minimise ``fun`` on ``[a, b]`` by golden-section search.

    Returns ``(x, f(x), n_evals)`` where ``x`` is the best evaluated point; the
    bracket shrinks by 1/phi per evaluation until shorter than ``tol``. ``+inf``
    values are allowed (treated as large). Raises ``ValueError`` for a bad
    interval or tolerance.
    """
    if not (math.isfinite(a) and math.isfinite(b)) or b < a:
        raise ValueError(f"golden_section: bad interval [{a}, {b}]")
    if not tol > 0:
        raise ValueError(f"golden_section: tolerance must be positive, got {tol}")
    g = INVPHI                         # (a local: the loop is on the timed path)
    c = b - g * (b - a)
    d = a + g * (b - a)
    fc = fun(c)
    fd = fun(d)
    n = 2
    while (b - a) > tol:
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = fun(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = fun(d)
        n += 1
    return (c, fc, n) if fc <= fd else (d, fd, n)


@dataclass(frozen=True)
class PlanState:
    """The filter's estimate used for planning (all {L}, SI): position, velocity,
    acceleration (m/s^2), attitude, 12x12 covariance of [r, v, dtheta, p]."""

    r: np.ndarray
    v: np.ndarray
    a: np.ndarray
    R_LtoB: np.ndarray
    P: np.ndarray


@dataclass(frozen=True)
class PlannerConfig:
    t_s: float = 1.0                 # observation interval of the depth model, s
    n_sigma_v: float = 3.0           # eps_v = n_sigma * sqrt(max eig P_vv)
    tol_rad: float = 1e-3            # golden-section tolerance
    n_grid: int = 0                  # visible interval: 0 exact, > 0 grid over [-pi, pi]
    margin_px: float = 40.0          # planning margin inside the detector edge, px
    knn: int = 16                    # nearest-landmark candidates checked
    eval_path: str = "matrix_scalar"  # how baseline metrics are evaluated
    p_known: tuple = (0.0, 0.0, 0.0)  # known landmark (landing site), m
    # the filter's model, for the planned-information metric (logdet_nav, planned_info)
    noise_scale: float = 1.0         # filter bearing noise / true pixel noise
    depth_sigma_frac: float = 0.1    # a new landmark's depth guess 1-sigma / depth
    obs_per_landmark: int = 3        # observations of a landmark (Fig. 3 strategy)
    oc: bool = True                  # observability-constrained updates
    g: tuple = (0.0, 0.0, -3.711)    # gravity in {L}, m/s^2 (the filter's transition)


@dataclass(slots=True)
class PlanResult:
    method: str
    index: int                 # chosen landmark (field index), -1 if none
    beta: float                # signed beta*, rad (nan if no search)
    ground: np.ndarray         # ideal ground point, m
    objective: float           # objective at beta* (minimised)
    n_evals: int               # objective evaluations
    time_ns: int               # wall time of the planning call (perf_counter_ns)
    note: str = ""
    cpu_ns: int = 0            # not measured by the call (0): the replay (timing.replay)
                               # reads the thread CPU clock around it
    edge: bool = False         # in-plane optimum on an end of the visible interval:
                               # the detected landmarks were scored directly
    pick_ratio: float = math.nan  # picked landmark's metric / best detected one's (>= 1;
                                  # 1 = the best detected landmark), outside the timed path


_GRID_CACHE: dict = {}


def _unit_grid(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if n not in _GRID_CACHE:
        t = np.linspace(-math.pi, math.pi, int(n))
        _GRID_CACHE[n] = (t, np.cos(t)[:, None], np.sin(t)[:, None])
    return _GRID_CACHE[n]


def _split_at_zero(b0: float, b1: float) -> list[tuple[float, float]]:
    eps = 1e-9
    out = []
    if b0 < 0:
        hi = min(b1, -eps)
        if hi > b0:
            out.append((b0, hi))
    if b1 > 0:
        lo = max(b0, eps)
        if b1 > lo:
            out.append((lo, b1))
    return out


def visible_intervals(geom: PlaneGeometry, R_LtoB: np.ndarray, camera: Camera, n_grid: int,
                      margin_px: float) -> list[tuple[float, float]]:
    """Sub-intervals of signed beta (rad) whose lines of sight meet the ground
    inside the field of view (estimated attitude), split at 0.

    ``n_grid = 0``: exact. Each of the four side planes of the (square) field
    of view and the ground condition ``u_z < 0`` is, on the circle of in-plane
    directions ``u(beta) = cos(beta) v_hat + sin(beta) w_hat``, an open half
    circle centred at some angle ``phi_i``; their intersection is empty unless
    all ``phi_i`` fit in an arc shorter than pi, and is then
    ``(max phi_i - pi/2, min phi_i + pi/2)``. ``n_grid > 0``: the circle is
    sampled at ``n_grid`` angles and the interval ends are the outermost
    visible samples (reference implementation).
    """
    if n_grid <= 0:
        return _visible_exact(geom, R_LtoB, camera, margin_px)
    return _visible_grid(geom, R_LtoB, camera, n_grid, margin_px)


def _visible_exact(geom, R_LtoB, camera, margin_px):
    # scalar floats after the two matrix-vector products, the planner's timed
    # path (numpy's 3 x 3 products are kept: OpenBLAS fuses multiply-adds, so
    # float arithmetic would round otherwise, and mineig's plateau picks
    # follow rounding); the same rule as the batched planner's _intervals.
    # ``ndarray.dot``: the same BLAS call as ``@`` on these contiguous operands
    # (bit-equal: the same gemm/gemv), without the matmul ufunc dispatch (0.3 against 0.75 us)
    k = (camera.half_px - margin_px) / camera.focal_px
    if k <= 0:
        return []
    M = camera.R_BtoC.dot(R_LtoB)
    a0, a1, a2 = M.dot(geom.v_hat).tolist()
    c0, c1, c2 = M.dot(geom.w_hat).tolist()
    atan2, pi = math.atan2, math.pi
    # k z -+ x > 0, k z -+ y > 0 (camera axes); ground: -u_z(L) > 0
    phis = [atan2(k * c2 - c0, k * a2 - a0), atan2(k * c2 + c0, k * a2 + a0),
            atan2(k * c2 - c1, k * a2 - a1), atan2(k * c2 + c1, k * a2 + a1),
            geom.gamma - pi / 2]
    phis.sort()
    # the widest gap between consecutive centres (first on ties), around the circle
    j, gap = 4, phis[0] + 2 * pi - phis[4]
    for i in (3, 2, 1, 0):
        g = phis[i + 1] - phis[i]
        if g >= gap:
            j, gap = i, g
    if gap <= pi:
        return []                      # the centres do not fit in a half circle
    # the window starts after the gap; the centres before it get one turn (unwrap)
    b0 = (phis[j] + 2 * pi if j < 4 else phis[4]) - pi / 2
    b1 = phis[(j + 1) % 5] + pi / 2
    # express in the ground arc (-(pi - gamma), gamma)
    mid = 0.5 * (b0 + b1)
    g0 = geom.gamma - pi / 2
    shift = 2 * pi * round((g0 - mid) / (2 * pi))
    return _split_at_zero(b0 + shift + 1e-12, b1 + shift - 1e-12)


def _visible_grid(geom, R_LtoB, camera, n_grid, margin_px):
    betas, cb, sb = _unit_grid(n_grid)
    # the two in-plane directions in camera axes; u(beta) = cos v_hat + sin w_hat
    M = camera.R_BtoC @ R_LtoB
    d = cb * (M @ geom.v_hat) + sb * (M @ geom.w_hat)
    lim = (camera.half_px - margin_px) / camera.focal_px
    z = d[:, 2]
    ok = ((z > 0) & (np.abs(d[:, 0]) < lim * z) & (np.abs(d[:, 1]) < lim * z)
          & (betas > -(math.pi - geom.gamma)) & (betas < geom.gamma))
    if not ok.any():
        return []
    idx = np.flatnonzero(ok)
    # the field of view cut by a plane through its apex is one arc: take the
    # longest run of visible grid angles (guards against grid artefacts)
    if idx[-1] - idx[0] + 1 == idx.size:
        i0, i1 = idx[0], idx[-1]
    else:
        runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
        run = max(runs, key=len)
        i0, i1 = run[0], run[-1]
    return _split_at_zero(float(betas[i0]), float(betas[i1]))


# ----------------------------------------------------------------- objectives

def depth_objective(state: PlanState, geom: PlaneGeometry, cfg: PlannerConfig, camera=None,
                    sigma_b=None) -> Callable:
    """Depth estimation error (eq. 23-25, ``depth_error.depth_error_scalar``) as
    a scalar function of signed beta; ``batch`` scores landmarks
    (``depth_error.depth_error_at_points``)."""
    b = baseline(state.v, state.a, cfg.t_s)
    r_e = error_radius(state.P[3:6, 3:6], cfg.t_s, cfg.n_sigma_v)
    f = depth_error_scalar(geom, b, r_e)
    f.batch = lambda points: depth_error_at_points(points, geom, b, r_e)
    f.ratio = _ratio_positive
    return f


def _ratio_positive(f_pick: float, f_best: float) -> float:
    """Picked / best for a positive objective that is minimised (>= 1)."""
    return f_pick / f_best


def _ratio_negated(f_pick: float, f_best: float) -> float:
    """Best / picked metric for a positive metric m maximised, f = -m (>= 1)."""
    return f_best / f_pick


def _ratio_log(f_pick: float, f_best: float) -> float:
    """Ratio of the metric's exponentials for a log metric maximised, f = -log m
    (log det: the ratio of the determinants, >= 1)."""
    return math.exp(f_pick - f_best)


_METRIC_CACHE: dict = {}


def _metric(name: str) -> metrics.Metric:
    if name not in _METRIC_CACHE:
        _METRIC_CACHE[name] = metrics.make_metric(name)
    return _METRIC_CACHE[name]


def _metric_context(state: PlanState, cfg: PlannerConfig, camera: Camera,
                    sigma_b: float) -> metrics.MetricContext:
    """The metrics' context of a planning state (bearing noise sigma_b^2 I, rad^2);
    inputs validated once per descent (descent.run_descent), not per call."""
    return metrics.MetricContext.trusted(r_L=state.r, v_L=state.v, R_LtoB=state.R_LtoB,
                                         p_known_L=np.asarray(cfg.p_known, float), P=state.P,
                                         R_meas=(sigma_b**2) * _EYE6, boresight_B=camera.boresight_B)


def metric_objective(name: str) -> Callable:
    """Factory: the negated metric ``name`` at the ground point of beta."""

    def build(state: PlanState, geom: PlaneGeometry, cfg: PlannerConfig, camera: Camera,
              sigma_b: float, **_) -> Callable:
        m = _metric(name)
        ctx = _metric_context(state, cfg, camera, sigma_b)
        ground = ground_point_scalar(geom)
        path = cfg.eval_path
        # batch scoring of landmarks (edge rule): the same computation as the search's
        # path, vectorised: closed-form singular values, or H for all + batched LAPACK
        batch_call = {"closed_form": m.__call__, "casadi_map": m.casadi_map}.get(path, m.numpy_H)

        def batch(points: np.ndarray) -> np.ndarray:
            return -batch_call(ctx, np.asarray(points, float))

        if path in ("matrix_scalar", "closed_form"):
            call1 = m.matrix_scalar if path == "matrix_scalar" else m.scalar

            def f(beta: float) -> float:
                p = ground(beta)
                return math.inf if p is None else -call1(ctx, p)
        else:
            call = {"numpy_H": m.numpy_H, "reference": m.reference,
                    "casadi_map": m.casadi_map}.get(path)
            if call is None:
                raise ValueError(f"landing.planner.eval_path: unknown {path!r}")

            def f(beta: float) -> float:
                p = ground(beta)
                if p is None:
                    return math.inf
                return -float(call(ctx, np.array([p]))[0])
        f.batch = batch
        f.ratio = _ratio_log if name == "logdet" else _ratio_negated
        f.diagnostic = lambda points: -m(ctx, np.asarray(points, float))   # fastest, same values

        def screen(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            lo, hi = m.screen(ctx, np.asarray(points, float), rtol=_SHORTLIST_RTOL / 10)
            return -hi, -lo                 # bounds on the minimised objective

        f.screen = screen                   # the batched edge rule's screening (plan_batch)
        f.ctx, f.ground = ctx, ground       # for plan_batch's searches across runs
        return f

    return build


def planned_info_objective(state: PlanState, geom: PlaneGeometry, cfg: PlannerConfig, camera: Camera,
                           sigma_b: float, **_) -> Callable:
    """``logdet_nav``: minus the planned navigation information of the ground
    point of beta (:func:`opnav.landing.planned_info.planned_nav_logdet`: the
    candidate's own initialisation, the filter's noise model ``noise_scale *
    sigma_b``, ``obs_per_landmark`` observations ``t_s`` apart from the predicted
    poses, marginalised on [r, v, theta])."""
    from opnav.landing.planned_info import planned_nav_logdet

    ground = ground_point_scalar(geom)
    kw = dict(sigma_f=sigma_b * cfg.noise_scale, depth_sigma_frac=cfg.depth_sigma_frac,
              n_obs=cfg.obs_per_landmark, dt=cfg.t_s, g=cfg.g, oc=cfg.oc,
              boresight_B=camera.boresight_B)
    p_known = np.asarray(cfg.p_known, float)

    def batch(points: np.ndarray) -> np.ndarray:
        return -planned_nav_logdet(state.r, state.v, state.a, state.R_LtoB, state.P, p_known, points,
                                   **kw)

    def f(beta: float) -> float:
        p = ground(beta)
        return math.inf if p is None else float(batch(np.asarray(p)[None])[0])

    f.batch = batch
    f.ratio = _ratio_log
    return f


#: method name -> objective factory (minimised over signed beta)
OBJECTIVES: dict[str, Callable] = {"depth": depth_objective, "logdet_nav": planned_info_objective}
OBJECTIVES.update({n: metric_objective(n) for n in metrics.METRIC_NAMES})

def _pick_random(field_, cand, state, camera, rng) -> int:
    """A detected landmark drawn uniformly (the run's own picker stream)."""
    if rng is None:
        raise ValueError("the 'random' planner needs a random generator")
    return int(rng.integers(len(cand)))


def _pick_center(field_, cand, state, camera, rng) -> int:
    """The detected landmark nearest the image centre (estimated attitude)."""
    d = (field_.xyz[cand] - state.r) @ state.R_LtoB.T
    cosang = (d @ camera.boresight_B) / np.linalg.norm(d, axis=1)
    return int(np.argmax(cosang))


def _pick_closest(field_, cand, state, camera, rng) -> int:
    """The detected landmark nearest the estimated lander by range (m): no
    search, no metric; exact ties go to the smaller field index (``cand`` is
    sorted). The control that tells how much of a metric's edge is picking a
    close landmark (a short range is what ``svd`` mostly rewards)."""
    d = field_.xyz[cand] - state.r
    return int(np.argmin(np.einsum("ij,ij->i", d, d)))


#: method name -> direct picker without search: f(field, candidate indices (k,),
#: state, camera, rng) -> chosen position in the candidates (B-X1 baselines and
#: the equivalence test's negative controls)
PICKERS: dict[str, Callable] = {"random": _pick_random, "center": _pick_center,
                                "closest": _pick_closest}


def alternative_path(cfg: PlannerConfig) -> PlannerConfig:
    """``cfg`` on the other fastest faithful evaluation path of the baselines:
    closed-form singular values if ``cfg`` uses the explicit matrices, else the
    explicit H + LAPACK path (``matrix_scalar``); for timing both (B-F7, B-T3)."""
    import dataclasses

    return dataclasses.replace(cfg, eval_path="matrix_scalar" if cfg.eval_path == "closed_form"
                               else "closed_form")


def available_methods() -> tuple[str, ...]:
    return tuple(OBJECTIVES) + tuple(PICKERS)


# ----------------------------------------------------------------- planning

def _pick_nearest(field_: LandmarkField, point, detected: np.ndarray, exclude=()) -> int:
    """The detected landmark nearest (horizontally) to ``point``, less
    ``exclude``; -1 only if the image holds no other landmark (paper B sec.
    2.2: "the visible landmark nearest to the optimum"). ``detected``: the
    image's feature list, field indices in increasing order.

    The optimum, planned from the *estimated* pose, may fall outside the *true*
    image: the pick is then the nearest landmark the image does hold, however
    far. Exact distance ties go to the smaller index. By the field's bucket
    index (``LandmarkField.grid``, plain floats: a few us per query where a
    ``cKDTree`` query costs ~15 us of call overhead for one point)."""
    return field_.grid.nearest(point[0], point[1], detected, exclude)


def _candidates(detected: np.ndarray, exclude) -> np.ndarray:
    """The detected landmarks less ``exclude``, sorted field indices."""
    cand = np.sort(np.asarray(detected, np.int64))
    for e in exclude:          # (at most a few: a mask per element, not np.isin's sort)
        cand = cand[cand != e]
    return cand


def plan(method: str, state: PlanState, camera: Camera, field_: LandmarkField,
         visible: Callable[[np.ndarray], np.ndarray], cfg: PlannerConfig,
         exclude: set = frozenset(), rng: np.random.Generator | None = None,
         detected: np.ndarray | None = None, diagnose: bool = True) -> PlanResult:
    """One planning call (see :func:`_plan`), with its wall time (``time_ns``,
    ``perf_counter_ns``). Its CPU time is measured from outside, by the replay
    (``timing.replay``: the calling thread's CPU clock around the call): the
    thread CPU clock is a system call, and two reads inside the call cost
    2-3 us of a 30 us depth call (measured, the code after a read runs slower
    too), so ``cpu_ns`` stays 0.

    ``detected``: field indices, in increasing order, of the landmarks the
    image holds (the feature detector's list, the same for every method, as
    ``np.flatnonzero`` of the image's mask gives them); computed from
    ``visible`` if not given. Building it is not planning work, so it stays
    outside the timed path, as does the diagnostic ``pick_ratio`` (every
    detected landmark scored by the method's own metric, fastest path)."""
    if detected is None:
        detected = np.flatnonzero(visible(field_.xyz))
    res, fun, vals, cand = _plan(method, state, camera, field_, cfg, exclude, rng,
                                 np.asarray(detected, np.int64))
    if diagnose and fun is not None and res.index >= 0:
        if cand is None:
            cand = _candidates(detected, exclude)
        if cand.size:
            if vals is None:       # (edge calls scored every detected landmark already)
                vals = getattr(fun, "diagnostic", fun.batch)(field_.xyz[cand])
            fin = np.isfinite(vals)
            if fin.any():
                f_pick = vals[np.searchsorted(cand, res.index)] if res.index in cand else math.nan
                res.pick_ratio = float(fun.ratio(f_pick, float(vals[fin].min())))
    return res


def _plan(method: str, state: PlanState, camera: Camera, field_: LandmarkField, cfg: PlannerConfig,
          exclude: set, rng: np.random.Generator | None, detected: np.ndarray):
    """One planning call: choose the next unknown landmark; returns the
    :class:`PlanResult`, the objective used (None for direct pickers), the
    detected landmarks' scores if the edge rule computed them (else None) and
    the candidates they belong to (else None).

    ``detected`` (increasing field indices) are the landmarks the camera
    actually detects (truth pose; the same for every method); the candidates
    are those less ``exclude`` (the current landmark). If the planning
    geometry is degenerate (velocity not descending, zero velocity) or no
    interval is visible, the detected landmark nearest to the image centre is
    chosen and ``note`` says why (never a silent NaN).

    Edge rule (one rule for every metric): when the in-plane golden-section
    optimum lies on an end of its visible sub-interval (within ``tol_rad``),
    the metric's optimum is outside the image, the landmark nearest to that
    end need not be the best one in the image (it may sit at a corner), so
    every detected landmark is scored directly by the same metric
    (vectorised, ``objective.batch``) and the best is chosen (first index on
    ties); ``edge`` says so and the evaluations are counted. Otherwise the
    detected landmark nearest to the optimum's ground point is chosen
    (:func:`_pick_nearest`); only the edge rule needs the candidate list.
    """
    t0 = time.perf_counter_ns()
    if method in PICKERS:
        cand = _candidates(detected, exclude)
        k = -1 if cand.size == 0 else int(cand[PICKERS[method](field_, cand, state, camera, rng)])
        return PlanResult(method, k, math.nan, field_.xyz[k] if k >= 0 else np.full(3, np.nan),
                          math.nan, 0, time.perf_counter_ns() - t0), None, None, cand
    build = OBJECTIVES.get(method)
    if build is None:
        raise ValueError(f"unknown planning method {method!r}; available: {available_methods()}")
    note = ""
    best = (math.inf, math.nan, math.nan, math.nan)       # f, beta, interval ends
    n = 0
    fun = None
    try:
        geom = plane_geometry(state.r, state.v)
        intervals = (_visible_exact(geom, state.R_LtoB, camera, cfg.margin_px) if cfg.n_grid <= 0
                     else _visible_grid(geom, state.R_LtoB, camera, cfg.n_grid, cfg.margin_px))
        if intervals:                  # (visible_intervals, its dispatch inlined: timed path)
            fun = build(state, geom, cfg, camera, camera.sigma_b)
            for a, b in intervals:
                x, fx, k = golden_section(fun, a, b, cfg.tol_rad)
                n += k
                if fx < best[0] or math.isnan(best[1]):
                    best = (fx, x, a, b)
        else:
            note = "no visible interval"
    except DegenerateGeometry as exc:
        note = str(exc)
    if math.isnan(best[1]):
        # documented fallback: the detected landmark nearest the boresight
        point = state.r + state.R_LtoB.T @ camera.boresight_B * max(state.r[2], 1.0) / max(
            -(state.R_LtoB.T @ camera.boresight_B)[2], 1e-3)
        k = _pick_nearest(field_, point, detected, exclude)
        return PlanResult(method, k, math.nan, point, math.nan, n, time.perf_counter_ns() - t0,
                          note or "no finite objective"), fun, None, None
    fx, x, a, b = best
    gx, gy, gz = ground_point_scalar(geom)(x)
    point = np.array((gx, gy, gz))
    edge = min(x - a, b - x) <= cfg.tol_rad
    k = -1
    vals = cand = None
    if edge:
        cand = _candidates(detected, exclude)
        if cand.size:
            vals = fun.batch(field_.xyz[cand])
            n += int(cand.size)
            if np.isfinite(vals).any():
                k = int(cand[int(np.argmin(np.where(np.isfinite(vals), vals, np.inf)))])
    if k < 0:
        # (_pick_nearest with the point's floats: no numpy scalars on the timed path)
        k = field_.grid.nearest(gx, gy, detected, exclude)
    return PlanResult(method, k, x, point, fx, n, time.perf_counter_ns() - t0, note,
                      edge=bool(edge)), fun, vals, cand


# ----------------------------------------------------------------- batched planning
# The runs of a batched descent that need a new landmark at the same image are
# planned together: the same steps as :func:`_plan` (same picks), with the
# golden-section searches in lockstep, the objective evaluated for all runs at
# once, one KD-tree query for all runs. Not timed (planning time comes from
# replaying recorded inputs through :func:`plan`).

def golden_section_batch(fun: Callable[[np.ndarray, np.ndarray], np.ndarray], a, b, tol: float
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Many independent golden-section searches in lockstep: problem ``i`` on
    ``[a[i], b[i]]``; ``fun(i (m,), x (m,)) -> (m,)`` evaluates problems ``i`` at
    ``x``. Each problem runs exactly the iterations (and arithmetic) of
    :func:`golden_section` (masks: a problem stops when its bracket is shorter
    than ``tol``). Returns ``(x, f(x), n_evals)``, arrays (m,)."""
    a = np.array(a, float)
    b = np.array(b, float)
    if not (np.isfinite(a).all() and np.isfinite(b).all()) or np.any(b < a):
        raise ValueError("golden_section: bad interval")
    if not tol > 0:
        raise ValueError(f"golden_section: tolerance must be positive, got {tol}")
    m = a.size
    c = b - INVPHI * (b - a)
    d = a + INVPHI * (b - a)
    every = np.arange(m)
    fc = np.asarray(fun(every, c), float).copy()
    fd = np.asarray(fun(every, d), float).copy()
    n = np.full(m, 2, np.int64)
    act = np.flatnonzero((b - a) > tol)
    while act.size:
        left = fc[act] <= fd[act]
        il, ir = act[left], act[~left]
        b[il], d[il], fd[il] = d[il], c[il], fc[il]
        c[il] = b[il] - INVPHI * (b[il] - a[il])
        a[ir], c[ir], fc[ir] = c[ir], d[ir], fd[ir]
        d[ir] = a[ir] + INVPHI * (b[ir] - a[ir])
        f = np.asarray(fun(act, np.where(left, c[act], d[act])), float)
        fc[il] = f[left]
        fd[ir] = f[~left]
        n[act] += 1
        act = act[(b[act] - a[act]) > tol]
    use_c = fc <= fd
    return np.where(use_c, c, d), np.where(use_c, fc, fd), n


def _ground_points(beta, C, v_hat, w_hat, cd, gamma) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~opnav.landing.depth_error.ground_point_scalar` for many (plane, beta): points (m, 3) and a mask of
    the betas whose line of sight meets the ground."""
    alpha = np.where(beta > 0, math.pi - gamma, gamma)
    ab = np.abs(beta)
    s = np.sin(alpha + ab)
    ok = (beta != 0.0) & (alpha + ab < math.pi) & (s > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        dd = (cd * np.sin(alpha) / s)[:, None]
    cb, sb = np.cos(beta)[:, None], np.sin(beta)[:, None]
    return C + dd * (cb * v_hat + sb * w_hat), ok


class _Contexts:
    """The H baselines' per-run context (lander, attitude, known landmark) of a
    batch, for evaluating many candidates of many runs at once by the metrics
    module's closed-form structural singular values of H (eq. 14-18,
    ``metrics.structural_scores``: the scores of ``Metric.batch``'s fast path).
    Not ``Metric.batch`` itself: its per-pair layout (gathers of every (run,
    candidate) pair) costs 2-4x on the edge rule's runs x all detected landmarks
    (e.g. 10 x 7403) here, where the geometry broadcasts."""

    def __init__(self, states: PlanState, cfg: PlannerConfig, camera: Camera):
        self.r, self.R = states.r, states.R_LtoB
        self.p_known = np.asarray(cfg.p_known, float)
        self.min_range = metrics.MetricContext.trusted(states.r[0], states.v[0], states.R_LtoB[0],
                                                       self.p_known).min_range_m
        d1 = self.p_known - self.r
        rho1 = np.linalg.norm(d1, axis=1)
        self.bs_L = np.einsum("bji,j->bi", self.R, camera.boresight_B)      # R^T boresight
        self.known_ok = (rho1 > self.min_range) & (np.einsum("bi,bi->b", d1, self.bs_L) > 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.u = d1 / rho1[:, None]
            self.x = 1.0 / rho1

    def _valid(self, i, pts):
        d2 = pts - self.r[i]
        rho2 = np.sqrt(np.einsum("...k,...k->...", d2, d2))
        ok = (rho2 > self.min_range) & (np.einsum("...k,...k->...", d2, self.bs_L[i]) > 0.0)
        return d2, rho2, ok & self.known_ok[i]

    def closed_form(self, name: str, i, pts) -> np.ndarray:
        """Metric ``name`` (larger is better) of candidates ``pts`` (..., 3) of runs
        ``i`` (closed-form structural singular values; -inf where invalid)."""
        d2, rho2, ok = self._valid(i, pts)
        with np.errstate(divide="ignore", invalid="ignore"):
            w = d2 / rho2[..., None]
            u = self.u[i]
            cg = np.einsum("...k,...k->...", w, u)
            cr = cross(u, w)
            s2 = np.einsum("...k,...k->...", cr, cr)
            sc = metrics.structural_scores(name, self.x[i], 1.0 / rho2, cg, s2)
        return np.where(ok, sc, -np.inf)


def plan_batch(method: str, states: PlanState, camera: Camera, field_: LandmarkField,
               visible: Callable[[np.ndarray], np.ndarray], cfg: PlannerConfig,
               exclude: np.ndarray, rngs: list | None = None, detected: np.ndarray | None = None,
               diagnose: bool = True) -> list[PlanResult]:
    """:func:`plan` for a batch of runs seeing the same image: ``states`` holds
    arrays with a leading run axis (m, ...), ``exclude`` (m,) each run's current
    landmark (-1: none), ``rngs`` each run's picker stream. Returns one
    :class:`PlanResult` per run with the picks, optima, edge flags, evaluation
    counts and pick ratios of the per-call :func:`plan` (to round-off), and no
    timing (``time_ns = cpu_ns = 0``).

    The golden-section searches of all runs and sub-intervals run in lockstep
    (:func:`golden_section_batch`); the depth objective and the paper's H
    baselines are evaluated for all runs at once (other objectives run by run);
    the B-X1 metrics' searches evaluate the per-call path for all runs at
    once with its bits (:func:`_matrix_batch_objective`). The edge rule of
    every metric screens every detected landmark cheaply (the closed-form
    singular values for the H baselines, ``Metric.screen`` bounds for the
    others) and evaluates the explicit path only on those that can be within
    1e-6 of the best (the explicit scores are checked against their bounds on
    that shortlist; else all are evaluated, :func:`_shortlist`), which gives
    the same pick."""
    exclude = np.asarray(exclude, np.int64)
    m = exclude.size
    rngs = [None] * m if rngs is None else list(rngs)
    if detected is None:
        detected = np.flatnonzero(visible(field_.xyz))
    det = np.sort(np.asarray(detected, np.int64))
    pts = field_.xyz[det]
    candmask = det[None, :] != exclude[:, None]                 # (m, n_det)
    n_cand = candmask.sum(axis=1)

    def one(j):
        return PlanState(states.r[j], states.v[j], states.a[j], states.R_LtoB[j], states.P[j])

    if method in PICKERS:
        out = []
        for j in range(m):
            cand = det[candmask[j]]
            k = -1 if cand.size == 0 else int(cand[PICKERS[method](field_, cand, one(j), camera, rngs[j])])
            out.append(PlanResult(method, k, math.nan, field_.xyz[k] if k >= 0 else np.full(3, np.nan),
                                  math.nan, 0, 0))
        return out
    build = OBJECTIVES.get(method)
    if build is None:
        raise ValueError(f"unknown planning method {method!r}; available: {available_methods()}")
    notes = [""] * m
    G = _planes(states.r, states.v)
    for j in np.flatnonzero(~G["ok"]):          # the scalar raises the documented reason
        try:
            plane_geometry(states.r[j], states.v[j])
        except DegenerateGeometry as exc:
            notes[j] = str(exc)
    if method not in _VECTORISED:
        # objectives evaluated run by run: the per-call planner's own geometry, so
        # that flat objectives (mineig's plateau, decided by rounding) pick alike
        for j in np.flatnonzero(G["ok"]):
            g = plane_geometry(states.r[j], states.v[j])
            G["C"][j], G["v_hat"][j], G["w_hat"][j], G["cd"][j], G["gamma"][j] = (
                g.C, g.v_hat, g.w_hat, g.cd, g.gamma)
    owner, lo, hi = _intervals(G, states.R_LtoB, camera, cfg, scalar=method not in _VECTORISED)
    searched = np.zeros(m, bool)
    searched[owner] = True
    for j in np.flatnonzero(G["ok"] & ~searched):
        notes[j] = "no visible interval"
    funs = _LazyObjectives(build, one, G, cfg, camera)
    if method == "depth":
        G["b"], G["r_e"] = _depth_constants(states, cfg)
        for j in np.flatnonzero(searched & ~(G["b"] > 0)):
            try:                                # zero baseline: the objective says why
                funs[j]
            except DegenerateGeometry as exc:
                notes[j] = str(exc)
                searched[j] = False
        keep = searched[owner]
        owner, lo, hi = owner[keep], lo[keep], hi[keep]
    elif method not in _VECTORISED and owner.size:
        for j in np.flatnonzero(searched):
            funs[j]                             # build now (errors as the per-call planner)
    evaluate = _batch_objective(method, states, G, cfg, camera, funs)
    best_x = np.full(m, math.nan)
    best_f = np.full(m, math.inf)
    best_a = np.full(m, math.nan)
    best_b = np.full(m, math.nan)
    n_ev = np.zeros(m, np.int64)
    if owner.size:
        x, fx, ne = golden_section_batch(lambda i, bb: evaluate(owner[i], bb), lo, hi, cfg.tol_rad)
        for q in range(owner.size):            # intervals in order: the first, then a better one
            j = owner[q]
            n_ev[j] += ne[q]
            if fx[q] < best_f[j] or math.isnan(best_x[j]):
                best_x[j], best_f[j], best_a[j], best_b[j] = x[q], fx[q], lo[q], hi[q]
    found = ~np.isnan(best_x)
    point = np.full((m, 3), math.nan)
    if found.any():
        f = np.flatnonzero(found)
        point[f] = _ground_points(best_x[f], G["C"][f], G["v_hat"][f], G["w_hat"][f], G["cd"][f],
                                  G["gamma"][f])[0]
    edge = found & (np.minimum(best_x - best_a, best_b - best_x) <= cfg.tol_rad)
    pick = np.full(m, -1, np.int64)
    vals: list = [None] * m                  # per run: the scores behind its pick ratio
    ie = np.flatnonzero(edge & (n_cand > 0))
    if ie.size:
        exact, pos = _edge_scores(method, ie, states, G, cfg, camera, funs, pts, candmask)
        for j, (vv, pp) in zip(ie, zip(exact, pos)):
            n_ev[j] += n_cand[j]
            fin = np.isfinite(vv)
            if fin.any():
                pick[j] = det[pp[int(np.argmin(np.where(fin, vv, np.inf)))]]
            vals[j] = (vv, pp)
    # the nearest detected landmark to the ideal ground point (one KD-tree query)
    need = np.flatnonzero(pick < 0)
    if need.size:
        fb = need[~found[need]]
        if fb.size:                          # documented fallback: nearest the boresight
            bs = np.einsum("bji,j->bi", states.R_LtoB[fb], camera.boresight_B)
            point[fb] = states.r[fb] + bs * (np.maximum(states.r[fb, 2], 1.0)
                                            / np.maximum(-bs[:, 2], 1e-3))[:, None]
        pick[need] = _pick_nearest_batch(field_, point[need], det, cfg.knn, exclude[need])
    if diagnose:
        _pick_ratios(method, pick, vals, funs, searched, states, G, cfg, camera, pts, det, candmask)
    out = []
    for j in range(m):
        if found[j]:
            res = PlanResult(method, int(pick[j]), float(best_x[j]), point[j], float(best_f[j]),
                             int(n_ev[j]), 0, notes[j], edge=bool(edge[j]))
        else:
            res = PlanResult(method, int(pick[j]), math.nan, point[j], math.nan, int(n_ev[j]), 0,
                             notes[j] or "no finite objective")
        r = vals[j]
        if isinstance(r, float):
            res.pick_ratio = r
        out.append(res)
    return out


class _LazyObjectives:
    """Per run, the per-call planner's objective (``OBJECTIVES[method]``), built
    on first use: the batched paths need it only for some runs."""

    def __init__(self, build, state_of, G, cfg, camera):
        self._build, self._state_of, self._G, self._cfg, self._camera = build, state_of, G, cfg, camera
        self._funs: dict = {}

    def __getitem__(self, j):
        j = int(j)
        if j not in self._funs:
            G = self._G
            geom = PlaneGeometry(C=G["C"][j], v_hat=G["v_hat"][j], w_hat=G["w_hat"][j],
                                 cd=float(G["cd"][j]), gamma=float(G["gamma"][j]))
            self._funs[j] = self._build(state=self._state_of(j), geom=geom, cfg=self._cfg,
                                        camera=self._camera, sigma_b=self._camera.sigma_b)
        return self._funs[j]

    def ctx(self, j) -> metrics.MetricContext:
        """Run ``j``'s metric context (its objective's, if built)."""
        j = int(j)
        if j in self._funs:
            return self._funs[j].ctx
        return _metric_context(self._state_of(j), self._cfg, self._camera, self._camera.sigma_b)

    def ratio(self, j):
        """The method's pick-ratio rule (the same for every run)."""
        fun = next(iter(self._funs.values())) if self._funs else self[j]
        return fun.ratio


def _planes(r: np.ndarray, v: np.ndarray) -> dict:
    """:func:`~opnav.landing.depth_error.plane_geometry` for many runs (the same
    arithmetic): arrays C, v_hat, w_hat (m, 3), cd, gamma (m,) and ``ok`` (m,),
    False where the scalar function raises (zero velocity, lander not above
    the ground, velocity not descending)."""
    sp = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])
    ok = np.isfinite(sp) & (sp >= 1e-9) & (r[:, 2] > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = v / sp[:, None]
        ok &= a[:, 2] < 0
        nh = np.hypot(a[:, 0], a[:, 1])
        vert = nh < 1e-9                         # vertical velocity: the plane through {L} +x
        h0 = np.where(vert, 1.0, a[:, 0] / nh)
        h1 = np.where(vert, 0.0, a[:, 1] / nh)
        hv = h0 * a[:, 0] + h1 * a[:, 1]
        w = np.stack([h0 - hv * a[:, 0], h1 - hv * a[:, 1], -hv * a[:, 2]], axis=1)
        nw = np.sqrt(w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1] + w[:, 2] * w[:, 2])
        return {"C": r.copy(), "v_hat": a, "w_hat": w / nw[:, None], "cd": r[:, 2] / -a[:, 2],
                "gamma": np.arcsin(np.minimum(1.0, -a[:, 2])), "ok": ok}


def _intervals(G: dict, R_LtoB: np.ndarray, camera: Camera, cfg: PlannerConfig,
               scalar: bool = False):
    """The visible sub-intervals of every run with a plane (``G["ok"]``), in the
    per-run order of :func:`visible_intervals`: (owner run, lo, hi) arrays
    (``scalar``: by :func:`visible_intervals` run by run)."""
    rows = np.flatnonzero(G["ok"])
    if cfg.n_grid > 0 or scalar:                 # reference grid path, or run by run
        owner, lo, hi = [], [], []
        for j in rows:
            geom = PlaneGeometry(C=G["C"][j], v_hat=G["v_hat"][j], w_hat=G["w_hat"][j],
                                 cd=float(G["cd"][j]), gamma=float(G["gamma"][j]))
            for a, b in visible_intervals(geom, R_LtoB[j], camera, cfg.n_grid, cfg.margin_px):
                owner.append(j)
                lo.append(a)
                hi.append(b)
        return np.asarray(owner, np.int64), np.asarray(lo, float), np.asarray(hi, float)
    k = (camera.half_px - cfg.margin_px) / camera.focal_px
    if k <= 0 or not rows.size:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
    M = camera.R_BtoC @ R_LtoB[rows]
    A = np.einsum("mij,mj->mi", M, G["v_hat"][rows])
    Cc = np.einsum("mij,mj->mi", M, G["w_hat"][rows])
    gamma = G["gamma"][rows]
    pi = math.pi
    phis = np.stack([np.arctan2(k * Cc[:, 2] - Cc[:, 0], k * A[:, 2] - A[:, 0]),
                     np.arctan2(k * Cc[:, 2] + Cc[:, 0], k * A[:, 2] + A[:, 0]),
                     np.arctan2(k * Cc[:, 2] - Cc[:, 1], k * A[:, 2] - A[:, 1]),
                     np.arctan2(k * Cc[:, 2] + Cc[:, 1], k * A[:, 2] + A[:, 1]),
                     gamma - pi / 2], axis=1)
    phis.sort(axis=1)
    gaps = np.concatenate([np.diff(phis, axis=1), (phis[:, 0] + 2 * pi - phis[:, 4])[:, None]], axis=1)
    j = np.argmax(gaps, axis=1)
    fits = gaps[np.arange(rows.size), j] > pi          # else the centres do not fit in a half circle
    start = (j + 1) % 5
    # rotate to start at `start`; the wrapped centres get one turn (unwrap into one window)
    pos = (start[:, None] + np.arange(5)[None, :]) % 5
    un = np.take_along_axis(phis, pos, axis=1)
    un = np.where(pos < start[:, None], un + 2 * pi, un)
    b0, b1 = un[:, -1] - pi / 2, un[:, 0] + pi / 2
    mid = 0.5 * (b0 + b1)
    shift = 2 * pi * np.round((gamma - pi / 2 - mid) / (2 * pi))
    b0, b1 = b0 + shift + 1e-12, b1 + shift - 1e-12
    eps = 1e-9
    neg_lo, neg_hi = b0, np.minimum(b1, -eps)
    pos_lo, pos_hi = np.maximum(b0, eps), b1
    has_neg = fits & (b0 < 0) & (neg_hi > neg_lo)
    has_pos = fits & (b1 > 0) & (pos_hi > pos_lo)
    owner = np.concatenate([rows[has_neg], rows[has_pos]])
    lo = np.concatenate([neg_lo[has_neg], pos_lo[has_pos]])
    hi = np.concatenate([neg_hi[has_neg], pos_hi[has_pos]])
    order = np.argsort(owner, kind="stable")            # per run: the negative side first
    return owner[order], lo[order], hi[order]


def _depth_constants(states, cfg) -> tuple[np.ndarray, np.ndarray]:
    """Per run: baseline (m, eq. 19) and error radius (m, eq. 22) of the depth
    objective, for all runs at once."""
    from opnav.landing.depth_error import error_radius_batch

    h = 0.5 * cfg.t_s * cfg.t_s
    bvec = states.v * cfg.t_s + states.a * h
    b = np.sqrt(np.einsum("bi,bi->b", bvec, bvec))
    return b, error_radius_batch(states.P[:, 3:6, 3:6], cfg.t_s, cfg.n_sigma_v)


def _batch_objective(method, states, G, cfg, camera, funs) -> Callable:
    """``f(runs (n,), beta (n,)) -> (n,)``: the method's objective (minimised) at
    signed beta in each run's plane, for many runs at once."""
    if method == "depth":
        from opnav.landing.depth_error import depth_error_in_plane

        return lambda i, beta: depth_error_in_plane(beta, G["gamma"][i], G["cd"][i], G["b"][i],
                                                    G["r_e"][i])
    from opnav.landing.metrics import H_METRICS

    if method in H_METRICS:
        # the closed-form structural singular values of H (metrics module): the
        # explicit H + LAPACK path's values to ~1e-12 relative, at a fraction of
        # the cost (the per-call planner keeps the configured eval_path)
        score = _Contexts(states, cfg, camera).closed_form

        def f(i, beta):
            p, ok = _ground_points(beta, G["C"][i], G["v_hat"][i], G["w_hat"][i], G["cd"][i],
                                   G["gamma"][i])
            out = np.full(len(i), math.inf)
            if ok.any():
                out[ok] = -score(method, i[ok], p[ok])
            return out

        return f
    if method == "logdet_nav":
        # planned information of every run's ground point at once (each run's state)
        from opnav.landing.planned_info import planned_nav_logdet

        kw = dict(sigma_f=camera.sigma_b * cfg.noise_scale, depth_sigma_frac=cfg.depth_sigma_frac,
                  n_obs=cfg.obs_per_landmark, dt=cfg.t_s, g=cfg.g, oc=cfg.oc,
                  boresight_B=camera.boresight_B)
        p_known = np.asarray(cfg.p_known, float)

        def f(i, beta):
            p, ok = _ground_points(beta, G["C"][i], G["v_hat"][i], G["w_hat"][i], G["cd"][i],
                                   G["gamma"][i])
            out = np.full(len(i), math.inf)
            if ok.any():
                j = i[ok]
                out[ok] = -planned_nav_logdet(states.r[j], states.v[j], states.a[j], states.R_LtoB[j],
                                              states.P[j], p_known, p[ok], **kw)
            return out

        return f
    if method in metrics.METRIC_NAMES and cfg.eval_path == "matrix_scalar":
        return _matrix_batch_objective(_metric(method), funs)
    return lambda i, beta: np.array([funs[j](float(x)) for j, x in zip(i, beta)])


def _matrix_batch_objective(m: metrics.Metric, funs) -> Callable:
    """``f(runs, beta)`` of the per-call objective with ``eval_path =
    matrix_scalar`` for many runs at once, with its bits: each run's ground
    point by its own ``ground_point_scalar``, then ``Metric.batch(...,
    path="matrix")`` (H of eq. 14-18 for all pairs at once, the per-pair LAPACK
    of ``matrix_scalar``; tested bit-equal), so flat objectives (mineig's
    plateau, decided by rounding) search alike."""

    stacks: dict = {}          # per set of runs: their contexts stacked once, not per iteration

    def f(i, beta):
        out = np.full(len(i), math.inf)
        pts = [funs[j].ground(x) for j, x in zip(i.tolist(), beta.tolist())]
        k = [q for q, p in enumerate(pts) if p is not None]
        if k:
            runs = tuple(int(i[q]) for q in k)
            if runs not in stacks:
                stacks[runs] = metrics.stack_contexts([funs[j].ctx for j in runs])
            out[k] = -m.batch(stacks[runs], np.array([pts[q] for q in k])[:, None, :],
                              path="matrix")[:, 0]
        return out

    return f


#: objectives evaluated for many runs at once by :func:`_batch_objective`
_VECTORISED = ("depth", "svd", "gdop", "cond")
_SHORTLIST_RTOL = 1e-6      # candidates this close to the closed-form best get the explicit path
_AGREE_RTOL = _SHORTLIST_RTOL / 4   # screened vs explicit path on the shortlist, else all explicit


def _edge_scores(method, ie, states, G, cfg, camera, funs, pts, candmask):
    """Edge rule for runs ``ie``: per run, the scores (minimised) of its detected
    candidates that decide the pick and the positions (into the detected list)
    they belong to, in candidate order."""
    from opnav.landing.metrics import H_METRICS

    out_v, out_p = [], []
    if method == "depth":
        from opnav.landing.depth_error import depth_error_of_points

        allv = depth_error_of_points(pts, G["C"][ie], G["v_hat"][ie], G["b"][ie], G["r_e"][ie])
        for q, j in enumerate(ie):
            pp = np.flatnonzero(candmask[j])
            out_v.append(allv[q, pp])
            out_p.append(pp)
        return out_v, out_p
    if method in H_METRICS:
        cf = -_Contexts(states, cfg, camera).closed_form(method, ie[:, None], pts[None])
    m = _metric(method) if method in metrics.METRIC_NAMES else None
    out_v, out_p = [None] * len(ie), [None] * len(ie)
    single = []                # runs whose short list is one candidate (matrix path, below)
    for q, j in enumerate(ie):
        pp = np.flatnonzero(candmask[j])
        if m is None:          # no screening for this objective: every candidate explicitly
            out_v[q], out_p[q] = funs[j].batch(pts[pp]), pp
            continue
        f_lo, f_hi = (cf[q, pp], cf[q, pp]) if method in H_METRICS else funs[j].screen(pts[pp])
        sl = _shortlist(f_lo, f_hi)
        if sl is None:
            out_v[q], out_p[q] = funs[j].batch(pts[pp]), pp
        elif not sl.size:      # no valid candidate
            out_v[q], out_p[q] = np.full(pp.size, np.inf), pp
        elif sl.size == 1 and cfg.eval_path == "matrix_scalar":
            single.append((q, j, pp, f_lo[sl], f_hi[sl], sl))
        else:
            ex = funs[j].batch(pts[pp[sl]])
            out_v[q], out_p[q] = ((ex, pp[sl]) if _agree(ex, f_lo[sl], f_hi[sl])
                                  else (funs[j].batch(pts[pp]), pp))
    if single:
        # the explicit path (matrix_scalar, what fun.batch gives one candidate) of all
        # these runs' candidate at once: Metric.batch path="matrix", the same bits
        st = metrics.stack_contexts([funs.ctx(j) for _, j, *_ in single])
        cand = np.array([pts[pp[sl[0]]] for _, _, pp, _, _, sl in single])[:, None, :]
        ex = -m.batch(st, cand, path="matrix")[:, 0]
        for (q, j, pp, lo, hi, sl), e in zip(single, ex):
            e = np.array([e])
            out_v[q], out_p[q] = (e, pp[sl]) if _agree(e, lo, hi) else (funs[j].batch(pts[pp]), pp)
    return out_v, out_p


def _shortlist(f_lo, f_hi):
    """The edge rule's short list given screening bounds ``f_lo <= f <= f_hi``
    (minimised, every candidate; from :meth:`metrics.Metric.screen` or the
    closed form): the positions whose ``f_lo`` is within ``_SHORTLIST_RTOL``
    of the smallest ``f_hi`` (empty: no valid candidate; None: no finite upper
    bound, score every candidate)."""
    fin = np.isfinite(f_lo) | np.isfinite(f_hi)
    if not fin.any():
        return np.zeros(0, np.int64)
    top = np.min(np.where(np.isfinite(f_hi), f_hi, np.inf))
    if not np.isfinite(top):
        return None
    return np.flatnonzero(fin & (f_lo <= top + _SHORTLIST_RTOL * abs(top)))


def _agree(ex, f_lo, f_hi) -> bool:
    """Explicit scores within their screening bounds to ``_AGREE_RTOL`` (a
    quarter of the short-list margin, so no candidate left out could be
    better); else the caller scores every candidate explicitly."""
    tol = _AGREE_RTOL * np.abs(ex)
    return bool(np.all((ex >= f_lo - tol) & (ex <= f_hi + tol)))


def _pick_nearest_batch(field_: LandmarkField, points: np.ndarray, detected: np.ndarray,
                        knn: int, exclude: np.ndarray) -> np.ndarray:
    """:func:`_pick_nearest` for many ideal points (one KD-tree query for all
    of them, ``knn`` nearest each). Among a point's ``knn`` the detected ones
    (``detected``: increasing field indices) less its ``exclude`` are ranked
    by the bucket index's order (``dx*dx + dy*dy``, ties by the smaller
    index); a point whose best there is not clearly nearer than the farthest
    of its ``knn`` (relative 1e-12: the tree's own distances may round
    otherwise), or that has none, is answered by a brute-force search over the
    detected landmarks (``landmarks.nearest_brute_force``, the same order), so
    every pick is the per-call planner's."""
    points = np.asarray(points, float)
    n_field = len(field_.xyz)
    k = min(max(int(knn), 1), n_field)
    _, idx = field_.tree.query(points[:, :2], k=k)
    idx = np.asarray(idx).reshape(len(points), k)
    det = np.asarray(detected, np.int64)
    at = np.minimum(np.searchsorted(det, idx), max(det.size - 1, 0))
    ok = (det[at] == idx) & (idx != exclude[:, None]) if det.size else np.zeros(idx.shape, bool)
    dx = field_.xyz[idx, 0] - points[:, 0:1]
    dy = field_.xyz[idx, 1] - points[:, 1:2]
    d2 = dx * dx + dy * dy
    dm = np.where(ok, d2, np.inf)
    best = dm.min(axis=1)
    tie = ok & (dm == best[:, None])
    out = np.where(tie, idx, n_field).min(axis=1)
    sure = (best < d2.max(axis=1) * (1.0 - 1e-12)) | (k == n_field)
    out = np.where(ok.any(axis=1), out, -1)
    xy = field_.xyz[:, :2]
    for j in np.flatnonzero(~sure | (out < 0)):     # (brute force: no bucket index to build)
        out[j] = nearest_brute_force(xy, points[j, 0], points[j, 1], det,
                                     {int(exclude[j])} if exclude[j] >= 0 else ())
    return out.astype(np.int64)


#: metrics whose screening (:meth:`metrics.Metric.screen`) is cheaper than their
#: fastest explicit path: mineig (bounds, no 12 x 12 eigenproblem per candidate)
#: and the whitened ones (2 x 2 bounds, a 4 x 4 Gram near the best); for logdet the
#: screen is the fast path itself
_SCREEN_FIRST = ("mineig",) + tuple(metrics.WHITENED)


def _diagnostic_scores(method, fun, pts, pp, det, pick):
    """A search call's pick-ratio inputs: the fastest-path scores (``fun.diagnostic``,
    minimised) of the detected candidates ``pp`` (positions into ``det``) that
    decide it, with their positions: every candidate, or, for
    :data:`_SCREEN_FIRST` metrics, the screening short list (:func:`_shortlist`:
    it holds the best candidate) and the picked landmark, if the short list's
    scores agree with their bounds (:func:`_agree`; else every candidate). The
    best and the pick's score are the same numbers either way (each candidate's
    score does not depend on the others scored with it)."""
    diag = getattr(fun, "diagnostic", fun.batch)
    if method in _SCREEN_FIRST and hasattr(fun, "screen"):
        f_lo, f_hi = fun.screen(pts[pp])
        sl = _shortlist(f_lo, f_hi)
        if sl is not None and sl.size:
            at = np.flatnonzero(det[pp] == pick)
            sub = np.union1d(sl, at)                       # sorted: candidate order
            v = diag(pts[pp[sub]])
            in_sl = np.isin(sub, sl)
            if _agree(v[in_sl], f_lo[sub[in_sl]], f_hi[sub[in_sl]]):
                return v, pp[sub]
    return diag(pts[pp]), pp


def _pick_ratios(method, pick, vals, funs, searched, states, G, cfg, camera, pts, det, candmask) -> None:
    """Per run: the picked landmark's score over the best detected one's
    (``fun.ratio``), from the edge scores where the edge rule computed them,
    else every detected landmark scored by the method's fastest path; written
    into ``vals`` as floats (runs without a ratio keep None)."""
    from opnav.landing.metrics import H_METRICS

    m = len(pick)
    todo = [j for j in range(m) if searched[j] and pick[j] >= 0 and candmask[j].any()]
    fresh = [j for j in todo if vals[j] is None]
    scores = {}
    if fresh:
        rows = np.asarray(fresh)
        if method == "depth":
            from opnav.landing.depth_error import depth_error_of_points

            allv = depth_error_of_points(pts, G["C"][rows], G["v_hat"][rows], G["b"][rows],
                                         G["r_e"][rows])
        elif method in H_METRICS:
            allv = -_Contexts(states, cfg, camera).closed_form(method, rows[:, None], pts[None])
        else:
            allv = None
        if allv is not None:          # all runs at once: the best candidate and the pick's score
            fin = np.isfinite(allv) & candmask[rows]
            best = np.min(np.where(fin, allv, np.inf), axis=1)
            at = np.minimum(np.searchsorted(det, pick[rows]), det.size - 1)
            ok = (det[at] == pick[rows]) & candmask[rows, at]
            f_pick = np.where(ok, allv[np.arange(rows.size), at], np.nan)
            has = fin.any(axis=1)
            for q, j in enumerate(fresh):
                vals[j] = float(funs.ratio(j)(f_pick[q], best[q])) if has[q] else None
        else:
            for j in fresh:
                scores[j] = _diagnostic_scores(method, funs[j], pts, np.flatnonzero(candmask[j]),
                                               det, int(pick[j]))
    for j in todo:
        if isinstance(vals[j], float) or (vals[j] is None and j not in scores):
            continue
        v, pp = vals[j] if vals[j] is not None else scores[j]
        vals[j] = None
        fin = np.isfinite(v)
        if fin.any():
            hit = np.flatnonzero(det[pp] == pick[j])
            f_pick = v[hit[0]] if hit.size else math.nan
            vals[j] = float(funs.ratio(j)(f_pick, float(v[fin].min())))
    for j in range(m):
        if not isinstance(vals[j], float):
            vals[j] = None
