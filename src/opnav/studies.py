"""Parameter studies: sweep config keys of one paper, compare methods on paired runs.

Description
    A study (config section ``studies``, schema ``schemas/studies.schema.yaml``)
    names its paper, one or more dotted config keys with their values
    (``vary``; zipped, or every combination with ``grid: true``), the methods
    (and for paper A the scenario variants) to compare, the runs per value and
    the metrics to tabulate. :func:`plan` turns every study into
    :class:`Study` objects before any job starts:

    * each value set (an *instance*) is merged into a copy of the whole config
      and validated by the project schema (plus any extra check passed in), so
      a bad value is refused naming the study and the key;
    * a swept key must be one the paper's simulation reads (``shape``, the
      simulation's ``params:``), or the sweep would change nothing;
    * the simulation config of an instance (the config projected on
      ``shape``) is content-addressed (:func:`config_digest`): identical
      simulations (the same value in two studies, a value equal to the
      default in another) share their Monte-Carlo jobs, and editing one
      study's values adds only the new value's jobs.

    Runs are paired: run ``i`` uses the paper's stream of run index ``i``
    (paper B: ``SeedSequence([landing.mc.base_seed, i])``; paper A: the
    headline case's ``SeedSequence([approach.base_seed, 1, i])``) at every
    value and for every method, whatever the chunking.

Statistics (:func:`summarize`), per (instance, [variant,] method, metric) over
the runs: n, mean, sample sd, RMS, median, the 95 % confidence interval of the
mean (Student t, n - 1 degrees of freedom) and the paired difference against
the first method (mean and 95 % interval of the per-run differences).
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping

import numpy as np

if TYPE_CHECKING:  # pandas (0.3 CPU-s of import) in the functions that make tables: a
    import pandas as pd  # Monte-Carlo job imports this module for config_digest alone

from opnav.core.checks import MAX_APPROACH_SEED_SAMPLES, MAX_STUDY_VALUES, study_size_problem, study_spec_defaults
from opnav.core.errors import ConfigError

__all__ = ["METRICS", "CONSTANT_METRICS", "APPROACH_METHODS", "SIM_KEYS", "Study", "plan", "simulation_shapes",
           "config_digest",
           "instance_label", "get_path", "set_path", "project", "summarize", "table_metrics", "wide_table",
           "caption", "ci95", "gather_runs", "tidy_table", "shown_statistic", "loglog_slopes"]

#: Per-run metrics a study can tabulate: name -> (label with unit, CRLB column or None).
METRICS: dict[str, dict[str, tuple[str, str | None]]] = {
    "landing": {
        "final_pos_err_m": ("final position error (m)", None),
        "rms_pos_err_m": ("RMS position error (m)", None),
        "final_vel_err_mps": ("final velocity error (m/s)", None),
        "rms_vel_err_mps": ("RMS velocity error (m/s)", None),
        "final_att_err_deg": ("final attitude error (deg)", None),
        "rms_att_err_deg": ("RMS attitude error (deg)", None),
        "mean_nees_pos": ("mean position NEES (-)", None),
        "mean_nees_vel": ("mean velocity NEES (-)", None),
        "n_landmarks": ("landmarks used per run (-)", None),
        "converged_pct": ("runs converged (%)", None),
        "median_plan_time_us": ("median planning time (us)", None),
        "median_plan_cpu_us": ("median planning CPU time (us)", None),
        "no_pick_pct": ("plans choosing no landmark (%)", None),
    },
    "approach": {
        "err_x_arcsec": ("tx estimate - truth (arcsec)", "crlb_x_arcsec"),
        "err_y_arcsec": ("ty estimate - truth (arcsec)", "crlb_y_arcsec"),
        "err_z_arcsec": ("tz estimate - truth (arcsec)", None),
        "crlb_x_arcsec": ("1-sigma CRLB of tx, all data (arcsec)", None),
        "crlb_y_arcsec": ("1-sigma CRLB of ty, all data (arcsec)", None),
        "crlb_used_x_arcsec": ("1-sigma CRLB of tx, data the estimator used (arcsec)", None),
        "crlb_used_y_arcsec": ("1-sigma CRLB of ty, data the estimator used (arcsec)", None),
        "stalled_pct": ("EM seeds the stall rule flags (%)", None),
        "converged_pct": ("EM seeds labelled converged (%)", None),
        "nav_err_after_km": ("RMS nav. error after compensation (km)", None),
        "data_to_converge_samples": ("data needed to converge (samples)", None),
    },
}
#: Metrics that are one number per value and method (the same for every run): tables and
#: figures show their value (the mean), whatever the study's statistic.
CONSTANT_METRICS = frozenset({"crlb_x_arcsec", "crlb_y_arcsec", "crlb_used_x_arcsec", "crlb_used_y_arcsec"})
#: Per-run 0/100 indicators: their mean is the share of runs, whatever the study's statistic.
SHARE_METRICS = frozenset({"converged_pct", "stalled_pct"})
DEFAULT_METRICS = {"landing": ["final_pos_err_m", "rms_pos_err_m", "mean_nees_pos"],
                   "approach": ["err_x_arcsec", "err_y_arcsec", "nav_err_after_km"]}
DEFAULT_METHODS = {"landing": ["depth", "svd"], "approach": ["em", "augmented"]}
#: Paper-A estimators: em = EM-EKF with approach.em.method; augmented = augmented EKF.
APPROACH_METHODS = ("em", "em_plain", "em_squarem", "em_growing_squarem", "augmented")
STATISTICS = ("mean", "sd", "rms")
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


# ------------------------------------------------------------------ config paths
def get_path(cfg: Mapping, dotted: str):
    node: Any = cfg
    for part in dotted.split("."):
        if not isinstance(node, Mapping) or part not in node:
            raise KeyError(dotted)
        node = node[part]
    return node


def set_path(cfg: dict, dotted: str, value) -> None:
    parts = dotted.split(".")
    node = cfg
    for part in parts[:-1]:
        node = node[part]
    node[parts[-1]] = copy.deepcopy(value)


def project(src: Mapping, shape: Mapping) -> dict:
    """``src`` restricted to the keys of ``shape`` (recursively): the simulation's view."""
    out = {}
    for k in sorted(shape):
        if isinstance(shape[k], Mapping) and isinstance(src.get(k), Mapping):
            out[k] = project(src[k], shape[k])
        else:
            out[k] = copy.deepcopy(src[k])
    return out


