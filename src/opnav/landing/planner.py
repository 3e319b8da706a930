"""Landmark planner: golden-section search over the visible interval, then the
nearest detected landmark (paper B sec. 2.2, eq. 26; SPEC B.3).

Description
-----------
Every method runs the SAME call (``planning.search.plan_core``); only the objective
(minimised over the signed angle beta between velocity and line of sight, in
the vertical plane holding the estimated velocity) differs:

1. the plane (``planning.geometry.plane``) and the visible interval: the betas whose line
   of sight meets the ground inside the field of view less the planning margin,
   under the *estimated* attitude (``planning.geometry.visible_interval``), split at beta
   = 0 (no parallax) into at most two sub-intervals;
2. a golden-section search (``planning.search.golden_section``, tolerance ``tol_rad``)
   on each; the better optimum wins (the first on exact ties);
3. beta* mapped to its ground point (eq. 26) and the landmark nearest to it
   (horizontal distance, exact ties to the smaller index) among those the image
   holds (``detected``) less the current one, however far;
4. edge rule: an optimum within ``tol_rad`` of an end of its sub-interval lies
   outside the image, so every detected landmark is scored by the objective and
   the best is picked by the tie rule (``planning.screens.best_index``: scores within
   ``planning.screens.TIE_RTOL`` = 1e-9 relative of the best are tied, the lowest
   landmark index wins); ``edge`` says so and the landmarks scored count as
   evaluations.

Degenerate geometry or no visible interval: the detected landmark nearest to
the boresight's ground point, ``note`` says why.

Methods (``opnav.landing.methods``, the registry): ``depth`` (eq. 23-25), the H baselines and
the B-X1 information baselines (``planning.layout.KINDS``) are compiled
(``planning.search.objective``); :data:`PICKERS` search nothing; a user's own metric
(``landing.custom_methods``, ``PlannerConfig.custom``) runs the same call's source through the
interpreter with its score as the objective (``methods.objective``), on either path.

Paths (``PlannerConfig.eval_path``): ``compiled`` (what a lander's computer would
run) and ``paper`` (the paper's definition through the same call's source run by
the interpreter, ``planning.search.interpreted``, with ``planning.reference.paper_objective``:
the law-of-sines depth error; H from CasADi and LAPACK's SVD / pseudo-inverse; the information
baselines in numpy);
timing replays both. One planner:
:func:`plan_batch` plans run by run with :func:`plan_one`; :func:`plan` is one
timed call of it.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from opnav.core.registry import what as _what
from opnav.landing import methods as registry, metrics
from opnav.landing.camera import Camera
from opnav.landing.landmarks import LandmarkField
from opnav.landing.planning import geometry, layout, reference, screens, search
from opnav.landing.planning.geometry import PlaneGeometry

__all__ = ["golden_section", "visible_intervals", "PlanState", "PlanResult", "PlannerConfig", "plan",
           "plan_one", "plan_batch", "compiled_kind", "compiled_call", "candidate_scores", "PICKERS", "PATHS",
           "available_methods", "alternative_path"]

PATHS = ("compiled", "paper")
#: candidates closer than this to the lander are invalid (m; ``planning.screens.candidate_ok``)
MIN_RANGE_M = 1e-6


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
    margin_px: float = 40.0          # planning margin inside the detector edge, px
    eval_path: str = "compiled"      # compiled | paper (module docstring)
    p_known: tuple = (0.0, 0.0, 0.0)  # known landmark (landing site), m
    # the filter's model, for the planned-information metric (logdet_nav, planning.reference)
    noise_scale: float = 1.0         # filter bearing noise / true pixel noise
    depth_sigma_frac: float = 0.1    # a new landmark's depth guess 1-sigma / depth
    obs_per_landmark: int = 3        # observations of a landmark (Fig. 3 strategy)
    oc: bool = True                  # observability-constrained updates
    g: tuple = (0.0, 0.0, -3.711)    # gravity in {L}, m/s^2 (the filter's transition)
    custom: tuple = ()               # the user's own methods: (name, import path) pairs (methods.spec_items)

    def __post_init__(self):
        if self.eval_path not in PATHS:
            raise ValueError(f"landing.planner.eval_path: unknown {self.eval_path!r}; expected one of {PATHS}")


@dataclass(slots=True)
class PlanResult:
    method: str
    index: int                 # chosen landmark (field index), -1 if none
    beta: float                # signed beta*, rad (nan if no search)
    ground: np.ndarray         # ideal ground point, m
    objective: float           # objective at beta* (minimised)
    n_evals: int               # objective evaluations (edge rule: + landmarks scored)
    time_ns: int               # wall time of the planning call (plan: perf_counter_ns; else 0)
    note: str = ""
    cpu_ns: int = 0            # not measured by the call (timing.replay reads the CPU clock)
    edge: bool = False         # optimum on an end of the visible interval (edge rule)
    pick_ratio: float = math.nan  # picked landmark's metric / best detected one's (>= 1)


def alternative_path(cfg: PlannerConfig) -> PlannerConfig:
    """``cfg`` on the other evaluation path (compiled <-> paper), for timing both."""
    return dataclasses.replace(cfg, eval_path="paper" if cfg.eval_path == "compiled" else "compiled")


def golden_section(fun: Callable[[float], float], a: float, b: float, tol: float
                   ) -> tuple[float, float, int]:
    """``planning.search.golden_section`` of a Python function ``fun(x)`` on [a, b]:
    ``(x, f(x), n_evals)``. Raises ``ValueError`` for a bad interval or tolerance."""
    if not (math.isfinite(a) and math.isfinite(b)) or b < a:
        raise ValueError(f"golden_section: bad interval [{a}, {b}]")
    if not tol > 0:
        raise ValueError(f"golden_section: tolerance must be positive, got {tol}")
    return search.interpreted(search.golden_section, objective=lambda x, q: fun(x))(None, a, b, tol)


def _kfov(camera: Camera, margin_px: float) -> float:
    return (camera.half_px - margin_px) / camera.focal_px


def visible_intervals(geom: PlaneGeometry, R_LtoB: np.ndarray, camera: Camera,
                      margin_px: float) -> list[tuple[float, float]]:
    """Sub-intervals of signed beta (rad) whose lines of sight meet the ground
    inside the field of view (estimated attitude), split at 0 (``planning.geometry.visible_interval``)."""
    n, *e = geometry.visible_interval(geom.q, camera.R_BtoC @ np.asarray(R_LtoB, float),
                               _kfov(camera, margin_px))
    return [(e[0], e[1]), (e[2], e[3])][:n]


# ----------------------------------------------------------------- objectives

def _ratio(method: str) -> Callable[[float, float], float]:
    """Picked / best (>= 1) of the minimised objective f: f_pick / f_best for the
    depth error, m_best / m_pick for a metric (f = -m), the ratio of determinants
    exp(f_pick - f_best) for a log metric."""
    if method == "depth":
        return lambda fp, fb: fp / fb
    if method not in registry.BUILTIN:        # a user's score has no scale: no ratio
        return lambda fp, fb: math.nan
    if method in ("logdet", "logdet_nav"):
        return lambda fp, fb: math.exp(fp - fb)
    return lambda fp, fb: fb / fp


def _metric_context(state: PlanState, cfg: PlannerConfig, camera: Camera) -> metrics.MetricContext:
    """The metrics' context of a planning state (bearing noise sigma_b^2 I, rad^2)."""
    return metrics.MetricContext(r_L=state.r, v_L=state.v, R_LtoB=state.R_LtoB,
                                 p_known_L=np.asarray(cfg.p_known, float), P=0.5 * (state.P + state.P.T),
                                 R_meas=camera.sigma_b ** 2 * np.eye(6), boresight_B=camera.boresight_B,
                                 min_range_m=MIN_RANGE_M)


