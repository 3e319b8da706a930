"""Config-time physics and consistency checks, run before any job.

Description
-----------
The JSON schema checks each key alone (type, range); :func:`config_problems`
checks what only several keys together decide, so that a config that would
crash, hang or quietly produce garbage inside a job is refused at once, with
one line per problem naming the keys:

* paper A: the arc and roll-step durations versus ``approach.dt_s``; the
  approach direction non-zero and not along the ecliptic pole (the aim-offset
  direction is ``v_inf_dir x z``); the arc starting outside Mars and not
  hitting it; Mars (at its closest along the arc, two-body Mars-centred
  hyperbola) fitting the detector; the truth misalignment keeping Mars on the
  detector; ``table1_variants`` inside ``variants`` and ``peers.variants``
  inside ``table1_variants``; memory bounds (data
  length, seeds x samples);
* paper B: ``duration_s`` a multiple of ``filter.dt_s``, ``imu.rate_hz x
  filter.dt_s`` an integer; the lander above ground (and above the
  measurement-cut-off altitude, and above its initial position errors) and its
  nominal guidance trajectory not through the ground; a planning margin that
  leaves part of the detector; the landing site in the configured camera's view at the
  start and while the filter measures (a parameter study runs these checks on
  every swept value: :func:`opnav.studies.plan`);
  every method name known to :func:`opnav.landing.planner.available_methods`
  (the planner's own registry); the B-X1 reference among the flown methods;
  the B-F5 instant inside the descent on a filter step; memory bounds;
* both: ``results_dir`` non-empty and outside the checkout's tracked folders.

Use: :func:`opnav.core.config.validate_config` calls :func:`config_problems` after
the schema (Snakefile validation and the ``opnav`` CLI both go through it).
Every check reads the package's own models (camera, guidance, constants), so
it follows them when they change. Units as in the config.
"""

from __future__ import annotations

import functools
import math
import re
from pathlib import Path

import numpy as np

__all__ = ["config_problems", "approach_problems", "landing_problems", "results_dir_problems",
           "TRACKED_DIRS", "MAX_APPROACH_SAMPLES", "MAX_APPROACH_SEED_SAMPLES",
           "MAX_LANDING_IMU_SAMPLES", "MAX_LANDING_RUN_STEPS"]

#: Memory bounds. An approach arc of n samples keeps n one-step STMs (6x6) per
#: geometry and (seeds x n) filter states and covariances per batch.
MAX_APPROACH_SAMPLES = 200_000
MAX_APPROACH_SEED_SAMPLES = 2_000_000
#: A descent keeps its truth at every IMU sample; a Monte Carlo keeps per-run
#: histories of every filter step.
MAX_LANDING_IMU_SAMPLES = 1_000_000
MAX_LANDING_RUN_STEPS = 5_000_000

#: Folders of the checkout that hold tracked files: results_dir may not be
#: (inside) one of them, nor the checkout itself.
TRACKED_DIRS = ("paper", "src", "config", "workflow", "profiles", "tests", "benchmarks", ".git",
                ".snakemake")


def _multiple(value: float, step: float, tol: float = 1e-9) -> bool:
    k = round(value / step)
    return k >= 1 and abs(k * step - value) <= tol * max(1.0, abs(value))


def _duplicates(items) -> list:
    seen, dup = set(), []
    for x in items:
        if x in seen and x not in dup:
            dup.append(x)
        seen.add(x)
    return dup