def _in_shape(shape: Mapping, parts: list[str]) -> bool:
    node: Any = shape
    for p in parts:
        if not isinstance(node, Mapping):
            return True          # a sub-key of a value the simulation reads whole
        if p not in node:
            return False
        node = node[p]
    return True


def config_digest(obj) -> str:
    """A short content hash of plain data (key order and int/float spelling independent)."""
    def norm(x):
        if isinstance(x, Mapping):
            return {str(k): norm(x[k]) for k in sorted(x)}
        if isinstance(x, (list, tuple)):
            return [norm(v) for v in x]
        if isinstance(x, bool) or x is None or isinstance(x, str):
            return x
        if isinstance(x, (int, float, np.integer, np.floating)):
            f = float(x)
            return int(f) if f.is_integer() and abs(f) < 2**53 else repr(f)
        return str(x)
    text = json.dumps(norm(obj), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ------------------------------------------------------------------ labels
def _slug(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.12g}"
    if isinstance(value, (list, tuple)):
        return ",".join(_slug(v) for v in value)
    if isinstance(value, Mapping):
        return ",".join(f"{k}={_slug(value[k])}" for k in sorted(value))
    return re.sub(r"[^A-Za-z0-9._,+-]", "_", str(value))


def _display(value):
    """A swept value for a table cell: lists as '(a, b, c)' (a LaTeX row must not start with '[')."""
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(str(_display(v)) for v in value) + ")"
    return value


def _short_keys(keys: Iterable[str]) -> dict[str, str]:
    """Each dotted key by its last component, more components where two would clash."""
    keys = list(keys)
    for depth in range(1, max(k.count(".") for k in keys) + 2):
        short = {k: ".".join(k.split(".")[-depth:]) for k in keys}
        if len(set(short.values())) == len(keys):
            return short
    return {k: k for k in keys}


def instance_label(values: Mapping[str, Any]) -> str:
    """File-name label of a value set: ``fov_deg~45`` or ``N~25_L~80`` (Paramspace style)."""
    short = _short_keys(values)
    return "_".join(f"{short[k]}~{_slug(values[k])}" for k in values)


# ------------------------------------------------------------------ planning
#: The simulation's view of each paper's config section (what its Monte-Carlo rule passes
#: as ``params``): the keys a study may sweep or fix. studies.smk checks that these
#: equal the rules' own (B_SIM of landing.smk, A_SCENARIO of approach.smk).
SIM_KEYS = {
    "landing": ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu",
                "camera", "landmarks", "filter", "planner", "mc.base_seed", "mc.bounds", "timing.max_calls"),
    "approach": ("base_seed", "dt_s", "mars_elements", "geometry", "initial_error", "prior_sigma",
                 "process_noise_diag", "camera", "truth_bias_arcsec", "theta_init_arcsec", "segments",
                 "roll", "crlb", "stars", "em", "nav_error", "alternatives", "growing"),
}


