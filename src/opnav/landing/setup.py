"""The paper-B setup: the ``landing`` config section parsed once, at the edge, into frozen dataclasses.

Description
    :meth:`Setup.from_config` turns the (schema-validated) ``landing`` section, or the part of
    it a workflow rule passes as params, into a frozen :class:`Setup`: the descent (gravity,
    duration, initial state, guidance yaw and terminal acceleration), the IMU, the camera and
    its scenarios, the landmark field, the filter, the planner, the Monte Carlo, the timing
    replay, B-X1, the tuning, the equivalence test and a user's own methods. Everything below
    the edge (the scenario, the Monte Carlo, the tuning, the timing replay, the studies) takes
    the :class:`Setup`, never the raw dict; the workflow scripts, the CLI, the preflight and the
    tests parse (``opnav.core.sections``: a key the rule did not pass is
    :class:`~opnav.core.sections.Missing` and fails on first use naming it, unless its field
    has a default below).

    The workflow itself (the Snakefile's rules, their params and reuse digests) works on the
    config mapping: :func:`scenario_sections` is its camera-scenario merge, and
    :meth:`Setup.scenarios` the same for a parsed setup.

Units: as the config keys say (m, m/s, m/s^2, s, deg, px, Hz).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from opnav.core.sections import Missing, Pairs, Section, conversion, register

__all__ = ["Setup", "InitialState", "Imu", "CameraSettings", "NearSite", "Landmarks", "FilterSettings",
           "PlannerSettings", "Single", "Figures", "Bounds", "MonteCarloSettings", "TimingSettings", "Extra",
           "Tuning", "Equivalence", "scenario_sections", "Missing"]

_FROZEN = {"frozen": True, "kw_only": True}

#: ``tuning.candidates``: ((meas_noise_scale, iterations), ...)
Candidates = tuple
#: ``custom_methods``: the registered methods (``core.registry.CustomSpec``), in config order
CustomMethods = tuple


def _candidates(x) -> tuple:
    return tuple((float(s), int(i)) for s, i in x)


def _custom(x) -> tuple:
    from opnav.core import registry

    return tuple(registry.specs(x, "landing.custom_methods").values())


conversion("Candidates", _candidates)
conversion("CustomMethods", _custom)


@register
@dataclass(**_FROZEN)
class InitialState(Section):
    """``initial_state``: position (m), velocity (m/s) in {L} and the published attitude (deg)."""

    KEY = "landing.initial_state"
    r_m: tuple
    v_mps: tuple
    att_deg: tuple


@register
@dataclass(**_FROZEN)
class Imu(Section):
    """``imu``: rate (Hz) and white-noise 1-sigma per sample (m/s^2, deg/s)."""

    KEY = "landing.imu"
    rate_hz: float
    sigma_a_mps2: float
    sigma_w_degps: float


@register
@dataclass(**_FROZEN)
class CameraSettings(Section):
    """``camera`` (or a scenario's camera): square field of view (deg), detector (px), centroid
    noise 1-sigma (px), boresight tilt from body -z and its azimuth (deg); ``plan_margin_px``
    the camera's own planning margin (not a config key: 0)."""

    KEY = "landing.camera"
    fov_deg: float
    pixels: int
    sigma_px: float
    tilt_deg: float
    tilt_azimuth_deg: float
    plan_margin_px: float = 0.0

    def overlay(self, changes: Mapping) -> "CameraSettings":
        """This camera with a scenario's overlay (``landing.scenarios.<name>``) applied."""
        return self.replace(**{k: type(getattr(self, k))(v) for k, v in dict(changes or {}).items()})


@register
@dataclass(**_FROZEN)
class NearSite(Section):
    """``landmarks.near_site``: landmarks log-uniform in distance from the site (count 0: none)."""

    KEY = "landing.landmarks.near_site"
    count: int = 0
    r_min_m: float = 1.0


@register
@dataclass(**_FROZEN)
class Landmarks(Section):
    """``landmarks``: the uniform field (half width m, count, seed) and the near-site part."""

    KEY = "landing.landmarks"
    half_width_m: float
    count: int
    seed: int
    near_site: NearSite | None = None


@register
@dataclass(**_FROZEN)
class FilterSettings(Section):
    """``filter``: update period (s), the Fig. 3 strategy, the new landmark's depth 1-sigma
    (fraction), the vision cut-off (m), OC-EKF, iterations and the bearing-noise scale."""

    KEY = "landing.filter"
    dt_s: float
    obs_per_landmark: int
    depth_sigma_frac: float
    min_update_altitude_m: float
    update_altitude_margin_m: float
    observability_constrained: bool
    iterations: int
    meas_noise_scale: float


@register
@dataclass(**_FROZEN)
class PlannerSettings(Section):
    """``planner``: eps_v's sigmas (eq. 22), golden-section tolerance (rad), margin (px), path."""

    KEY = "landing.planner"
    n_sigma_v: float
    tol_rad: float
    margin_px: float
    eval_path: str


@register
@dataclass(**_FROZEN)
class Single(Section):
    """``single``: the method and run index of the single descent (B-F4, B-F5)."""

    KEY = "landing.single"
    method: str
    run_index: int


@register
@dataclass(**_FROZEN)
class Figures(Section):
    KEY = "landing.figures"
    f5_time_s: float


@register
@dataclass(**_FROZEN)
class Bounds(Section):
    """``mc.bounds``: initial errors uniform within +- these per axis (m, m/s, deg)."""

    KEY = "landing.mc.bounds"
    r_m: float
    v_mps: float
    att_deg: float


@register
@dataclass(**_FROZEN)
class MonteCarloSettings(Section):
    """``mc``: runs, job and batch sizes (speed only; ``batch_size`` 0 = a job's chunk), the
    methods, the seed, B-T3's converged threshold (m), the error bounds (B-C3's yaw ratio is the
    analysis plan's, its one home)."""

    KEY = "landing.mc"
    n_runs: int
    runs_per_job: int
    methods_per_job: int
    batch_size: int = 0
    methods: tuple[str, ...]
    base_seed: int
    converged_pos_err_m: float
    bounds: Bounds


@register
@dataclass(**_FROZEN)
class TimingSettings(Section):
    KEY = "landing.timing"
    max_calls: int
    n_replays: int
    max_calls_paper: int


@register
@dataclass(**_FROZEN)
class Extra(Section):
    """``extra`` (B-X1): the methods, the reference, runs per scenario, bootstrap, tie tolerance."""

    KEY = "landing.extra"
    methods: tuple[str, ...]
    reference: str
    n_runs: Pairs
    n_boot: int
    tie_rtol: float


@register
@dataclass(**_FROZEN)
class Tuning(Section):
    """``tuning``: the tuning runs' seed, count and method, the candidates (scale, iterations)
    and the retuned variant's points."""

    KEY = "landing.tuning"
    base_seed: int
    n_runs: int
    method: str
    candidates: Candidates
    retune_points: int = 0


@register
@dataclass(**_FROZEN)
class Equivalence(Section):
    """``equivalence``: the reference, the tested methods and the controls; ``alpha`` is no config
    key (each one-sided test's level is ``(1 - level) / 2`` of the analysis plan's one interval
    level: the caller sets it with ``replace``)."""

    KEY = "landing.equivalence"
    reference: str
    methods: tuple[str, ...]
    controls: tuple[str, ...]
    alpha: float


@dataclass(frozen=True, kw_only=True)
class Setup(Section):
    """Paper B's setup (module docstring); one field per ``landing`` key. ``scenarios``: name ->
    camera overlay, as ``((name, ((key, value), ...)), ...)``; ``custom_methods``: the user's
    registered methods (``core.registry.CustomSpec``, in the config's order)."""

    KEY = "landing"
    gravity_mps2: tuple
    duration_s: float
    initial_state: InitialState
    yaw_deg: float = 0.0
    terminal_accel_mps2: tuple | None = None
    imu: Imu
    camera: CameraSettings
    scenarios: Pairs
    headline_scenario: str | None = None
    custom_methods: CustomMethods = ()
    landmarks: Landmarks
    filter: FilterSettings
    planner: PlannerSettings
    single: Single
    figures: Figures
    mc: MonteCarloSettings
    timing: TimingSettings
    extra: Extra
    tuning: Tuning
    equivalence: Equivalence
    site: Pairs = ()

    @classmethod
    def from_config(cls, section: Mapping, key: str | None = None) -> "Setup":
        """Parse the ``landing`` section (or a rule's part of it); absent keys become
        :class:`Missing` unless their field has a default."""
        if isinstance(section, Setup):
            raise TypeError("landing setup: already parsed (pass the Setup itself)")
        if not isinstance(section, Mapping):
            raise TypeError(f"landing setup: expected the 'landing' config section, got {type(section).__name__}")
        return super().from_config(section, key)

    # ------------------------------------------------------------ camera scenarios
    def scenario_names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.scenarios) or ("default",)

    def headline(self) -> str:
        """The scenario the manuscript leads with (``headline_scenario``, else the first);
        ``ValueError`` naming ``landing.headline_scenario`` if it is not one of the scenarios."""
        names = self.scenario_names()
        head = self.headline_scenario
        if head is not None and head not in names:
            raise ValueError(f"landing.headline_scenario: {head!r} is not one of landing.scenarios "
                             f"({', '.join(names)})")
        return head or names[0]

    def scenarios_by_name(self) -> dict[str, "Setup"]:
        """The setup of every camera scenario (its camera overlaid on ``camera``), in config order."""
        self.headline()
        overlays = dict(self.scenarios) or {"default": {}}
        return {n: self.replace(camera=self.camera.overlay(o), scenarios=(), headline_scenario=None)
                for n, o in overlays.items()}

    def with_filter(self, **changes) -> "Setup":
        """This setup with ``filter`` keys changed (the tuning's candidates)."""
        return self.replace(filter=self.filter.replace(**changes))

    def with_seed(self, base_seed: int) -> "Setup":
        """This setup flying the runs of another seed stream (``mc.base_seed``)."""
        return self.replace(mc=self.mc.replace(base_seed=int(base_seed)))

    @property
    def custom_items(self) -> tuple[tuple[str, str], ...]:
        """``(name, path)`` of every registered method (``planner.PlannerConfig.custom``)."""
        return tuple((s.name, s.path) for s in self.custom_methods)


def scenario_sections(section: Mapping) -> dict[str, dict]:
    """The ``landing`` config mapping of every camera scenario (``landing.scenarios``: name ->
    overlay on ``landing.camera``), in config order; each holds the merged ``camera`` and no
    ``scenarios`` key. The workflow's form (rule params and their digests are mappings);
    :meth:`Setup.scenarios_by_name` is the parsed one. Raises ``ValueError`` naming
    ``landing.headline_scenario`` if it is not one of the scenarios."""
    scen = section.get("scenarios") or {"default": {}}
    head = section.get("headline_scenario")
    if head is not None and head not in scen:
        raise ValueError(f"landing.headline_scenario: {head!r} is not one of landing.scenarios "
                         f"({', '.join(scen)})")
    out = {}
    for name, overlay in scen.items():
        cfg = {k: v for k, v in section.items() if k not in ("scenarios", "headline_scenario")}
        cfg["camera"] = {**section["camera"], **(overlay or {})}
        out[name] = cfg
    return out
