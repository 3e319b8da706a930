"""The paper-A setup: the ``approach`` config section parsed once, at the edge, into frozen dataclasses.

Description
    :meth:`Setup.from_config` turns the (schema-validated) ``approach`` section,
    or the part of it a workflow rule passes as params, into a frozen
    :class:`Setup`: the scenario geometry (Mars elements, approach geometry,
    initial error, roll), the camera and the noise (prior sigmas, process
    noise, pixel errors), the segments, the EM settings, the seeds and the
    settings of the alternatives, studies and peers. Everything below the
    edge (scripts, the CLI, the studies) takes the :class:`Setup`, never the
    raw dict.

    A rule passes only the keys it uses (PyPSA-Eur style). A key it did not
    pass is held as :class:`Missing`, which fails on first use with one line
    naming the key, so a rule whose params lack a key it needs stops at once
    instead of falling back on a default.

    The config is parsed once, at the edge (a workflow script, the CLI, a test's
    :meth:`Setup.from_config`): every function of the package takes the :class:`Setup`,
    none the raw section.
Units: as the config keys say (km, km/s, s, arcsec, px, rad where named).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from .dynamics import KeplerElements


class Missing:
    """A config key the rule did not pass: any use raises one line naming it."""

    def __init__(self, key: str):
        object.__setattr__(self, "_key", key)

    def _fail(self, *_a, **_k):
        raise KeyError(f"approach.{object.__getattribute__(self, '_key')}: not among this rule's params "
                       "(add the key to the rule's params)")

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        self._fail()

    __iter__ = __len__ = __index__ = __int__ = __float__ = __getitem__ = __bool__ = _fail

    def __eq__(self, other):
        return isinstance(other, Missing) and other._key == self._key

    def __hash__(self):
        return hash(("Missing", self._key))

    def __repr__(self):
        return f"Missing({self._key!r})"

    def __reduce__(self):
        return (Missing, (self._key,))


def _tuple(x) -> tuple:
    return tuple(float(v) for v in x)


#: How a field's annotation converts its config value (nested sections: their class name).
_CONVERT = {"float": float, "int": int, "str": str, "bool": bool, "tuple": _tuple,
            "tuple[str, ...]": lambda v: tuple(str(x) for x in v)}


class _Section:
    """A frozen config section: :meth:`from_config` converts each key by its field's annotation."""

    @classmethod
    def from_config(cls, c: Mapping):
        kw = {}
        for f in dataclasses.fields(cls):
            conv = _CONVERT.get(f.type) or globals()[f.type].from_config
            kw[f.name] = conv(c[f.name])
        return cls(**kw)

    def as_dict(self) -> dict:
        """The section as the config holds it (for reports and JSON)."""
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class ApproachGeometry(_Section):
    """``geometry``: hyperbolic approach from ``range_km`` with ``v_inf_kms`` along ``v_inf_dir``."""

    range_km: float
    v_inf_kms: float
    aim_offset_km: float
    v_inf_dir: tuple


@dataclass(frozen=True)
class InitialError(_Section):
    """``initial_error``: the paper's fixed initial error (km, km/s) and the mode (fixed / sampled)."""

    r_km: tuple
    v_kms: tuple
    mode: str

    @property
    def e_fixed(self) -> np.ndarray:
        """Prior mean minus truth at t0 (6,), km and km/s."""
        return np.concatenate([self.r_km, self.v_kms]).astype(float)


@dataclass(frozen=True)
class PriorSigma(_Section):
    """``prior_sigma``: 1-sigma of the prior on position (km) and velocity (km/s) per axis."""

    r_km: float
    v_kms: float

    @property
    def P0(self) -> np.ndarray:
        """Prior covariance at t0 (6, 6), km^2 and (km/s)^2."""
        return np.diag(np.r_[np.full(3, self.r_km ** 2), np.full(3, self.v_kms ** 2)])


@dataclass(frozen=True)
class Camera(_Section):
    """``camera``: pixel size (arcsec), detector size (px), 3-sigma pixel errors of
    (centroid x, centroid y, radius), the radius/centroid error ratio of the pixel sweep, the
    attitude knowledge of each Mars image (1-sigma per axis, arcsec, independent per image; 0:
    known exactly, paper A's eq. 3) and the values of its bound study (arcsec)."""

    ifov_arcsec: float
    pixels: int
    sigma3_px: tuple
    radius_to_centroid_ratio: float
    attitude_sigma_arcsec: float
    attitude_study_arcsec: tuple

    def pixel_errors(self, centroid_px: float) -> tuple:
        """3-sigma (x, y, radius) errors for a centroid error, with the configured ratio."""
        return (float(centroid_px), float(centroid_px), self.radius_to_centroid_ratio * float(centroid_px))


@dataclass(frozen=True)
class Roll(_Section):
    """``roll``: the camera's roll about its boresight in the ``roll`` variant."""

    rate_deg_s: float
    steps_deg: tuple
    step_interval_s: float