def _paper_objective(method: str, state: PlanState, cfg: PlannerConfig, camera: Camera, q: np.ndarray):
    """``reference.paper_objective`` of this state (the H baselines' context made on demand)."""
    return reference.paper_objective(method, state, cfg, camera, q, lambda: _metric_context(state, cfg, camera))


# ----------------------------------------------------------------- planning

_CACHE: dict = {}


def _setup(field_: LandmarkField, cfg: PlannerConfig, camera: Camera):
    """Per (field, config, camera), built once: the field's landmarks, the
    compiled call's constant vector (``planning.search.plan_run``, with the field's bucket
    grid) and the grid's buckets (``planning.screens.field_grid``)."""
    key = (id(field_), id(cfg), id(camera))
    if key not in _CACHE:
        xyz = np.ascontiguousarray(field_.xyz, float)
        grid, cells = screens.field_grid(xyz)
        c = np.concatenate([[cfg.t_s, cfg.n_sigma_v, cfg.tol_rad, _kfov(camera, cfg.margin_px), MIN_RANGE_M],
                            camera.R_BtoC.ravel(), camera.boresight_B, cfg.p_known, grid, [camera.sigma_b],
                            [cfg.noise_scale, cfg.depth_sigma_frac, cfg.obs_per_landmark, float(cfg.oc)], cfg.g])
        _CACHE[key] = (field_, cfg, camera, xyz, c, cells)
    return _CACHE[key][3:]


