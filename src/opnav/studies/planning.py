"""A study section checked and expanded: every value set merged into the config, validated
and content-addressed (the package docstring, :mod:`opnav.studies`, says how).
"""

from __future__ import annotations

import copy
import itertools
import json
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from opnav.core.checks import (
    MAX_APPROACH_SEED_SAMPLES,
    MAX_STUDY_VALUES,
    study_size_problem,
    study_spec_defaults,
)
from opnav.core.errors import ConfigError
from opnav.core.planvalues import with_plan_values
from opnav.studies.metrics import (
    APPROACH_METHODS,
    DEFAULT_METHODS,
    DEFAULT_METRICS,
    METRICS,
)
from opnav.studies.values import (
    config_digest,
    get_path,
    in_shape,
    instance_label,
    project,
    set_path,
    simulation_shapes,
)

__all__ = ["MAX_LABEL_CHARS", "Instance", "Study", "plan"]

_LETTER = {"approach": "A", "landing": "B"}


@dataclass(frozen=True)
class Instance:
    """One value set of a study: ``label`` (file name), the overrides, the simulation config."""

    label: str
    values: dict[str, Any]
    sim: dict[str, Any] = field(repr=False)
    digest: str = ""


@dataclass(frozen=True)
class Study:
    name: str
    paper: str
    id: str
    title: str
    keys: tuple[str, ...]
    grid: bool
    methods: tuple[str, ...]
    variants: tuple[str, ...]
    runs: int
    runs_per_job: int
    metrics: tuple[str, ...]
    statistic: str
    instances: tuple[Instance, ...]
    fixed: dict = field(default_factory=dict)
    slopes: bool = False
    note: str = ""

    @property
    def units(self) -> list[tuple[str, str]]:
        """(variant, method) pairs, one line each in the figure (variant '' for paper B)."""
        return [(v, m) for v in (self.variants or ("",)) for m in self.methods]

    def spec(self) -> dict:
        """Plain-data description (rule params, caption, table provenance)."""
        return {"name": self.name, "paper": self.paper, "id": self.id, "title": self.title,
                "keys": list(self.keys), "grid": self.grid, "methods": list(self.methods),
                "variants": list(self.variants), "runs": self.runs, "metrics": list(self.metrics),
                "statistic": self.statistic, "fixed": dict(self.fixed), "slopes": self.slopes,
                "note": self.note, "runs_per_job": self.runs_per_job,
                "timing_calls": self.timing_calls,
                "instances": {i.label: i.values for i in self.instances}}

    @property
    def timing_calls(self) -> int | None:
        """Paper B: the planning calls replayed per job for the timing metrics
        (``landing.timing.max_calls`` of the simulation; 0 = all); None for paper A."""
        t = self.instances[0].sim.get("timing") if self.instances else None
        return int(t["max_calls"]) if isinstance(t, Mapping) and "max_calls" in t else None


def _value_sets(name: str, spec: Mapping) -> list[dict[str, Any]]:
    vary = spec["vary"]
    keys = list(vary)
    lists = [list(vary[k]) for k in keys]
    if spec.get("grid", False):
        combos = list(itertools.product(*lists))
    else:
        if len({len(v) for v in lists}) != 1:
            lens = ", ".join(f"{k}: {len(v)}" for k, v in zip(keys, lists))
            raise ConfigError(f"invalid config key 'studies.{name}.vary' (study '{name}'): the vary lists have "
                              f"different lengths ({lens}); give them the same length or set grid: true")
        combos = list(zip(*lists))
    return [dict(zip(keys, c)) for c in combos]


_PLANS: dict[str, dict] = {}

#: Longest value label (``fov_deg~45``): it names the value's files, within a file name's
#: 255 characters with the study id and name around it.
MAX_LABEL_CHARS = 150