def simulation_shapes(config: Mapping) -> dict[str, dict]:
    """``{paper: the config section projected on SIM_KEYS[paper]}`` (keys sorted)."""
    out: dict[str, dict] = {}
    for paper, keys in SIM_KEYS.items():
        view: dict = {}
        for dotted in keys:
            *parents, last = dotted.split(".")
            src, dst = config[paper], view
            for part in parents:
                src, dst = src[part], dst.setdefault(part, {})
            dst[last] = copy.deepcopy(src[last])
        out[paper] = _sorted(view)
    return out


def _sorted(x):
    return {k: _sorted(x[k]) for k in sorted(x)} if isinstance(x, Mapping) else x


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
    for field, keys in (("vary", spec["vary"]), ("fixed", fixed)):
        for key in keys:
            parts = key.split(".")
            if parts[0] != paper:
                bad(f"{field}.{key}", f"key '{key}' is not under '{paper}.' (the study's paper)")
                continue
            try:
                current = get_path(config, key)
            except KeyError:
                bad(f"{field}.{key}", f"key '{key}' is not a config key")
                continue
            if isinstance(current, Mapping):   # the rule: a map is never replaced whole
                bad(f"{field}.{key}", f"key '{key}' is a map ({', '.join(sorted(current))}): a value would "
                                      f"replace all its keys; {'sweep' if field == 'vary' else 'fix'} its keys "
                                      f"instead (e.g. {key}.{next(iter(sorted(current)), 'x')})")
                continue
            if not _in_shape(shapes[paper], parts[1:]):
                bad(f"{field}.{key}", f"key '{key}' is not read by the {paper} simulation, so setting "
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
                                             "headline_scenario": "study"}}
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
        sim = project(merged[paper], shapes[paper])
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
    from opnav.approach.scenario import n_samples

    n = n_samples(approach)
    if seeds_per_job * n > MAX_APPROACH_SEED_SAMPLES:
        raise ConfigError(f"{where}: runs_per_job = {seeds_per_job} seeds x {n} samples exceeds the limit "
                          f"{MAX_APPROACH_SEED_SAMPLES} (memory); lower runs_per_job")


def table_metrics(study: Mapping) -> list[str]:
    """The study's metrics and, after them, the bounds they are compared with (paper A CRLB)."""
    mets = list(study["metrics"])
    bounds = [METRICS[study["paper"]][m][1] for m in mets]
    return mets + [b for b in dict.fromkeys(bounds) if b and b not in mets]


# ------------------------------------------------------------------ tables
def gather_runs(parts: Iterable[tuple[str, pd.DataFrame]], study: Mapping,
                converged_pos_err_m: float | None = None) -> pd.DataFrame:
    """Every run of a study, one row per (instance, [variant,] method, run): the chunk
    tables ``(instance label, frame)`` joined, the rows of the study's methods (and
    variants) kept (a chunk also holds those of other studies of the same value), runs
    beyond ``study["runs"]`` dropped (kept chunks of a larger earlier study), paper-B
    derived metrics added, the swept values beside each row; rows in (value, [variant,]
    method, run) order, whatever the chunking."""
    import pandas as pd
    frames = []
    for label, df in parts:
        df = df.copy()
        df.insert(0, "instance", label)
        frames.append(df)
    runs = pd.concat(frames, ignore_index=True)
    keep = runs["method"].isin(study["methods"]) & (runs["run"] < study["runs"])
    if study["variants"]:
        keep &= runs["variant"].isin(study["variants"])
    runs = runs[keep]
    variants = list(study["variants"]) or [None]
    counts = runs.groupby(["instance", "variant", "method"] if study["variants"] else ["instance", "method"]).size()
    for label, v, m in itertools.product(study["instances"], variants, study["methods"]):
        n = int(counts.get((label, v, m) if v else (label, m), 0))
        if n != study["runs"]:
            raise ValueError(f"study '{study['name']}': value {label}: {n} runs of {f'{v}/{m}' if v else m}, "
                             f"expected {study['runs']} (rerun its study_runs jobs)")
    if study["paper"] == "landing":
        from opnav.landing.study import add_derived

        runs = add_derived(runs, converged_pos_err_m)
    for key in study["keys"]:
        runs.insert(1, key, [str(study["instances"][i][key]) for i in runs["instance"]])
    # one row order whatever the chunking (runs_per_job): value, [variant,] method, run
    order = {c: {v: i for i, v in enumerate(vals)} for c, vals in
             (("instance", list(study["instances"])), ("variant", list(study["variants"])),
              ("method", list(study["methods"])))}
    cols = ["instance", *(["variant"] if study["variants"] else []), "method", "run"]
    runs = runs.sort_values(cols, key=lambda col: col.map(order[col.name]) if col.name in order else col,
                            kind="stable")
    return runs.reset_index(drop=True)