def plan_one(method: str, state: PlanState, camera: Camera, field_: LandmarkField, cfg: PlannerConfig,
             exclude: int, detected: np.ndarray, rng: np.random.Generator | None = None
             ) -> tuple[PlanResult, np.ndarray]:
    """One planning call (module docstring): ``(PlanResult, q)`` with ``q`` the
    call's per-run constants (``planning.layout.NQ``). ``detected``: sorted int64 field
    indices of the landmarks the image holds; ``exclude``: the current landmark
    (-1: none)."""
    kind = compiled_kind(method, cfg)
    entry = registry.get(method, cfg.custom)
    if entry.family == "picker":
        cand = detected[detected != exclude]
        k = -1 if cand.size == 0 else int(cand[PICKERS[method](field_, cand, state, camera, rng)])
        return PlanResult(method, k, math.nan, field_.xyz[k] if k >= 0 else np.full(3, np.nan),
                          math.nan, 0, 0), None
    xyz, c, cells = setup = _setup(field_, cfg, camera)
    if kind == OWN_COMPILED:          # a user's numba metric: the call compiled with it (planning.custom)
        args = _own_args(state, setup, exclude, detected)
        _run_own(entry, args)
        work = args[-1]
    elif kind >= 0:
        args = _kernel_args(kind, state, setup, exclude, detected)
        search.plan_run(*args)
        work = args[-1]
    else:
        work = np.empty(layout.NQ + layout.NOUT)
    q, out = work[:-layout.NOUT], work[-layout.NOUT:]
    if kind < 0:
        st = geometry.plane(state.r, state.v, q)
        if st == layout.OK and entry.family == "custom":
            f, scores = registry.objective(entry, state, cfg, camera)
        elif st == layout.OK:
            f, scores, st = _paper_objective(method, state, cfg, camera, q)
        if st == layout.OK:
            pick = search.interpreted(search.edge_pick,
                                      score_points=lambda q, xyz, cand: np.asarray(scores(q, xyz, cand), float))
            core = search.interpreted(search.plan_core, edge_pick=pick,
                                      golden_section=search.interpreted(search.golden_section, objective=f))
            core(q, camera.R_BtoC @ state.R_LtoB, c[layout.C_KFOV], c[layout.C_TOL], xyz, detected, exclude,
                 c[layout.C_GRID:layout.C_GRID + layout.NG], cells, out)
        else:
            out[layout.O_NEVAL], out[layout.O_STATUS] = 0, st
    o = out.tolist()
    if o[layout.O_STATUS] != layout.OK:      # documented fallback: the detected landmark nearest the boresight
        bs = state.R_LtoB.T @ camera.boresight_B
        point = state.r + bs * max(state.r[2], 1.0) / max(-bs[2], 1e-3)
        grid = c[layout.C_GRID:layout.C_GRID + layout.NG]
        k = screens.nearest(point[0], point[1], xyz, detected, exclude, grid, cells)
        return PlanResult(method, int(k), math.nan, point, math.nan, int(o[layout.O_NEVAL]), 0,
                          layout.REASONS[int(o[layout.O_STATUS])]), q
    L = layout
    return PlanResult(method, int(o[L.O_PICK]), o[L.O_BETA], out[L.O_XYZ:L.O_XYZ + 3], o[L.O_F],
                      int(o[L.O_NEVAL]), 0, "", 0, o[L.O_EDGE] > 0), q


#: :func:`compiled_kind` of a user's numba-compiled metric on the compiled path (``planning.custom``)
OWN_COMPILED = 1000


def compiled_kind(method: str, cfg: PlannerConfig) -> int:
    """The compiled objective kind of ``method`` on ``cfg``'s path (``planning.layout.KINDS``;
    :data:`OWN_COMPILED` for a user's numba-compiled metric); -1: none."""
    if cfg.eval_path != "compiled":
        return -1
    kind = layout.KINDS.get(method, -1)
    if kind < 0 and cfg.custom:
        entry = registry.resolve(method, cfg.custom)
        if entry is not None and entry.family == "custom" and entry.compiled:
            return OWN_COMPILED
    return kind