def config_problems(config: dict, root: str | Path | None = None,
                    workdir: str | Path | None = None, *, skip=(), sections=None,
                    workflow: bool = False, plan_studies=None) -> list[str]:
    """Every problem of a schema-valid ``config`` (defaults filled), one line each,
    naming the key(s): ``results_dir``, the ``approach`` and ``landing`` sections and,
    with ``workflow`` (the Snakefile, ``opnav study``), what only the workflow reads:
    paper A's growing windows, the ``studies`` (each value checked as its own config,
    :func:`opnav.studies.plan`) and the job-graph bounds (:func:`job_problems`).
    ``root`` is the checkout (default: the working directory), ``workdir`` where
    relative outputs go (default: ``root``); sections in ``skip`` (their schema failed)
    are not read; ``sections`` (default all) limits the checks to those sections;
    ``plan_studies(config)`` plans the studies, raising :class:`ConfigError` (handed in
    by :func:`opnav.core.config.validate_config`: :mod:`opnav.studies` imports this module)."""
    want = set(sections) if sections is not None else {"results_dir", "approach", "landing", "studies",
                                                        "limits"}
    todo = want - set(skip)
    out: list[str] = []
    if "results_dir" in todo:
        out += results_dir_problems(config, root, workdir)
    unsound = set(skip)                 # sections whose values the later checks cannot trust
    for name, check in (("approach", approach_problems), ("landing", landing_problems)):
        if name in todo and name in config:
            found = check(config[name])
            out += found
            # camera scenarios and the headline scenario are not what a study flies
            if any(not re.match(r"invalid config key 'landing\.(scenarios|headline_scenario)\b", ln)
                   for ln in found):
                unsound.add(name)
    if not workflow:
        return out
    if "approach" in todo and "approach" not in set(skip):
        out += growing_problems(config["approach"])
    jobs = []                           # counted, not built: first, as planning a study costs per value
    if "limits" in todo and not set(skip) & {"landing", "studies", "limits"}:
        jobs = job_problems(config)
    if ("studies" in todo and config.get("studies") and not jobs and plan_studies is not None
            and not unsound & {"approach", "landing", "limits"}):
        try:
            plan_studies(config)
        except ValueError as exc:        # ConfigError: one line per problem
            out += str(exc).splitlines()
    return out + jobs


#: Default upper bound on a study's value sets (config ``limits.max_study_values``).
MAX_STUDY_VALUES = 100


def study_size_problem(name: str, spec: Mapping, limit: int) -> str | None:
    """The line refusing study ``name`` if it has more than ``limit`` value sets
    (``limits.max_study_values``), counted without expanding them."""
    lens = [len(v) for v in spec["vary"].values()]
    n_sets = math.prod(lens) if spec.get("grid", False) else max(lens, default=0)
    if n_sets <= limit:
        return None
    lens = " x ".join(str(len(v)) for v in spec["vary"].values())
    return (f"invalid config key 'studies.{name}.vary' (study '{name}'): {lens} = {n_sets} value sets exceed "
            f"limits.max_study_values = {limit} (each is a Monte Carlo; raise the limit to mean it)")