def tidy_table(runs: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """The study's tidy summary (:func:`summarize`) with the study name and swept values."""
    tidy = summarize(runs, table_metrics(study), study["methods"])
    for key in reversed(study["keys"]):
        tidy.insert(1, key, [study["instances"][i][key] for i in tidy["instance"]])
    tidy.insert(0, "study", study["name"])
    return tidy


def shown_statistic(study: Mapping, metric: str) -> str:
    """The statistic a figure draws for ``metric``: the study's; the value (mean) of a
    metric that is the same for every run (:data:`CONSTANT_METRICS`); the share (mean) of a
    0/100 indicator (:data:`SHARE_METRICS`)."""
    return "mean" if metric in CONSTANT_METRICS | SHARE_METRICS else study["statistic"]


def loglog_slopes(tidy: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """Power-law exponents: per ([variant,] method, metric) the least-squares slope of
    log(statistic) against log(first swept key), the statistic being
    :func:`shown_statistic`'s (+1: proportional). Values or statistics <= 0 are left out;
    NaN below two points."""
    import pandas as pd
    key = study["keys"][0]
    unit = (["variant"] if "variant" in tidy else []) + ["method", "metric"]
    rows = []
    for keys, g in tidy[tidy["metric"].isin(table_metrics(study))].groupby(unit, sort=False):
        keys = keys if isinstance(keys, tuple) else (keys,)
        stat = shown_statistic(study, keys[-1])
        x = np.array([float(study["instances"][i][key]) for i in g["instance"]])
        y = g[stat].to_numpy(float)
        ok = (x > 0) & (y > 0) & np.isfinite(y)
        slope = (float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])
                 if ok.sum() >= 2 and np.ptp(np.log(x[ok])) > 0 else math.nan)
        rows.append({"study": study["name"], **dict(zip(unit, keys)), "statistic": stat,
                     "against": key, "n_values": int(ok.sum()), "slope": slope})
    return pd.DataFrame(rows)


# ------------------------------------------------------------------ statistics
def ci95(x) -> tuple[float, float]:
    """95 % confidence interval of the mean of the finite values of ``x`` (Student t,
    :func:`opnav.landing.ranking.paired_t_interval`); NaN below two values."""
    from opnav.landing.ranking import paired_t_interval

    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        return math.nan, math.nan
    _, lo, hi, _ = paired_t_interval(x, 0.95)
    return lo, hi


def summarize(runs: pd.DataFrame, metrics: Iterable[str], methods: Iterable[str]) -> pd.DataFrame:
    """Tidy summary: one row per (instance, [variant,] method, metric).

    ``runs`` holds one row per (instance, [variant,] method, run) with the
    metric columns. The paired difference is against the first of ``methods``
    on the same (instance, variant, run).
    """
    import pandas as pd
    methods = list(methods)
    ref = methods[0]
    unit = ["instance"] + (["variant"] if "variant" in runs else [])
    rows = []
    for keys, g in runs.groupby(unit, sort=False):
        keys = keys if isinstance(keys, tuple) else (keys,)
        base = g[g["method"] == ref].set_index("run")
        for m in methods:
            gm = g[g["method"] == m]
            for metric in metrics:
                x = gm[metric].to_numpy(float)
                fin = x[np.isfinite(x)]
                lo, hi = ci95(fin)
                row = dict(zip(unit, keys))
                row.update(method=m, metric=metric, n_runs=int(fin.size),
                           mean=float(fin.mean()) if fin.size else math.nan,
                           sd=float(fin.std(ddof=1)) if fin.size > 1 else math.nan,
                           rms=float(np.sqrt(np.mean(fin**2))) if fin.size else math.nan,
                           median=float(np.median(fin)) if fin.size else math.nan,
                           ci95_low=lo, ci95_high=hi)
                if m != ref:
                    d = (gm.set_index("run")[metric] - base[metric]).to_numpy(float)
                    d = d[np.isfinite(d)]
                    dlo, dhi = ci95(d)
                    row.update({"diff_vs": ref, "diff_mean": float(d.mean()) if d.size else math.nan,
                                "diff_ci95_low": dlo, "diff_ci95_high": dhi})
                else:
                    row.update({"diff_vs": "", "diff_mean": math.nan, "diff_ci95_low": math.nan,
                                "diff_ci95_high": math.nan})
                rows.append(row)
    return pd.DataFrame(rows)