def plan(config: Mapping, shapes: Mapping[str, Mapping] | None = None,
         validate: Callable[[dict], Any] | None = None,
         landing_methods: Iterable[str] | None = None, *,
         validate_paper: Callable[[dict, str], Any] | None = None) -> dict[str, Study]:
    """Every study of ``config["studies"]``, checked and expanded (module docstring).

    ``shapes[paper]`` is the simulation's view of ``config[paper]`` (default
    :func:`simulation_shapes`); ``validate(cfg)`` raises :class:`ConfigError` (or
    ``ValueError``) for a bad merged config, or ``validate_paper(cfg, paper)`` (the
    workflow's: :func:`opnav.preflight.validate_study_value`, which checks that paper's
    section alone); ``landing_methods`` are the planner's method names (default: its
    registry). Raises one :class:`ConfigError` with one line per problem of every
    study, each naming ``studies.<name>...``. Without shapes, validate and methods the
    plan is cached per config (the Snakefile's validation and studies.smk plan once).
    """
    if validate is None and validate_paper is None:
        raise TypeError("plan() needs validate or validate_paper")
    key = None
    if shapes is None and validate is None and landing_methods is None:
        key = json.dumps(config, sort_keys=True, default=repr)
        if key in _PLANS:
            return _PLANS[key]
    if shapes is None:
        shapes = simulation_shapes(config)
    if landing_methods is None:
        from opnav.landing.planner import available_methods

        landing_methods = available_methods()
    check = validate_paper if validate is None else (lambda cfg, paper: validate(cfg))
    out, problems = {}, []
    limit = int((config.get("limits") or {}).get("max_study_values", MAX_STUDY_VALUES))
    for name, spec in (config.get("studies") or {}).items():
        try:
            out[name] = _plan_one(name, spec, config, shapes, check, tuple(landing_methods), limit)
        except ConfigError as exc:
            problems += str(exc).splitlines()
    if problems:
        raise ConfigError("\n".join(dict.fromkeys(problems)))
    if key is not None:
        _PLANS.clear()
        _PLANS[key] = out
    return out


