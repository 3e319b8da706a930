"""The registry of paper B's planning methods: the built-in ones and a user's own selection
metric (``landing.custom_methods``), flown, timed, scored and plotted beside them.

Description
-----------
Every planning method has one :class:`Method` entry. Its ``family`` says how the planner
(``opnav.landing.planner.plan_one``) runs it:

* ``compiled``: a built-in objective with a compiled kind (``planning.layout.KINDS``: the
  depth error, the H baselines, B-X1's information baselines); the kernels are its fast path,
  ``planning.reference`` its paper path;
* ``picker``: a built-in direct pick without a search (``random``, ``center``, ``closest``:
  ``planner.PICKERS``);
* ``custom``: a user's score function, registered in the config by its import path. The
  planner runs the same call as for every method (plane, visible interval, golden-section
  search, edge rule, nearest detected landmark: ``planning.search.plan_core``'s source, run by
  the interpreter) with the user's function as the objective, at the ground points the search
  tries and, on the edge rule, at every detected landmark.

A user's metric
---------------
``landing.custom_methods`` maps a method name to its function::

    landing:
      custom_methods:
        parallax:
          path: examples/parallax.py:parallax_score   # or an importable module: mypkg.metrics:parallax_score
          label: max. parallax                          # legend and table name (default: the name)
          color: "#117733"                             # any matplotlib colour (default: from the name)

``path`` is ``module:function`` (a module on ``sys.path`` or under the checkout) or
``file.py:function`` (relative to the checkout's root, or absolute). The function takes ONE
argument, a :class:`Candidate`, and returns one real number, the score of that candidate:
LOWER IS BETTER (return ``-metric`` for a metric where larger is better); ``+inf`` marks a
candidate the metric refuses; NaN is an error. It may be a plain Python function or a
numba-compiled one (``numba.njit``; a :class:`Candidate` is a named tuple of float64 arrays
and floats, which numba takes as it is), in which case each evaluation runs compiled and the
planning-time replay names its path so (:func:`eval_path`).

Checked before any work (:func:`problems`, the workflow's preflight), one line naming the
method: the path imports and names a callable, the callable takes exactly one positional
argument, the name is no built-in method's, and a probe call on candidates of the scenario's
start (:func:`probe_candidates`: the estimate equal to the truth at t = 0, the prior
covariance of the Monte Carlo, the landing site and the boresight's ground point) returns a
finite real number without raising. A function that raises or returns NaN during the Monte
Carlo stops its job with a :class:`MethodError` naming the method, the run and the call
(``opnav.landing.descent``).

Units and frames: SI (m, m/s, m/s^2, rad); {L} the landing frame (the landing site at its
origin, z up, the ground z = 0), {B} the lander's body frame, {C} the camera frame (z the
boresight).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from opnav.core import registry
from opnav.core.registry import CHECKOUT, CustomSpec, MethodError
from opnav.landing.planning import layout
from opnav.landing.planning.candidate import Candidate

__all__ = ["Candidate", "Method", "MethodError", "CustomSpec", "BUILTIN", "PICKER_NAMES", "builtin_names",
           "specs", "spec_items", "load", "resolve", "get", "probe", "probe_candidates", "problems",
           "objective", "eval_path", "display", "labels", "colors", "source_files", "CHECKOUT"]

#: the config key of the registry
SECTION = "landing.custom_methods"
#: the built-in pickers (their functions are ``opnav.landing.planner.PICKERS``)
PICKER_NAMES = ("random", "center", "closest")


@dataclass(frozen=True)
class Method:
    """A planning method: its name, how the planner runs it (``family``: compiled | picker |
    custom), its legend name and colour (empty: the palette's, ``opnav.core.figures``), and for
    a custom method its import path and function (``compiled``: a numba dispatcher)."""

    name: str
    family: str
    label: str = ""
    color: str = ""
    path: str = ""
    fn: Callable | None = None
    compiled: bool = False

    @property
    def kind(self) -> int:
        """The compiled objective kind (``planning.layout.KINDS``); -1 for none."""
        return layout.KINDS.get(self.name, -1) if self.family == "compiled" else -1


#: the built-in methods: the compiled kinds, then the pickers
BUILTIN: dict[str, Method] = {**{m: Method(m, "compiled") for m in layout.KINDS},
                              **{m: Method(m, "picker") for m in PICKER_NAMES}}


def builtin_names() -> tuple[str, ...]:
    return tuple(BUILTIN)


# ---------------------------------------------------------------- the config's entries

def specs(custom_methods: Mapping | None) -> dict[str, CustomSpec]:
    """``landing.custom_methods`` (a mapping name -> ``{path, label, color}`` or name -> path)
    as :class:`CustomSpec` entries, in the config's order."""
    return registry.specs(custom_methods, SECTION)


def spec_items(custom_methods: Mapping | None) -> tuple[tuple[str, str], ...]:
    """``(name, path)`` of every registered method: the planner's hashable form of the registry
    (``planner.PlannerConfig.custom``)."""
    return tuple((s.name, s.path) for s in specs(custom_methods).values())


def load(spec: CustomSpec) -> Method:
    """The :class:`Method` of a registered metric: imported and its signature checked
    (:class:`MethodError`, one line naming the method)."""
    fn = registry.load_function(spec, BUILTIN, "opnav.landing.methods.Candidate")
    return Method(spec.name, "custom", spec.label, spec.color, spec.path, fn, registry.is_numba(fn))


@functools.lru_cache(maxsize=64)
def _loaded(name: str, path: str) -> Method:
    return load(CustomSpec(name, path, section=SECTION))


def resolve(name: str, custom: tuple = ()) -> Method | None:
    """The :class:`Method` called ``name``: a built-in one, or one of ``custom`` (``(name, path)``
    pairs, :func:`spec_items`), imported once per process; None if neither."""
    if name in BUILTIN:
        return BUILTIN[name]
    for n, path in custom:
        if n == name:
            return _loaded(n, path)
    return None


def get(name: str, custom: tuple = ()) -> Method:
    """:func:`resolve`, or ``ValueError`` naming the methods available."""
    m = resolve(name, custom)
    if m is None:
        raise ValueError(f"unknown planning method {name!r}; available: "
                         f"{builtin_names() + tuple(n for n, _ in custom)}")
    return m


# ---------------------------------------------------------------- scoring

def _score(method: Method, rec: Candidate) -> float:
    """The user's score of one candidate as a float (+inf allowed); :class:`MethodError` for an
    exception, NaN, -inf or a value that is not one real number."""
    key = f"landing.custom_methods.{method.name}"
    try:
        s = method.fn(rec)
    except Exception as exc:
        raise MethodError(f"{key}: {method.path} raised {registry.what(exc)}") from exc
    if isinstance(s, (bool, np.bool_)) or not isinstance(s, (int, float, np.integer, np.floating)):
        arr = np.asarray(s) if isinstance(s, np.ndarray) else None
        if arr is None or arr.shape != () or arr.dtype.kind not in "iuf":
            raise MethodError(f"{key}: {method.path} returned {type(s).__name__} {s!r:.60}, "
                              "not one real number")
    s = float(s)
    if math.isnan(s) or s == -math.inf:
        raise MethodError(f"{key}: {method.path} returned {s} (scores are finite, or +inf for a refused candidate)")
    return s


def candidate_record(state, cfg, camera) -> Candidate:
    """The :class:`Candidate` of a planning call (``planner.PlanState``, ``PlannerConfig``,
    ``Camera``) with ``p_L`` unset (NaN): :func:`objective` fills it per candidate."""
    f = lambda x: np.ascontiguousarray(x, np.float64)   # noqa: E731
    return Candidate(np.full(3, np.nan), f(state.r), f(state.v), f(state.a), f(state.R_LtoB),
                     f(0.5 * (np.asarray(state.P) + np.asarray(state.P).T)), f(cfg.p_known), f(camera.R_BtoC),
                     float(camera.sigma_b), float(cfg.noise_scale), float(cfg.t_s), int(cfg.obs_per_landmark))


def objective(method: Method, state, cfg, camera) -> tuple[Callable, Callable]:
    """``(f(beta, q), scores(q, xyz, cand))`` of a custom method for one planning call, as the
    interpreted search takes them (``planning.search.interpreted``): the user's score at the
    ground point of the line of sight at signed beta (eq. 26; +inf where it misses the ground)
    and at the landmarks ``xyz[cand]`` (the edge rule)."""
    from opnav.landing.planning.geometry import ground_point

    base = candidate_record(state, cfg, camera)

    def at(p) -> float:
        return _score(method, base._replace(p_L=np.array(p, np.float64)))

    def f(beta, q):
        hit, x, y, z = ground_point(beta, q)
        return at((x, y, z)) if hit else math.inf

    def scores(q, xyz, cand):
        return np.array([at(xyz[i]) for i in cand], float)

    return f, scores


def eval_path(name: str, cfg) -> str:
    """The path a method's planning call runs on under ``cfg`` (a ``PlannerConfig``), as the
    planning-time replay names it: ``cfg.eval_path`` for a built-in; for a custom method its
    path: a numba function on the compiled path runs the whole call compiled
    (``planning.custom``: ``custom (compiled search and score: examples/x.py:f)``), else the
    search is interpreted and the score compiled (numba) or interpreted
    (``custom (interpreted search, interpreted score: ...)``)."""
    m = resolve(name, getattr(cfg, "custom", ()))
    if m is None or m.family != "custom":
        return cfg.eval_path
    if m.compiled and cfg.eval_path == "compiled":
        return f"custom (compiled search and score: {m.path})"
    return f"custom (interpreted search, {'compiled' if m.compiled else 'interpreted'} score: {m.path})"


# ---------------------------------------------------------------- preflight

def probe_candidates(setup) -> list[Candidate]:
    """Candidates of the scenario's start for the probe call: the estimate equal to the truth at
    t = 0 (acceleration the truth's), the Monte Carlo's prior covariance (``mc.bounds``: uniform
    errors, variance bound^2 / 3; the landmark block dormant, 1e8 m^2), the base camera; the
    candidates the landing site and the ground point of the boresight (both in view at the start:
    ``landing.preflight``); ``setup``: the landing ``setup.Setup``."""
    from opnav.landing.camera import make_camera
    from opnav.landing.trajectory import nominal_truth

    tr = nominal_truth(setup, [0.0])
    cam = make_camera(setup.camera)
    b = setup.mc.bounds
    P = np.zeros((12, 12))
    P[:9, :9] = np.diag(np.repeat([b.r_m ** 2 / 3, b.v_mps ** 2 / 3, math.radians(b.att_deg) ** 2 / 3], 3))
    P[9:, 9:] = np.eye(3) * 1e8
    r, R = tr.r[0], tr.R_LtoB[0]
    bs_L = R.T @ cam.boresight_B
    ground = r + bs_L * (r[2] / -bs_L[2]) if bs_L[2] < 0 else np.array([0.0, 0.0, 0.0])
    ground[2] = 0.0
    fl = setup.filter
    base = Candidate(np.zeros(3), r.copy(), tr.v[0].copy(), tr.a[0].copy(), R.copy(), P, np.zeros(3),
                     cam.R_BtoC.copy(), float(cam.sigma_b), float(fl.meas_noise_scale), float(fl.dt_s),
                     int(fl.obs_per_landmark))
    return [base._replace(p_L=np.zeros(3)), base._replace(p_L=ground)]


def probe(method: Method, setup) -> None:
    """The probe call (module docstring): :class:`MethodError` if the function raises or a score
    is not finite."""
    key = f"landing.custom_methods.{method.name}"
    for rec in probe_candidates(setup):
        try:
            s = _score(method, rec)
        except MethodError as exc:
            raise MethodError(f"{exc} on the probe call (the start's estimate, candidate "
                              f"p_L = [{', '.join(f'{x:.6g}' for x in rec.p_L)}] m)") from exc
        if not math.isfinite(s):
            raise MethodError(f"{key}: {method.path} returned {s} on the probe call (candidate "
                              f"p_L = [{', '.join(f'{x:.6g}' for x in rec.p_L)}] m, in view at the start): "
                              "a probe score must be finite")


def problems(setup) -> list[str]:
    """One line per registered method of the landing ``setup.Setup`` that cannot be used (module
    docstring); [] if none is registered."""
    out = []
    for spec in setup.custom_methods:
        try:
            m = load(spec)
            probe(m, setup)
        except MethodError as exc:
            out.append(f"invalid config key '{spec.key}': {registry.strip_key(str(exc), spec.key)}")
    return out


# ---------------------------------------------------------------- display

def display(name: str, custom_methods: Mapping | None = None) -> tuple[str, str]:
    """``(legend name, colour)`` of a method: a custom method's ``label`` / ``color`` from the
    config (empty: the name, the palette's colour from the name); a built-in's empty strings
    (the plots' own names and the palette)."""
    s = specs(custom_methods).get(name)
    return (s.label or s.name, s.color) if s else ("", "")


def labels(custom_methods: Mapping | None) -> dict[str, str]:
    """name -> legend name of every registered method."""
    return {n: s.label or n for n, s in specs(custom_methods).items()}


def colors(custom_methods: Mapping | None) -> dict[str, str]:
    """name -> colour of every registered method that gives one."""
    return {n: s.color for n, s in specs(custom_methods).items() if s.color}


def source_files(custom_methods: Mapping | None) -> list[str]:
    """The files the registered methods' functions live in (``core.registry.source_files``)."""
    return registry.source_files(specs(custom_methods))