def wide_table(tidy: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """The human view: one row per value x [variant x] method, '<stat> [lo, hi]' per metric."""
    import pandas as pd
    stat = study["statistic"]
    inst = study["instances"]
    rows = []
    unit = ["instance"] + (["variant"] if "variant" in tidy else []) + ["method"]
    for keys, g in tidy.groupby(unit, sort=False):
        row = {k: _display(v) for k, v in inst[keys[0]].items()}
        row.update(dict(zip(unit[1:], keys[1:])))
        row["n_runs"] = int(g["n_runs"].max())
        for r in g.itertuples():
            shown = shown_statistic(study, r.metric)
            if not np.isfinite(getattr(r, shown)):  # e.g. the stall share of a non-EM estimator
                row[r.metric if shown == "mean" else f"{r.metric} ({stat})"] = "--"
                continue
            if r.metric not in study["metrics"] or r.metric in CONSTANT_METRICS:  # the same for every run
                row[r.metric] = f"{r.mean:.4g}"
            elif shown == "mean":  # mean +- half-width of its 95 % interval
                row[r.metric] = (f"{r.mean:.4g} ± {(r.ci95_high - r.ci95_low) / 2:.2g}"
                                 if np.isfinite(r.ci95_low) else f"{r.mean:.4g}")
            else:
                row[f"{r.metric} ({stat})"] = f"{getattr(r, stat):.4g}"
        rows.append(row)
    return pd.DataFrame(rows)


def caption(study: Mapping) -> str:
    """The study's caption, from its spec (report and manuscript): at most three sentences
    (what is swept and compared; what is plotted and what the table adds; the study's own
    note, its first sentence) and no config key (the keys are in the study's CSV and spec)."""
    paper = {"approach": "paper A", "landing": "paper B"}[study["paper"]]
    swept = study.get("title") or ", ".join(k.split(".")[-1] for k in study["keys"])
    vals = ("; " if len(study["keys"]) > 1 else ", ").join(
        ", ".join(_slug(v) for v in vs.values()) for vs in study["instances"].values())
    fixed = study.get("fixed") or {}
    fixed_text = (" (" + ", ".join(f"{k.split('.')[-1]} = {_slug(v)}" for k, v in fixed.items()) + " at every value)"
                  if fixed else "")
    who = ", ".join(study["methods"])
    if study["variants"]:
        who += " under the scenario variants " + ", ".join(study["variants"])
        runs = f"{study['runs']} paired seeds of the headline case per value"
    else:
        runs = f"{study['runs']} paired runs per value and method"
    if study["paper"] == "approach" and study["statistic"] == "sd":
        stat = "RMS about the truth of the estimate errors and the mean of the other metrics"
    else:
        stat = {"mean": "mean over runs with its 95 % confidence interval",
                "sd": "spread (sd over runs)", "rms": "RMS over runs"}[study["statistic"]]
    mets = ", ".join(METRICS[study["paper"]][m][0] for m in study["metrics"])
    note = re.split(r"(?<=[.!?])\s+(?=[A-Z])", " ".join(str(study.get("note") or "").split()))[0]
    return (f"Study '{study['name']}' ({paper}): {swept} at {vals}{fixed_text}, all else as configured; "
            f"compared: {who}, {runs}. Plotted: the {stat} of {mets}"
            + (" beside the 1-sigma Cramer-Rao bound" if study["paper"] == "approach"
               and study["statistic"] != "mean" else "")
            + f"; the CSV table adds n, sd, RMS, median, the 95 % interval and the paired difference against "
            f"{study['methods'][0]}"
            + (f", and the log-log slopes against {swept}" if study.get("slopes") else "")
            + _timing_text(study) + "."
            + (f" {note}" if note else ""))


#: per-run metrics measured by replaying the runs' planning calls (opnav.landing.timing)
TIMING_METRICS = ("median_plan_time_us", "median_plan_cpu_us")


def _timing_text(study: Mapping) -> str:
    """How the planning-time metrics were measured (empty if the study shows none)."""
    if not set(study["metrics"]) & set(TIMING_METRICS):
        return ""
    n = study.get("timing_calls")
    per_job = min(int(study.get("runs_per_job") or study["runs"]), int(study["runs"]))
    which = ("every recorded planning call" if not n else
             f"at most {n} of a job's recorded planning calls (jobs of {per_job} runs), evenly spaced, "
             f"so a run's median rests on about {max(n // per_job, 1)} calls")
    return "; planning times by replay, apart from the filter's work, of " + which