@functools.lru_cache(maxsize=1)
def study_spec_defaults() -> dict:
    """Per-study defaults from the schema (validators fill ``properties`` defaults only,
    not those of a map's ``additionalProperties``); read once per process, shared: callers
    merge it into a new dict and never change it."""
    import yaml

    schema = Path(__file__).resolve().parents[1] / "schemas" / "studies.schema.yaml"
    props = yaml.load(schema.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    return {k: v["default"] for k, v in props["additionalProperties"]["properties"].items() if "default" in v}


def growing_problems(a: dict) -> list[str]:
    """Table 1 in growing windows (``approach.growing``, the workflow's rows) covers the
    sliding windows' data: its N must divide ``segments.L x N``."""
    grow, LN = a["growing"], a["segments"]["L"] * a["segments"]["N"]
    if grow["methods"] and LN % grow["N"]:
        return [f"invalid config key 'approach.growing.N': {grow['N']} does not divide approach.segments.L x N "
                f"= {LN} (growing windows cover the same data as the sliding ones)"]
    return []


def _jobs(config: dict) -> dict[str, int]:
    """The jobs the config's scattered parts make, by part, without building the DAG
    (an upper bound: study values sharing a simulation count apart): paper B's Monte
    Carlo (scenarios x methods x chunks, plus one gather per scenario and method when
    chunked), the studies (values x chunks, plus their table jobs), and the rest of
    the workflow (a fixed ~100)."""
    c = config["landing"]
    n_runs, per = c["mc"]["n_runs"], c["mc"]["runs_per_job"]
    chunks = -(-n_runs // max(per, 1))
    methods = len(dict.fromkeys([*c["mc"]["methods"], *c["extra"]["methods"]]))
    scen = len(c.get("scenarios") or {"default": {}})
    out = {"landing Monte Carlo (landing.scenarios x landing.mc.methods + extra.methods x "
           "landing.mc.n_runs / runs_per_job)": scen * methods * (chunks + (chunks > 1))}
    for name, spec in (config.get("studies") or {}).items():
        vary = list((spec.get("vary") or {}).values())
        lens = [len(v) for v in vary if isinstance(v, list)] or [0]
        values = math.prod(lens) if spec.get("grid") else max(lens)
        runs, rpj = (spec.get(k, study_spec_defaults()[k]) for k in ("runs", "runs_per_job"))
        out[f"study {name} (values x runs / runs_per_job)"] = values * -(-runs // max(min(rpj, runs), 1)) + 2
    return out


#: The workflow's jobs besides those :func:`_jobs` counts (tables, figures, paper A's
#: Monte Carlo by variant and group, manuscript): ~70 in the full profile.
OTHER_JOBS = 100


def job_problems(config: dict) -> list[str]:
    """The job graph within ``limits.max_jobs`` (Snakemake takes ~10 ms a job to build
    it, at every call) and each study within ``limits.max_study_values``, counted before
    anything is built or planned (:func:`_jobs`)."""
    limits = config.get("limits") or {}
    out = [line for name, spec in (config.get("studies") or {}).items()
           if (line := study_size_problem(name, spec, limits.get("max_study_values", MAX_STUDY_VALUES)))]
    limit = limits.get("max_jobs", 2000)
    parts = _jobs(config)
    total = OTHER_JOBS + sum(parts.values())
    if total > limit:
        top = sorted(parts.items(), key=lambda kv: -kv[1])[:2]
        what = "; ".join(f"{k}: {v}" for k, v in top)
        out.append(f"invalid config key 'limits.max_jobs': the config makes about {total} jobs, over the limit "
                   f"{limit} ({what}); raise runs_per_job, shrink the study, or raise limits.max_jobs to mean it")
    return out


def results_dir_problems(config_or_dir, root: str | Path | None = None,
                         workdir: str | Path | None = None) -> list[str]:
    """``results_dir`` (the key of ``config_or_dir``, a config mapping, or the path
    itself): non-empty, no NUL byte, at most :data:`MAX_PATH_CHARS` characters (and
    255 per component), ``~`` expanded (in the config, in place) or refused if it
    names no home; a writable directory (or creatable in a writable one), not a
    file; not the checkout ``root`` (default: the working directory) nor a folder
    holding it; not inside a folder of tracked files (:func:`tracked_dirs`; a
    relative path is taken from ``workdir``, where Snakemake writes; default ``root``)."""
    import os

    cfg = config_or_dir if isinstance(config_or_dir, dict) else None
    results_dir = str(cfg.get("results_dir", "results") if cfg is not None else config_or_dir)
    k = "invalid config key 'results_dir': "
    if not results_dir.strip():
        return [k + "empty (generated files would land in the checkout)"]
    if "\0" in results_dir:
        return [k + "contains a NUL byte"]
    if len(results_dir) > MAX_PATH_CHARS or any(len(x) > 255 for x in Path(results_dir).parts):
        return [k + f"{len(results_dir)} characters (at most {MAX_PATH_CHARS}, and 255 per folder name)"]
    if results_dir.startswith("~"):
        expanded = os.path.expanduser(results_dir)
        if expanded.startswith("~"):
            return [k + f"{results_dir[:60]!r}: '~' names no home folder here; give the path"]
        results_dir = expanded
        if cfg is not None:
            cfg["results_dir"] = expanded
    base = Path(root or Path.cwd()).resolve()
    p = Path(results_dir)
    p = (p if p.is_absolute() else Path(workdir or base) / p).resolve()
    shown = repr(results_dir if len(results_dir) <= 80 else results_dir[:77] + "...")
    if p == base:
        return [k + f"{shown} is the checkout itself"]
    if p in base.parents:
        return [k + f"{shown} holds the checkout (choose e.g. 'results')"]
    try:
        rel = p.relative_to(base)
    except ValueError:
        rel = None
    if rel is not None:
        for d in tracked_dirs(base):
            if rel == d or d in rel.parents:
                return [k + f"{shown} is inside the tracked folder {d.as_posix()}/ (choose e.g. 'results')"]
    q = p
    while not q.exists():
        q = q.parent
    if q == p and not p.is_dir():
        return [k + f"{shown} is an existing file, not a folder"]
    if not q.is_dir():
        return [k + f"{shown}: {q} is a file, so the folder cannot be made"]
    if not os.access(q, os.W_OK | os.X_OK):
        return [k + f"{shown}: {q} is not writable"]
    return []


#: results_dir's length limit (characters).
MAX_PATH_CHARS = 1024


def tracked_dirs(root: Path) -> tuple[Path, ...]:
    """The folders of checkout ``root`` (relative) that hold tracked files, from
    ``git ls-files`` (a folder whose tracked files are only README placeholders, such as
    results/, does not count), always with .git and .snakemake; outside git, every
    top-level folder but results*/ and :data:`TRACKED_DIRS`."""
    return _tracked_dirs(str(Path(root).resolve()))


@functools.lru_cache(maxsize=4)
def _tracked_dirs(root: str) -> tuple[Path, ...]:
    import subprocess

    base = Path(root)
    dirs = {Path(".git"), Path(".snakemake")}
    files = None
    if (base / ".git").exists():
        try:
            r = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True, timeout=20)
            if r.returncode == 0:
                files = [Path(f) for f in r.stdout.decode("utf-8", "replace").split("\0") if f]
        except (OSError, subprocess.SubprocessError):
            files = None
    if files is None:
        dirs |= {Path(d) for d in TRACKED_DIRS}
        dirs |= {Path(e.name) for e in base.iterdir() if e.is_dir() and not e.name.startswith("results")}
        return tuple(sorted(dirs))
    for f in files:
        if f.name.lower() in ("readme.md", ".gitkeep", "readme"):
            continue
        dirs.update(a for a in f.parents if a != Path("."))
    return tuple(sorted(dirs))


# --------------------------------------------------------------------- paper A

def _approach_min_range_km(a: dict, T: float) -> float:
    """Closest range to Mars over [0, T] (s) of the arc that
    :func:`opnav.approach.scenario.initial_truth` starts, km: Mars-centred two-body
    motion, in closed form (the hyperbolic Kepler equation; e.g. Vallado,
    *Fundamentals of Astrodynamics and Applications*, ch. 2). The arc is a hyperbola (its energy is v_inf^2 / 2 > 0): the range
    falls until periapsis and rises after it, so the minimum is the periapsis radius
    p / (1 + e) if periapsis comes within [0, T], else the range at the nearer end
    (at T from the hyperbolic Kepler equation e sinh H - H = M). At or below Mars'
    radius the arc has reached the surface: Mars' radius. (The Sun's tide over an
    approach arc moves it by far less than Mars' radius.) This runs in every
    Snakemake parse, where importing scipy.integrate cost more than the check; a
    nearly parabolic arc (energy lost in round-off) is integrated instead
    (:func:`_integrated_min_range_km`)."""
    from opnav.approach import dynamics, scenario

    X0 = scenario.initial_truth(a) - dynamics.kepler_state(
        dynamics.KeplerElements.from_config(a["mars_elements"]), 0.0)
    args = (X0[:3], X0[3:], T, dynamics.MU_MARS, dynamics.R_MARS_KM)
    try:
        return _hyperbola_min_range_km(*args)
    except ValueError:                               # nearly parabolic
        return _integrated_min_range_km(*args)


def _hyperbola_min_range_km(r0, v0, T: float, mu: float, r_surface: float) -> float:
    """Closest range over [0, T] s of the two-body hyperbola through (r0 km, v0 km/s)
    about a body of ``mu`` (km^3/s^2), floored to ``r_surface`` km (see
    :func:`_approach_min_range_km`)."""
    r0, v0 = np.asarray(r0, float), np.asarray(v0, float)
    r, v2, rv = float(np.linalg.norm(r0)), float(v0 @ v0), float(r0 @ v0)
    energy = v2 / 2.0 - mu / r
    if not energy > 1e-6 * mu / r:                   # relative to its two ~equal terms
        raise ValueError("not a well-conditioned hyperbola (nearly parabolic)")
    a = mu / (2.0 * energy)                              # |semi-major axis|, km
    h2 = float(np.sum(np.cross(r0, v0) ** 2))
    e = math.sqrt(1.0 + 2.0 * energy * h2 / mu ** 2)
    n = math.sqrt(mu / a ** 3)                           # mean motion, rad/s
    # hyperbolic anomaly now: r = a (e cosh H - 1), r . v = sqrt(mu a) e sinh H
    H0 = math.asinh(rv / (math.sqrt(mu * a) * e))
    M0 = e * math.sinh(H0) - H0
    if rv >= 0.0:                                        # receding already
        rmin = r
    elif -M0 / n <= T:                                   # periapsis within the arc
        rmin = h2 / mu / (1.0 + e)
    else:                                                # still approaching at T
        M, H = M0 + n * T, H0
        for _ in range(100):                             # Newton; f' = e cosh H - 1 > 0
            step = (e * math.sinh(H) - H - M) / (e * math.cosh(H) - 1.0)
            H -= step
            if abs(step) <= 1e-14 * max(1.0, abs(H)):
                break
        rmin = min(r, a * (e * math.cosh(H) - 1.0))
    return r_surface if rmin <= r_surface else rmin


def _integrated_min_range_km(r0, v0, T: float, mu: float, r_surface: float) -> float:
    """:func:`_hyperbola_min_range_km` by scipy's DOP853 integration of the same
    two-body motion (stopped at the surface) and a bounded search around the
    closest sample: any conic, and the reference the closed form is tested against."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    def rhs(t, X):
        return np.concatenate([X[3:], -mu * X[:3] / np.linalg.norm(X[:3]) ** 3])

    def surface(t, X):
        return np.linalg.norm(X[:3]) - r_surface

    surface.terminal = True
    sol = solve_ivp(rhs, (0.0, T), np.concatenate([r0, v0]), method="DOP853", rtol=1e-11,
                    atol=1e-7, dense_output=True, events=surface)
    if sol.status == 1:                              # reached the surface
        return r_surface
    rng = np.linalg.norm(sol.y[:3], axis=0)
    i = int(np.argmin(rng))
    lo, hi = sol.t[max(i - 1, 0)], sol.t[min(i + 1, len(sol.t) - 1)]
    rmin = float(rng[i])
    if hi > lo:
        best = minimize_scalar(lambda t: np.linalg.norm(sol.sol(t)[:3]), bounds=(lo, hi),
                               method="bounded", options={"xatol": 1e-7 * max(T, 1.0)})
        rmin = min(rmin, float(best.fun))
    # a grazing dip below the surface within one step has no sign change for the event
    return r_surface if rmin <= r_surface else rmin


def approach_problems(a: dict) -> list[str]:
    """Cross-key problems of the ``approach`` section (see module docstring)."""
    from opnav.approach import dynamics, scenario

    out: list[str] = []
    k = "invalid config key 'approach."
    dt = a["dt_s"]
    s = a["segments"]
    n = scenario.n_samples(a)
    if n > MAX_APPROACH_SAMPLES:
        out.append(f"{k}segments': N0 + L*N = {n} samples exceeds the limit "
                   f"{MAX_APPROACH_SAMPLES} (memory)")
        return out
    for key, seeds, samples in (("n_seeds", a["n_seeds"], n),
                                ("convergence_study.n_seeds", a["convergence_study"]["n_seeds"],
                                 s["N0"] + a["convergence_study"]["data_samples"])):
        if seeds * samples > MAX_APPROACH_SEED_SAMPLES:
            out.append(f"{k}{key}': {seeds} seeds x {samples} samples exceeds the limit "
                       f"{MAX_APPROACH_SEED_SAMPLES} (memory)")
    if s["N0"] + a["convergence_study"]["data_samples"] > MAX_APPROACH_SAMPLES:
        out.append(f"{k}convergence_study.data_samples': N0 + data_samples exceeds the limit "
                   f"{MAX_APPROACH_SAMPLES} (memory)")
    if out:
        return out
    roll = a["roll"]
    if roll["steps_deg"] and not _multiple(roll["step_interval_s"], dt):
        out.append(f"{k}roll.step_interval_s': {roll['step_interval_s']} s is not a multiple of "
                   f"approach.dt_s = {dt} s")
    for key in ("variants", "table1_variants", "methods"):
        node = a
        for part in key.split("."):
            node = node[part]
        dup = _duplicates(node)
        if dup:
            out.append(f"{k}{key}': duplicated {', '.join(map(str, dup))}")
    extra = [v for v in a["table1_variants"] if v not in a["variants"]]
    if extra:
        out.append(f"{k}table1_variants': {', '.join(extra)} not in approach.variants "
                   f"({', '.join(a['variants'])})")
    peers = a.get("peers", {}).get("variants", [])
    extra = [v for v in peers if v not in a["table1_variants"]]
    if extra:  # A-P1 sets the peer beside the A-X2 results of those variants
        out.append(f"{k}peers.variants': {', '.join(extra)} not in approach.table1_variants "
                   f"({', '.join(a['table1_variants'])})")
    dup = _duplicates(peers)
    if dup:
        out.append(f"{k}peers.variants': duplicated {', '.join(map(str, dup))}")
    g = a["geometry"]
    d = np.asarray(g["v_inf_dir"], float)
    dn = float(np.linalg.norm(d))
    if dn == 0:
        out.append(f"{k}geometry.v_inf_dir': the approach direction is zero")
        return out
    if float(np.linalg.norm(np.cross(d / dn, [0.0, 0.0, 1.0]))) < 1e-6:
        out.append(f"{k}geometry.v_inf_dir': {list(g['v_inf_dir'])} is along the ecliptic pole "
                   "(the aim-offset direction v_inf_dir x z is undefined)")
        return out
    if g["range_km"] <= dynamics.R_MARS_KM:
        out.append(f"{k}geometry.range_km': the arc starts inside Mars "
                   f"({g['range_km']} km <= Mars radius {dynamics.R_MARS_KM} km)")
        return out
    T = dt * max(n, s["N0"] + a["convergence_study"]["data_samples"])
    rmin = _approach_min_range_km(a, T)
    if rmin <= dynamics.R_MARS_KM:
        out.append(f"{k}geometry': the arc reaches Mars' surface within its {T:g} s "
                   "(dt_s x samples); raise geometry.aim_offset_km or range_km, or shorten the arc")
        return out
    cam = a["camera"]
    disc = scenario.mars_disc_px(rmin, cam["ifov_arcsec"])
    if disc > cam["pixels"]:
        out.append(f"{k}camera': Mars ({disc:.0f} px across at its closest, {rmin:.0f} km) does "
                   f"not fit the {cam['pixels']} px detector; raise camera.ifov_arcsec or "
                   "geometry.range_km")
    half_fov = cam["pixels"] * cam["ifov_arcsec"] / 2.0
    for key in ("truth_bias_arcsec", "theta_init_arcsec"):
        off = math.hypot(a[key][0], a[key][1])
        if off >= half_fov:
            out.append(f"{k}{key}': a misalignment of {off:g} arcsec (x, y) puts Mars off the "
                       f"detector (half field of view {half_fov:g} arcsec)")
    return out


# --------------------------------------------------------------------- paper B

def landing_problems(c: dict) -> list[str]:
    """Cross-key problems of the ``landing`` section (see module docstring)."""
    from opnav.landing.planner import available_methods
    from opnav.landing.trajectory import truth_states

    out: list[str] = []
    k = "invalid config key 'landing."
    T, Dt, rate = c["duration_s"], c["filter"]["dt_s"], c["imu"]["rate_hz"]
    if not _multiple(T, Dt):
        out.append(f"{k}duration_s': {T} s is not a multiple of landing.filter.dt_s = {Dt} s")
    if not _multiple(rate * Dt, 1.0):
        out.append(f"{k}imu.rate_hz': rate_hz x filter.dt_s = {rate} x {Dt} = {rate * Dt:g} "
                   "is not a positive integer")
    n_steps = max(1, round(T / Dt))
    if T * rate > MAX_LANDING_IMU_SAMPLES:
        out.append(f"{k}imu.rate_hz': duration_s x rate_hz = {T * rate:.0f} IMU samples exceeds "
                   f"the limit {MAX_LANDING_IMU_SAMPLES} (memory)")
    for key, runs in (("mc.n_runs", c["mc"]["n_runs"]),):
        if runs * n_steps > MAX_LANDING_RUN_STEPS:
            out.append(f"{k}{key}': {runs} runs x {n_steps} filter steps exceeds the limit "
                       f"{MAX_LANDING_RUN_STEPS} (memory)")
    f5 = c["figures"]["f5_time_s"]
    if not (0 <= f5 < T) or (f5 > 0 and not _multiple(f5, Dt)):
        out.append(f"{k}figures.f5_time_s': {f5} s must be a filter step "
                   f"(multiple of filter.dt_s = {Dt} s) in [0, duration_s = {T} s)")

    known = available_methods()
    lists = {"mc.methods": c["mc"]["methods"], "extra.methods": c["extra"]["methods"],
             "extra.reference": [c["extra"]["reference"]],
             "single.method": [c["single"]["method"]]}
    for key, names in lists.items():
        bad = [m for m in names if m not in known]
        if bad:
            out.append(f"{k}{key}': unknown planning method {', '.join(map(repr, bad))} "
                       f"(known: {', '.join(known)})")
        dup = _duplicates(names)
        if dup:
            out.append(f"{k}{key}': duplicated {', '.join(dup)}")
    if c["extra"]["n_boot"] == 1:
        out.append(f"{k}extra.n_boot': 1 resample gives no interval; use 0 (paired t only) or >= 2")
    flown = list(c["mc"]["methods"]) + list(c["extra"]["methods"])
    if c["extra"]["reference"] not in flown:
        out.append(f"{k}extra.reference': {c['extra']['reference']!r} is not flown "
                   "(not in landing.mc.methods or landing.extra.methods)")

    r0 = np.asarray(c["initial_state"]["r_m"], float)
    alt_min = c["filter"]["min_update_altitude_m"]
    if r0[2] <= 0:
        out.append(f"{k}initial_state.r_m': the lander starts at altitude {r0[2]:g} m, "
                   "not above the ground z = 0")
        return out
    if c["mc"]["bounds"]["r_m"] >= r0[2]:
        out.append(f"{k}mc.bounds.r_m': initial position errors up to {c['mc']['bounds']['r_m']:g} m "
                   f"would start estimates below the ground (the lander starts at {r0[2]:g} m)")
    out += _margin_problems(c["planner"]["margin_px"], c["camera"], f"{k}planner.margin_px'")
    scenarios = _scenario_cameras(c, out)
    for name, cam in scenarios.items():
        out += _margin_problems(c["planner"]["margin_px"], cam, f"{k}scenarios.{name}'")
    if r0[2] <= alt_min:
        out.append(f"{k}initial_state.r_m': the lander starts at {r0[2]:g} m, not above "
                   f"filter.min_update_altitude_m = {alt_min:g} m (no measurement would be taken)")
    if out or not _multiple(T, Dt):
        return out
    t = Dt * np.arange(n_steps + 1)
    try:
        tr = truth_states(t, r0, c["initial_state"]["v_mps"], T, c["gravity_mps2"], c["yaw_deg"])
    except (ValueError, np.linalg.LinAlgError) as exc:
        return [*out, f"{k}initial_state': the nominal guidance trajectory is undefined: {exc}"]
    below = np.nonzero(tr.r[:-1, 2] < 0)[0]
    if below.size:
        out.append(f"{k}initial_state': the nominal guidance trajectory goes below ground at "
                   f"t = {t[below[0]]:g} s (initial_state.r_m / v_mps / duration_s)")
        return out
    measuring = tr.r[:, 2] > alt_min                 # where the filter takes bearings
    to_site_B = np.einsum("kij,kj->ki", tr.R_LtoB, -tr.r)
    for key, cam in {"camera": c["camera"], **{f"scenarios.{n}": v for n, v in scenarios.items()}}.items():
        out += _view_problems(cam, f"{k}{key}'", t, to_site_B, measuring)
    return out


def _scenario_cameras(c: dict, out: list[str]) -> dict[str, dict]:
    """``{scenario: merged camera}`` of the camera scenarios (``landing.scenarios``) whose
    camera differs from ``landing.camera`` (each is checked as the base camera is); a
    ``landing.headline_scenario`` that names none of them is appended to ``out``."""
    from opnav.landing.scenario import camera_scenarios

    scen = c.get("scenarios") or {}
    head = c.get("headline_scenario")
    if head is not None and scen and head not in scen:
        out.append(f"invalid config key 'landing.headline_scenario': {head!r} is not one of "
                   f"landing.scenarios ({', '.join(scen)})")
        return {}
    try:
        merged = camera_scenarios(c)
    except ValueError as exc:
        out.append(f"invalid config key 'landing.scenarios': {exc}")
        return {}
    return {n: s["camera"] for n, s in merged.items() if s["camera"] != c["camera"]}


def _margin_problems(margin: float, cam: dict, key: str) -> list[str]:
    half = cam["pixels"] / 2.0
    if margin >= half:
        return [f"{key}: landing.planner.margin_px = {margin:g} px leaves no part of the "
                f"{cam['pixels']} px detector to plan landmarks in (must be < {half:g})"]
    return []


def _view_problems(camera: dict, key: str, t, to_site_B, measuring) -> list[str]:
    """The landing site in ``camera``'s view at the start and while the filter measures."""
    from opnav.landing.camera import camera_from_config

    fov = camera["fov_deg"]
    try:
        cam = camera_from_config(camera)
    except ValueError as exc:
        return [f"{key}: {exc}"]
    seen = cam.in_view(to_site_B)
    if not seen[0]:
        return [f"{key}: the landing site is not in the camera's view at t = 0 "
                f"(fov_deg {fov:g}, tilt_deg {camera['tilt_deg']:g}, "
                f"tilt_azimuth_deg {camera['tilt_azimuth_deg']:g})"]
    if not np.all(seen[measuring]):
        t_out = t[np.nonzero(measuring & ~seen)[0][0]]
        return [f"{key}: the landing site leaves the camera's view at t = {t_out:g} s "
                f"of the nominal descent (fov_deg {fov:g}, tilt_deg {camera['tilt_deg']:g})"]
    return []