def _plan_one(name, spec, config, shapes, validate, landing_methods, limit=MAX_STUDY_VALUES) -> Study:
    spec = {**study_spec_defaults(), **spec}
    paper = spec["paper"]
    where = f"study '{name}'"
    problems: list[str] = []

    def bad(field: str, msg: str) -> None:
        problems.append(f"invalid config key 'studies.{name}.{field}' ({where}): {msg}")

    fixed = dict(spec.get("fixed") or {})
    for section, keys in (("vary", spec["vary"]), ("fixed", fixed)):
        for key in keys:
            parts = key.split(".")
            if parts[0] != paper:
                bad(f"{section}.{key}", f"key '{key}' is not under '{paper}.' (the study's paper)")
                continue
            try:
                current = get_path(config, key)
            except KeyError:
                bad(f"{section}.{key}", f"key '{key}' is not a config key")
                continue
            if isinstance(current, Mapping):   # the rule: a map is never replaced whole
                bad(f"{section}.{key}", f"key '{key}' is a map ({', '.join(sorted(current))}): a value would "
                                      f"replace all its keys; {'sweep' if section == 'vary' else 'fix'} its keys "
                                      f"instead (e.g. {key}.{next(iter(sorted(current)), 'x')})")
                continue
            if not in_shape(shapes[paper], parts[1:]):
                bad(f"{section}.{key}", f"key '{key}' is not read by the {paper} simulation, so setting "
                                      f"it changes nothing (it reads: {', '.join(sorted(shapes[paper]))})")
    both = sorted(set(spec["vary"]) & set(fixed))
    if both:
        bad("fixed", f"key(s) {both} are both swept (vary) and fixed")
    methods = list(spec.get("methods") or DEFAULT_METHODS[paper])
    allowed = APPROACH_METHODS if paper == "approach" else landing_methods
    if allowed:
        unknown = [m for m in methods if m not in allowed]
        if unknown:
            bad("methods", f"unknown method(s) {unknown} for paper {paper}; available: {', '.join(allowed)}")
    if paper == "landing" and spec.get("variants"):
        bad("variants", "'variants' are paper-A scenario variants; paper B has none")
    variants = list(spec.get("variants") or (["literal", "roll"] if paper == "approach" else []))
    metrics = list(spec.get("metrics") or DEFAULT_METRICS[paper])
    unknown = [m for m in metrics if m not in METRICS[paper]]
    if unknown:
        bad("metrics", f"unknown metric(s) {unknown}; available for {paper}: {', '.join(METRICS[paper])}")
    too_many = study_size_problem(name, spec, limit)
    if too_many:
        problems.append(too_many)
    if problems:
        raise ConfigError("\n".join(problems))
    statistic = spec.get("statistic", "mean")
    instances, seen = [], {}
    for values in _value_sets(name, spec):
        merged = copy.deepcopy(dict(config))
        merged.pop("studies", None)
        for k, v in {**fixed, **values}.items():
            set_path(merged, k, v)
        shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        checked = merged
        if paper == "landing":  # a study flies the base camera (no scenario overlay): checked so
            checked = {**merged, "landing": {**merged["landing"], "scenarios": {"study": {}},
                                             "headline_scenario": "study",   # and no B-X1 to size
                                             "extra": {**merged["landing"]["extra"], "n_runs": {}}}}
        try:
            validate(checked, paper)
        except (ConfigError, ValueError) as exc:
            for line in str(exc).splitlines():
                bad("vary", f"value {shown} refused: {line}")
            continue
        if paper == "approach":  # one job holds runs_per_job seeds of the whole arc in memory
            try:
                _check_approach_job_size(where, merged["approach"],
                                         min(int(spec["runs_per_job"]), int(spec["runs"])))
            except ConfigError as exc:
                bad("runs_per_job", str(exc).removeprefix(f"{where}: "))
                break
        # the validated (defaults filled, possibly normalised) values
        values = {k: get_path(merged, k) for k in values}
        label = instance_label(values)
        if len(label) > MAX_LABEL_CHARS:
            bad("vary", f"value {shown} makes the label {label[:40]!r}... of {len(label)} characters (it names "
                        f"files; at most {MAX_LABEL_CHARS}): sweep fewer keys or shorter values")
            continue
        if label in seen:
            bad("vary", f"values {seen[label]} and {values} coincide (label {label!r})")
            continue
        seen[label] = values
        sim = project(with_plan_values(paper, merged[paper]), shapes[paper])   # as the rules' params (shapes)
        instances.append(Instance(label, values, sim, config_digest({"paper": paper, "sim": sim})))
    if problems:
        raise ConfigError("\n".join(dict.fromkeys(problems)))
    keys = tuple(spec["vary"])
    letter = _LETTER[paper]
    return Study(name=name, paper=paper, id=spec.get("id") or f"{letter}-S",
                 title=spec.get("title") or ", ".join(keys), keys=keys, grid=bool(spec.get("grid", False)),
                 methods=tuple(methods), variants=tuple(variants), runs=int(spec["runs"]),
                 runs_per_job=int(spec["runs_per_job"]), metrics=tuple(metrics), statistic=statistic,
                 instances=tuple(instances), fixed=fixed, slopes=bool(spec.get("slopes", False)),
                 note=str(spec.get("note", "")))


def _check_approach_job_size(where: str, approach: Mapping, seeds_per_job: int) -> None:
    """A paper-A study job runs its seeds batched over the whole arc: the same memory
    limit as the Monte Carlo's (:data:`opnav.core.checks.MAX_APPROACH_SEED_SAMPLES`)."""
    from opnav.approach.setup import Setup

    n = Setup.from_config(approach).segments.n_samples
    if seeds_per_job * n > MAX_APPROACH_SEED_SAMPLES:
        raise ConfigError(f"{where}: runs_per_job = {seeds_per_job} seeds x {n} samples exceeds the limit "
                          f"{MAX_APPROACH_SEED_SAMPLES} (memory); lower runs_per_job")