def _own_args(state: PlanState, setup: tuple, exclude: int, detected: np.ndarray) -> tuple:
    """``planning.custom.plan_run``'s arguments but the function (``work`` last)."""
    from opnav.landing.planning import custom

    xyz, c, cells = setup
    return (layout.estimate_arg(state.r, state.v, state.a, state.R_LtoB, state.P), c, xyz, detected, exclude,
            cells, np.empty(custom.work_size()))


def _run_own(entry, args) -> None:
    """The compiled call of a user's numba metric; :class:`methods.MethodError` naming it if it
    raised or scored NaN (as the interpreted path does)."""
    from opnav.landing.planning import custom

    key = f"{registry.SECTION}.{entry.name}"
    try:
        custom.plan_run(entry.fn, *args)
    except Exception as exc:
        raise registry.MethodError(f"{key}: {entry.path} raised {_what(exc)} "
                                   "(compiled planning call)") from exc
    n = args[-1][custom.X_NAN]
    if n:
        raise registry.MethodError(f"{key}: {entry.path} returned nan or -inf ({int(n)} of the call's scores; "
                                   "scores are finite, or +inf for a refused candidate)")


def _kernel_args(kind: int, state: PlanState, setup: tuple, exclude: int, detected: np.ndarray) -> tuple:
    """``planning.search.plan_run``'s arguments for one call (``setup``: :func:`_setup`'s; ``work`` last: q,
    then out)."""
    xyz, c, cells = setup
    return (kind, layout.estimate_arg(state.r, state.v, state.a, state.R_LtoB, state.P), c, xyz, detected, exclude,
            cells, np.empty(layout.work_size(c[layout.C_NOBS])))


def compiled_call(method: str, state: PlanState, camera: Camera, field_: LandmarkField, cfg: PlannerConfig,
                  exclude: int, detected: np.ndarray) -> Callable[[], None] | None:
    """The compiled planning call as a lander's computer runs it, for timing: a function of no
    argument that runs ``planning.search.plan_run`` on these inputs (the whole call: plane, visible
    interval, searches, edge rule, nearest landmark; numba's argument dispatch included), without
    the Python wrapper of :func:`plan_one` around it (the per-field constants, the
    ``PlanResult`` the Monte Carlo keeps, the degenerate-geometry fallback). None if ``method``
    has no compiled kind on ``cfg``'s path. ``detected``: sorted int64 field indices."""
    kind = compiled_kind(method, cfg)
    if kind < 0:
        return None
    setup = _setup(field_, cfg, camera)
    if kind == OWN_COMPILED:
        from opnav.landing.planning import custom

        entry = registry.get(method, cfg.custom)
        return functools.partial(custom.build(entry.fn), *_own_args(state, setup, int(exclude),
                                                                  np.asarray(detected, np.int64)))
    return functools.partial(search.plan_run, *_kernel_args(kind, state, setup, int(exclude),
                                                       np.asarray(detected, np.int64)))


def candidate_scores(method: str, state: PlanState, camera: Camera, field_: LandmarkField,
                     cfg: PlannerConfig, q: np.ndarray, cand: np.ndarray) -> np.ndarray:
    """The objective (minimised) of landmarks ``cand`` (field indices) at the call
    with per-run constants ``q`` (:func:`plan_one`): the edge rule's scores."""
    xyz = _setup(field_, cfg, camera)[0]
    if 0 <= compiled_kind(method, cfg) != OWN_COMPILED:
        return search.score_points(q, xyz, cand)
    entry = registry.get(method, cfg.custom)
    if entry.family == "custom":
        return registry.objective(entry, state, cfg, camera)[1](q, xyz, cand)
    return _paper_objective(method, state, cfg, camera, q)[1](q, xyz, cand)


def _diagnose(res: PlanResult, q, state, camera, field_, cfg, detected, exclude) -> None:
    """``res.pick_ratio``: the picked landmark's score over the best detected one's (a user's
    own metric has none: its score has no scale)."""
    if res.method not in registry.BUILTIN:
        return
    cand = detected[detected != exclude]
    if res.index < 0 or not cand.size or not math.isfinite(res.beta):
        return
    vals = candidate_scores(res.method, state, camera, field_, cfg, q, cand)
    fin = np.isfinite(vals)
    if fin.any():
        at = np.searchsorted(cand, res.index)
        f_pick = vals[at] if at < cand.size and cand[at] == res.index else math.nan
        res.pick_ratio = float(_ratio(res.method)(f_pick, float(vals[fin].min())))