@dataclass(frozen=True)
class Stars(_Section):
    """``stars``: star images every ``every_K`` samples, up to ``per_image`` brightest Hipparcos
    stars to ``mag_limit``, the star-mode slew (deg), the centroid 1-sigma (px) at
    ``sigma_ref_mag`` and its floor (px), the per-image attitude-knowledge 1-sigma and the
    star-mode / Mars-mode drift 1-sigma (arcsec per axis), and the stars study's sweeps (stars
    per image, each made real by its magnitude limit and field; per-image attitude knowledge)."""

    every_K: int
    per_image: int
    mag_limit: float
    slew_deg: float
    sigma_px: float
    sigma_ref_mag: float
    sigma_floor_px: float
    attitude_sigma_arcsec: float
    mode_drift_arcsec: float
    study_count: tuple
    study_attitude_sigma_arcsec: tuple


@dataclass(frozen=True)
class NavFloor(_Section):
    """``nav_floor``: the navigation error against arc length (A-C7's would_take): the variant and
    EM scheme (``growing-squarem``, ``plain``, ...) it is measured for, and the arc lengths, s."""

    variant: str
    scheme: str
    arcs_s: tuple


@dataclass(frozen=True)
class RollRateStudy(_Section):
    """``roll_rate_study``: roll rates of the bound table and the bracket of the rate search, deg/s."""

    rates_deg_s: tuple
    search_deg_s: tuple


@dataclass(frozen=True)
class Segments(_Section):
    """``segments``: N0 samples before the first window, L windows of N samples, M EM maps each;
    ``sliding`` windows or ``growing`` ones (all data from N0)."""

    N0: int
    N: int
    M: int
    L: int
    mode: str = "sliding"

    @property
    def data_samples(self) -> int:
        """Samples after N0 that the segments use: L N."""
        return self.L * self.N

    @property
    def n_samples(self) -> int:
        """Samples after t0 the arc needs: N0 + L N."""
        return self.N0 + self.data_samples

    def windows(self) -> list[tuple[int, int]]:
        """(a, b) sample ranges of the L segments (start sample a has no measurement)."""
        N0, N, L = self.N0, self.N, self.L
        if self.mode == "sliding":
            return [(N0 + l * N, N0 + (l + 1) * N) for l in range(L)]
        return [(N0, N0 + (l + 1) * N) for l in range(L)]


@dataclass(frozen=True)
class EMSettings(_Section):
    """``em``: scheme (plain / squarem), unobservable-direction tolerance, the data-to-converge
    tolerance (arcsec, Table 1's column), the convergence label's tolerance to the ML estimate
    as a fraction of the bound of the data used, its stall rate (contraction per map), and the
    map budget of the ML reference."""

    method: str
    tz_tol: float
    converge_tol_arcsec: float
    converge_frac_of_bound: float
    stall_rate: float
    ml_max_maps: int

    @classmethod
    def from_config(cls, c: Mapping):
        """As every section, but ``converge_frac_of_bound`` is no config key: its one home is the
        analysis plan (``settings.converge_frac_of_bound``, :mod:`opnav.core.planvalues`); a
        workflow rule passes the plan's value inside ``em`` (so a change of it reruns the rule),
        any other caller gets it from the plan."""
        if "converge_frac_of_bound" not in c:
            from opnav.core.planvalues import converge_frac_of_bound

            c = {**c, "converge_frac_of_bound": converge_frac_of_bound()}
        return super().from_config(c)


@dataclass(frozen=True)
class ConvergenceStudy(_Section):
    """``convergence_study``: plain EM vs SQUAREM to the ML estimate on one window."""

    n_seeds: int
    data_samples: int
    max_maps: int
    tol_arcsec: float
    initial_error_mode: str


@dataclass(frozen=True)
class Growing(_Section):
    """``growing``: Table 1 again with growing windows of ``N`` samples, ``M`` maps, per scheme."""

    methods: tuple[str, ...]
    N: int
    M: int


@dataclass(frozen=True)
class AugmentedSettings(_Section):
    """``alternatives.augmented``: prior and random-walk 1-sigma of theta, arcsec."""

    theta_prior_sigma_arcsec: float
    theta_process_sigma_arcsec: float


@dataclass(frozen=True)
class BatchMLSettings(_Section):
    """``alternatives.batch_ml``: theta prior (arcsec), checkpoint seeds and stride, IPOPT
    tolerance, JIT compilation."""

    theta_prior_sigma_arcsec: float
    checkpoint_seeds: int
    checkpoint_stride: int
    tol: float
    jit: bool


@dataclass(frozen=True)
class Alternatives(_Section):
    """``alternatives``: the A-X2 estimators' settings."""

    augmented: AugmentedSettings
    batch_ml: BatchMLSettings


@dataclass(frozen=True)
class BasiliskSettings(_Section):
    """``peers.basilisk``: the peer UKF's tuning (A-P1)."""

    alpha: float
    beta: float
    kappa: float
    bias_prior_sigma_arcsec: float
    radius_bias_prior_sigma_px: float
    bias_process_sigma_px: float


@dataclass(frozen=True)
class Peers(_Section):
    """``peers``: the variants of A-P1 and the peer's tuning."""

    variants: tuple[str, ...]
    basilisk: BasiliskSettings


#: Setup field -> (config key, parser); a key absent from the section becomes Missing(key).
_FIELDS: dict[str, tuple[str, Any]] = {
    "base_seed": ("base_seed", int),
    "n_seeds": ("n_seeds", int),
    "dt_s": ("dt_s", float),
    "mars": ("mars_elements", KeplerElements.from_config),
    "geometry": ("geometry", ApproachGeometry.from_config),
    "initial_error": ("initial_error", InitialError.from_config),
    "prior_sigma": ("prior_sigma", PriorSigma.from_config),
    "process_noise_diag": ("process_noise_diag", _tuple),
    "camera": ("camera", Camera.from_config),
    "truth_bias_arcsec": ("truth_bias_arcsec", _tuple),
    "theta_init_arcsec": ("theta_init_arcsec", _tuple),
    "segments": ("segments", Segments.from_config),
    "em": ("em", EMSettings.from_config),
    "convergence_study": ("convergence_study", ConvergenceStudy.from_config),
    "scatter": ("scatter", str),
    "growing": ("growing", Growing.from_config),
    "methods": ("methods", lambda v: tuple(str(m) for m in v)),
    "roll": ("roll", Roll.from_config),
    "roll_rate_study": ("roll_rate_study", RollRateStudy.from_config),
    "stars": ("stars", Stars.from_config),
    "variants": ("variants", tuple),
    "table1_variants": ("table1_variants", tuple),
    "nav_last_fraction": ("nav_error", lambda c: float(c["last_fraction"])),
    "nav_floor": ("nav_floor", NavFloor.from_config),
    "crlb_prior_sigma_rad": ("crlb", lambda c: float(c["theta_prior_sigma_rad"])),
    "alternatives": ("alternatives", Alternatives.from_config),
    "peers": ("peers", Peers.from_config),
}


@dataclass(frozen=True)
class Setup:
    """Paper A's setup (module docstring); one field per ``approach`` key, units in the key names.

    Seeds: ``base_seed`` and ``n_seeds`` (each run's stream is
    ``SeedSequence([base_seed, case_index, seed_index])``). Noise: ``prior_sigma``,
    ``process_noise_diag`` (per step, km^2 and (km/s)^2), ``camera.sigma3_px``.
    """

    base_seed: int
    n_seeds: int
    dt_s: float
    mars: KeplerElements
    geometry: ApproachGeometry
    initial_error: InitialError
    prior_sigma: PriorSigma
    process_noise_diag: tuple
    camera: Camera
    truth_bias_arcsec: tuple
    theta_init_arcsec: tuple
    segments: Segments
    em: EMSettings
    convergence_study: ConvergenceStudy
    scatter: str
    growing: Growing
    methods: tuple
    roll: Roll
    roll_rate_study: RollRateStudy
    stars: Stars
    variants: tuple
    table1_variants: tuple
    nav_last_fraction: float
    nav_floor: NavFloor
    crlb_prior_sigma_rad: float
    alternatives: Alternatives
    peers: Peers

    @classmethod
    def from_config(cls, section: Mapping) -> "Setup":
        """Parse the ``approach`` section (or a rule's part of it); absent keys become :class:`Missing`."""
        if not isinstance(section, Mapping):
            raise TypeError(f"approach setup: expected the 'approach' config section, got {type(section).__name__}")
        kw = {}
        for name, (key, parse) in _FIELDS.items():
            kw[name] = parse(section[key]) if key in section else Missing(key)
        return cls(**kw)

    def replace(self, **changes) -> "Setup":
        return dataclasses.replace(self, **changes)

    @property
    def Q(self) -> np.ndarray:
        """Process noise per step (6, 6)."""
        return np.diag(np.asarray(self.process_noise_diag, float))

    def scheme(self, mode: str) -> "Setup":
        """The setup of a Table-1 scheme: ``sliding`` is the configured ``segments``; ``growing``
        uses ``growing.N`` and ``growing.M`` over the same data (L = segments.L N / growing.N)."""
        if mode == "sliding":
            return self
        if mode != "growing":
            raise ValueError(f"unknown segment mode {mode!r}; use 'sliding' or 'growing'")
        s, g = self.segments, self.growing
        total = s.data_samples
        if total % g.N:
            raise ValueError(f"approach.growing.N = {g.N} must divide segments.L * segments.N = {total}")
        return self.replace(segments=dataclasses.replace(s, mode="growing", N=g.N, M=g.M, L=total // g.N))