def plan(method: str, state: PlanState, camera: Camera, field_: LandmarkField,
         visible: Callable[[np.ndarray], np.ndarray] | None, cfg: PlannerConfig,
         exclude=frozenset(), rng: np.random.Generator | None = None,
         detected: np.ndarray | None = None, diagnose: bool = True) -> PlanResult:
    """One planning call (:func:`plan_one`) with its wall time (``time_ns``,
    ``perf_counter_ns``; CPU time is read around it by ``timing.replay``).
    ``detected``: the image's feature list (sorted field indices), computed from
    ``visible`` if not given (not planning work: outside the clock, as is the
    ``pick_ratio`` diagnostic). ``exclude``: a set of at most one landmark."""
    if detected is None:
        detected = np.flatnonzero(visible(field_.xyz))
    ex = next(iter(exclude), -1) if exclude else -1
    det = np.asarray(detected, np.int64)
    t0 = time.perf_counter_ns()
    res, q = plan_one(method, state, camera, field_, cfg, ex, det, rng)
    res.time_ns = time.perf_counter_ns() - t0
    if diagnose and q is not None:
        _diagnose(res, q, state, camera, field_, cfg, det, ex)
    return res


def plan_batch(method: str, states: PlanState, camera: Camera, field_: LandmarkField,
               visible: Callable[[np.ndarray], np.ndarray] | None, cfg: PlannerConfig,
               exclude: np.ndarray, rngs: list | None = None, detected: np.ndarray | None = None,
               diagnose: bool = True) -> list[PlanResult]:
    """:func:`plan_one` for a batch of runs seeing the same image: ``states`` holds
    arrays with a leading run axis (m, ...), ``exclude`` (m,) each run's current
    landmark (-1: none), ``rngs`` each run's picker stream. No timing (``time_ns`` 0)."""
    exclude = np.asarray(exclude, np.int64)
    rngs = [None] * exclude.size if rngs is None else list(rngs)
    if detected is None:
        detected = np.flatnonzero(visible(field_.xyz))
    det = np.sort(np.asarray(detected, np.int64))
    out = []
    for j in range(exclude.size):
        st = PlanState(states.r[j], states.v[j], states.a[j], states.R_LtoB[j], states.P[j])
        try:
            res, q = plan_one(method, st, camera, field_, cfg, int(exclude[j]), det, rngs[j])
            if diagnose and q is not None:
                _diagnose(res, q, st, camera, field_, cfg, det, int(exclude[j]))
        except registry.MethodError as exc:
            exc.batch_position = j        # which run of the batch: the descent names it
            raise
        out.append(res)
    return out


def _pick_random(field_, cand, state, camera, rng) -> int:
    """A detected landmark drawn uniformly (the run's own picker stream)."""
    if rng is None:
        raise ValueError("the 'random' planner needs a random generator")
    return int(rng.integers(len(cand)))


def _pick_center(field_, cand, state, camera, rng) -> int:
    """The detected landmark nearest the image centre (estimated attitude)."""
    d = (field_.xyz[cand] - state.r) @ state.R_LtoB.T
    return int(np.argmax((d @ camera.boresight_B) / np.linalg.norm(d, axis=1)))


def _pick_closest(field_, cand, state, camera, rng) -> int:
    """The detected landmark nearest the estimated lander by range (m): no search,
    no metric; exact ties to the smaller field index. The control that tells how
    much of a metric's edge is picking a close landmark."""
    d = field_.xyz[cand] - state.r
    return int(np.argmin(np.einsum("ij,ij->i", d, d)))


#: method name -> direct picker without search: f(field, candidate indices (k,),
#: state, camera, rng) -> chosen position in the candidates (B-X1 baselines and
#: the equivalence test's negative controls)
PICKERS: dict[str, Callable] = {"random": _pick_random, "center": _pick_center,
                                "closest": _pick_closest}
#: methods with a search: the compiled kinds, the metrics, the planned information
OBJECTIVE_METHODS = tuple(layout.KINDS)
assert tuple(PICKERS) == registry.PICKER_NAMES and registry.builtin_names() == OBJECTIVE_METHODS + tuple(PICKERS)


def available_methods(cfg: PlannerConfig | None = None) -> tuple[str, ...]:
    """The built-in methods (``methods.BUILTIN``), then ``cfg``'s own (``PlannerConfig.custom``)."""
    return registry.builtin_names() + tuple(n for n, _ in (cfg.custom if cfg is not None else ()))
