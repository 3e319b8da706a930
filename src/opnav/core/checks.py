"""Config checks that need no physics: cross-key rules and bounds, run before any job.

Description
-----------
The JSON schema checks each key alone (type, range, the registry of names);
:func:`config_problems` checks what several keys decide together without any paper's
model, so it runs wherever a config is loaded (:func:`opnav.core.config.validate_config`,
fast, no numba), one line per problem naming the keys:

* ``results_dir``: a usable folder outside the checkout's tracked folders, not under
  /proc, /sys or /dev, no control character, no symlink loop (:func:`results_dir_problems`);
* names: lists without duplicates; ``table1_variants`` within ``variants``, ``peers``
  within ``table1_variants``; the B-X1 reference and the equivalence reference flown;
  negative controls among the pickers without a metric, apart from the tested methods;
  ``headline_scenario`` and the names of ``extra.n_runs`` among ``scenarios``; study
  names whose rules cannot collide with a rule the workflow has or makes, nor with another
  study's, and study ids that are no output id of the workflow (both read from the
  checkout's workflow: :func:`workflow_names`); tuning candidates without duplicates;
* the ``profile`` label against the sizes it claims (:func:`profile_problems`);
* numbers against each other: seeds of separate streams distinct, brackets ordered,
  a tolerance no larger than the quantity it tolerates, the landing vision cut-off
  (altitude plus margin) below the start altitude, the near-site landmark radius inside
  the field, the convergence threshold below the start altitude, the camera field of
  view under 180 deg, memory bounds (:func:`approach_rules`, :func:`landing_rules`);
* with ``workflow``: the growing windows, the job-graph bounds and each study's size
  (:func:`job_problems`).

The checks that need a paper's physics (the approach arc against Mars, the landing site
in the camera's view, ...) live in the paper packages (:mod:`opnav.approach.preflight`,
:mod:`opnav.landing.preflight`); :func:`opnav.preflight.check_config` runs both kinds and
the study planner, and is what the Snakefile and the CLI call.
"""

from __future__ import annotations

import functools
import math
import re
from pathlib import Path
from typing import Mapping, NamedTuple

from .planvalues import accuracy_target_arcsec

__all__ = ["config_problems", "approach_rules", "landing_rules", "results_dir_problems", "job_problems",
           "growing_problems", "study_size_problem", "study_spec_defaults", "TRACKED_DIRS",
           "MAX_APPROACH_SAMPLES", "MAX_APPROACH_SEED_SAMPLES", "MAX_LANDING_IMU_SAMPLES",
           "MAX_LANDING_RUN_STEPS", "STUDY_RULES", "PICKERS", "workflow_names", "profile_problems"]

#: Memory bounds. An approach arc of n samples keeps n one-step STMs (6x6) per
#: geometry and (seeds x n) filter states and covariances per batch.
MAX_APPROACH_SAMPLES = 200_000
MAX_APPROACH_SEED_SAMPLES = 2_000_000
#: A descent keeps its truth at every IMU sample; a Monte Carlo (and a study) keeps per-run
#: histories of every filter step.
MAX_LANDING_IMU_SAMPLES = 1_000_000
MAX_LANDING_RUN_STEPS = 5_000_000

#: Folders of the checkout that hold tracked files: results_dir may not be
#: (inside) one of them, nor the checkout itself.
TRACKED_DIRS = ("paper", "src", "config", "workflow", "profiles", "tests", "benchmarks", ".git",
                ".snakemake")

#: The rules a parameter study makes (studies.smk): ``study_<name>`` and ``study_<name>_outputs``.
STUDY_RULES = ("study_{}", "study_{}_outputs")

#: The planning "methods" without a metric (opnav.landing.planner's pickers): the negative
#: controls of the equivalence test. tests/test_bad_input.py keeps it equal to the planner's.
PICKERS = ("random", "center", "closest")

#: Mars' mean radius, km, as opnav.approach.dynamics has it (a test keeps them equal): the
#: approach arc's start must lie outside it.
R_MARS_KM = 3389.5


def multiple(value: float, step: float, tol: float = 1e-9) -> bool:
    """``value`` is a positive integer multiple of ``step`` (to a relative ``tol``)."""
    k = round(value / step)
    return k >= 1 and abs(k * step - value) <= tol * max(1.0, abs(value))


def _shown(x) -> str:
    """A list item as YAML shows it: [5.0, 3], a name bare."""
    return "[" + ", ".join(map(_shown, x)) + "]" if isinstance(x, (list, tuple)) else str(x)


def _numbers_as_floats(x):
    """``x`` with every number a float: [5, 3] and [5.0, 3] are one candidate."""
    if isinstance(x, (list, tuple)):
        return [_numbers_as_floats(v) for v in x]
    if isinstance(x, dict):
        return {k: _numbers_as_floats(v) for k, v in x.items()}
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) else x


def duplicates(items) -> list:
    """The items given more than once, in order of their second appearance."""
    seen, dup = set(), []
    for x in items:
        key = repr(_numbers_as_floats(x)) if isinstance(x, (list, dict)) else x
        if key in seen and x not in dup:
            dup.append(x)
        seen.add(key)
    return dup


_CONFIGFILE_FLAGS = ("--configfile", "--configfiles")


def configfile_flag_problem(argv) -> str | None:
    """One line if a command line gives ``--configfile`` more than once, else None.

    Snakemake's ``--configfile`` takes every file after one flag (argparse ``nargs="+"``);
    a second ``--configfile`` replaces the first list instead of adding to it, so
    ``--configfile config/quick.yaml --configfile mine.yaml`` silently builds the full
    profile with ``mine.yaml`` on top. ``argv``: the command line's arguments (the
    Snakefile passes ``sys.argv``)."""
    groups: list[list[str]] = []
    args = [str(a) for a in argv]
    for i, a in enumerate(args):
        flag, eq, val = a.partition("=")
        if flag not in _CONFIGFILE_FLAGS:
            continue
        files = [val] if eq else []
        for b in args[i + 1:] if not eq else ():
            if b.startswith("-"):
                break
            files.append(b)
        groups.append(files)
    if len(groups) < 2:
        return None
    kept = " ".join(groups[-1]) or "nothing"
    every = " ".join(f for g in groups for f in g)
    return (f"--configfile is given {len(groups)} times: Snakemake keeps only the last one ({kept}) and "
            f"drops the others; give every file after one flag: --configfile {every}")


def config_problems(config: dict, root: str | Path | None = None,
                    workdir: str | Path | None = None, *, skip=(), sections=None,
                    workflow: bool = False) -> list[str]:
    """Every physics-free problem of a schema-valid ``config`` (defaults filled), one line
    each naming the key(s) (module docstring). ``root`` is the checkout (default: the
    working directory), ``workdir`` where relative outputs go (default: ``root``); sections
    in ``skip`` (their schema failed) are not read; ``sections`` (default all) limits the
    checks to those sections; ``workflow`` adds what only the workflow reads (growing
    windows, job-graph bounds, study names and sizes)."""
    want = set(sections) if sections is not None else {"results_dir", "approach", "landing", "studies",
                                                        "limits", "profile"}
    todo = want - set(skip)
    out: list[str] = []
    # the profile label first: a results_dir owned by another profile follows from a wrong
    # label, so the owner check is skipped when the label is broken (one message per problem)
    label = (profile_problems(config) if workflow and "profile" in todo
             and not set(skip) & {"profile", "approach", "landing"} else [])
    if "results_dir" in todo:
        out += results_dir_problems(config, root, workdir, owner=not label and "profile" not in set(skip))
    for name, check in (("approach", approach_rules), ("landing", landing_rules)):
        if name in todo and name in config:
            out += check(config[name], workflow=workflow)
    if "landing" in todo and not set(skip) & {"landing", "replication"}:
        out += seed_rules(config)
    if not workflow:
        return out
    out += label     # the label the workflow's outputs carry
    if "approach" in todo and "approach" not in set(skip):
        out += growing_problems(config["approach"])
    if "studies" in todo and "landing" not in set(skip):
        out += study_rules(config, root)
    if "limits" in todo and not set(skip) & {"landing", "studies", "limits"}:
        out += job_problems(config)
    return out


#: The sample sizes the label ``profile: full`` claims (the Monte Carlos the verdicts are
#: judged on): at least the full profile's, which are the schema's defaults.
FULL_SIZES = ("approach.n_seeds", "landing.mc.n_runs")


def profile_problems(config: dict) -> list[str]:
    """``profile: full`` only on the full profile's sample sizes (:data:`FULL_SIZES`): the
    label decides whether the report, the claims table and the manuscript call the samples
    too small for verdicts. (``quick`` on larger samples is accepted: it only under-claims.)"""
    if config.get("profile") != "full":
        return []
    small = []
    for key in FULL_SIZES:
        section, *rest = key.split(".")
        node = config.get(section, {})
        for part in rest:
            node = node.get(part) if isinstance(node, dict) else None
        full = schema_default(key)
        if isinstance(node, int) and isinstance(full, int) and node < full:
            small.append(f"{key} = {node} < {full}")
    if not small:
        return []
    return [f"invalid config key 'profile': 'full' claims the full profile's samples, but {'; '.join(small)}: "
            "the report and the manuscript would judge verdicts on a sample the full profile does not have; "
            "set profile: quick (its outputs say the sample is too small for verdicts) or the full sizes"]


def schema_default(key: str):
    """The schema's default of the dotted ``key`` (``approach.n_seeds``); None where it has none."""
    return (schema_node(key) or {}).get("default")


@functools.lru_cache(maxsize=16)
def schema_node(key: str) -> dict | None:
    """The schema of the dotted config ``key`` (``landing.single.run_index``), following the
    section files; None where the schema has no such key."""
    here = Path(__file__).resolve().parents[1] / "schemas"
    load = functools.partial(_read_schema, here)
    node = load("config.schema.yaml")
    for part in key.split("."):
        node = (node.get("properties") or {}).get(part)
        if not isinstance(node, dict):
            return None
        if "$ref" in node and not node["$ref"].startswith("#"):
            node = {**load(node["$ref"]), **{k: v for k, v in node.items() if k != "$ref"}}
    return node


@functools.lru_cache(maxsize=8)
def _read_schema(here: Path, name: str) -> dict:
    import yaml

    return yaml.load((here / name).read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def _k(section: str, key: str) -> str:
    return f"invalid config key '{section}.{key}': "


def approach_rules(a: dict, *, workflow: bool = False) -> list[str]:
    """Physics-free cross-key rules of the ``approach`` section (module docstring)."""
    out: list[str] = []
    k = functools.partial(_k, "approach")
    s = a["segments"]
    n = s["N0"] + s["L"] * s["N"]
    if n > MAX_APPROACH_SAMPLES:
        return [k("segments") + f"N0 + L*N = {n} samples exceeds the limit {MAX_APPROACH_SAMPLES} (memory)"]
    lo, hi = a["roll_rate_study"]["search_deg_s"]
    if not lo < hi:
        out.append(k("roll_rate_study.search_deg_s") + f"the bracket [{lo:g}, {hi:g}] deg/s must be (low, high) "
                   "with low < high")
    target = accuracy_target_arcsec()  # A-C1's target, from the analysis plan (its one home)
    for key, tol in (("em.converge_tol_arcsec", a["em"]["converge_tol_arcsec"]),
                     ("convergence_study.tol_arcsec", a["convergence_study"]["tol_arcsec"])):
        if tol > target:
            out.append(k(key) + f"{tol:g} arcsec exceeds the claimed accuracy {target:g} arcsec (the analysis plan's "
                       "claims.A-C1.margins.target_arcsec) "
                       "(a run within a tolerance wider than the accuracy it is judged by would count as converged)")
    cam = a["camera"]
    fov_deg = cam["pixels"] * cam["ifov_arcsec"] / 3600.0
    if fov_deg >= 180.0:
        out.append(k("camera.ifov_arcsec") + f"{cam['ifov_arcsec']:g} arcsec x {cam['pixels']} px = {fov_deg:.4g} deg "
                   "of field of view (a pinhole camera sees less than 180 deg)")
    for key in ("variants", "table1_variants", "methods", "growing.methods", "peers.variants"):
        node = a
        for part in key.split("."):
            node = node[part]
        dup = duplicates(node)
        if dup:
            out.append(k(key) + f"duplicated {', '.join(map(str, dup))}")
    extra = [v for v in a["table1_variants"] if v not in a["variants"]]
    if extra:
        out.append(k("table1_variants") + f"{', '.join(extra)} not in approach.variants ({', '.join(a['variants'])})")
    peers = a.get("peers", {}).get("variants", [])
    extra = [v for v in peers if v not in a["table1_variants"]]
    if extra:  # A-P1 sets the peer beside the A-X2 results of those variants
        out.append(k("peers.variants") + f"{', '.join(extra)} not in approach.table1_variants "
                   f"({', '.join(a['table1_variants'])})")
    if a["geometry"]["range_km"] <= R_MARS_KM:
        out.append(k("geometry.range_km") + f"the arc starts inside Mars ({a['geometry']['range_km']:g} km <= Mars "
                   f"radius {R_MARS_KM} km)")
    st = a["stars"]
    if workflow and "stars" in a["variants"]:
        out += stars_arc_problems(a, "the stars variant (in approach.variants) would have no image")
    if st["sigma_floor_px"] > st["sigma_px"] * 10.0 ** (0.2 * (st["mag_limit"] - st["sigma_ref_mag"])):
        out.append(k("stars.sigma_floor_px") + f"{st['sigma_floor_px']:g} px exceeds the centroid 1-sigma of the "
                   f"faintest star imaged (sigma_px x 10^(0.2 (mag_limit - sigma_ref_mag))): the magnitude model "
                   "would not act; lower it or raise approach.stars.sigma_px")
    return out


def stars_arc_problems(a: dict, why: str = "the stars variant would have no image") -> list[str]:
    """The stars variant's first image (sample N0 + stars.every_K) within the arc (N0 + L*N
    samples): checked for the workflow when approach.variants flies stars, and by
    ``opnav approach --variant stars`` for the arc its flags make."""
    s, K = a["segments"], a["stars"]["every_K"]
    n = s["N0"] + s["L"] * s["N"]
    if s["N0"] + K > n:
        return [f"invalid config key 'approach.stars.every_K': {K}: the first star image (sample N0 + every_K = "
                f"{s['N0'] + K}) lies beyond the arc's last sample ({n} = N0 + L*N); {why}"]
    return []


def landing_rules(c: dict, *, workflow: bool = False) -> list[str]:
    """Physics-free cross-key rules of the ``landing`` section (module docstring)."""
    out: list[str] = []
    k = functools.partial(_k, "landing")
    T, Dt = c["duration_s"], c["filter"]["dt_s"]
    n_steps = max(1, round(T / Dt))
    z0 = c["initial_state"]["r_m"][2]
    if c["tuning"]["base_seed"] == c["mc"]["base_seed"]:
        out.append(k("tuning.base_seed") + f"{c['tuning']['base_seed']} equals landing.mc.base_seed: the tuning runs "
                   "must be out of sample (a separate random stream)")
    f = c["filter"]
    cut = f["min_update_altitude_m"] + f["update_altitude_margin_m"]
    if z0 > 0 and cut >= z0:
        out.append(k("filter.update_altitude_margin_m") + f"min_update_altitude_m + update_altitude_margin_m = "
                   f"{cut:g} m is not below the start altitude {z0:g} m (landing.initial_state.r_m[2]): the "
                   "filter would take no vision update")
    conv = c["mc"]["converged_pos_err_m"]
    if z0 > 0 and conv >= z0:
        out.append(k("mc.converged_pos_err_m") + f"{conv:g} m is not below the start altitude {z0:g} m: every run "
                   "would count as converged")
    lm = c["landmarks"]
    if lm["near_site"]["count"] and lm["near_site"]["r_min_m"] >= lm["half_width_m"]:
        out.append(k("landmarks.near_site.r_min_m") + f"{lm['near_site']['r_min_m']:g} m is not inside the landmark "
                   f"field (landing.landmarks.half_width_m = {lm['half_width_m']:g} m)")
    for key, runs in (("mc.n_runs", c["mc"]["n_runs"]), ("tuning.n_runs", c["tuning"]["n_runs"])):
        if runs * n_steps > MAX_LANDING_RUN_STEPS:
            out.append(k(key) + f"{runs} runs x {n_steps} filter steps exceeds the limit {MAX_LANDING_RUN_STEPS} "
                       "(memory)")
    lists = {"tuning.candidates": c["tuning"]["candidates"],
             "mc.methods": c["mc"]["methods"], "extra.methods": c["extra"]["methods"],
             "equivalence.methods": c["equivalence"]["methods"], "equivalence.controls": c["equivalence"]["controls"]}
    for key, names in lists.items():
        dup = duplicates(names)
        if dup:
            out.append(k(key) + f"duplicated {', '.join(map(_shown, dup))}")
    flown = list(c["mc"]["methods"]) + list(c["extra"]["methods"])
    if c["extra"]["reference"] not in flown:
        out.append(k("extra.reference") + f"{c['extra']['reference']!r} is not flown (not in landing.mc.methods or "
                   "landing.extra.methods)")
    eq = c["equivalence"]
    not_pickers = [m for m in eq["controls"] if m not in PICKERS]
    if not_pickers:
        out.append(k("equivalence.controls") + f"{', '.join(not_pickers)} has a metric; negative controls are the "
                   f"pickers without one ({', '.join(PICKERS)})")
    both = [m for m in eq["methods"] if m in eq["controls"] or m == eq["reference"]]
    if both:
        out.append(k("equivalence.methods") + f"{', '.join(both)} is also the reference or a control")
    scen = c.get("scenarios") or {}
    head = c.get("headline_scenario")
    if head is not None and scen and head not in scen:
        out.append(k("headline_scenario") + f"{head!r} is not one of landing.scenarios ({', '.join(scen)})")
    names = list(scen) or ["default"]
    for name in c["extra"].get("n_runs") or {}:
        if name not in names:
            out.append(k(f"extra.n_runs.{name}") + f"{name!r} is not one of landing.scenarios ({', '.join(names)}): "
                       "B-X1's runs are sized per camera scenario")
    if c["extra"]["n_boot"] == 1:
        out.append(k("extra.n_boot") + "1 resample gives no interval; use 0 (paired t only) or >= 2")
    return out


def seed_rules(config: dict) -> list[str]:
    """Paper B's random streams distinct: the tuning runs' seed is neither the Monte
    Carlo's nor the replication sample's (``landing.mc.base_seed`` + ``replication.seed_offset``,
    when the replication is flown)."""
    c, rep = config["landing"], config.get("replication") or {}
    tuning, mc = c["tuning"]["base_seed"], c["mc"]["base_seed"]
    out = []
    if rep.get("enabled") and "seed_offset" in rep and tuning == mc + rep["seed_offset"]:
        out.append(f"invalid config key 'landing.tuning.base_seed': {tuning} equals landing.mc.base_seed + "
                   f"replication.seed_offset = {mc} + {rep['seed_offset']}: the tuning runs would fly the replication "
                   "sample's stream")
    n_steps = max(1, round(c["duration_s"] / c["filter"]["dt_s"]))
    runs = rep.get("landing_n_runs", 0)
    if rep.get("enabled") and runs * n_steps > MAX_LANDING_RUN_STEPS:
        out.append(f"invalid config key 'replication.landing_n_runs': {runs} runs x {n_steps} filter steps exceeds "
                   f"the limit {MAX_LANDING_RUN_STEPS} (memory, as landing.mc.n_runs)")
    return out


def study_rules(config: dict, root: str | Path | None = None) -> list[str]:
    """Study names whose rules (:data:`STUDY_RULES`) collide with no rule the workflow has or
    makes (:func:`workflow_names`) nor with another study's; study ids that are no output
    id of the workflow and whose letter is the study's paper's; a paper-B study within the
    Monte Carlo's memory bound (runs x filter steps)."""
    out = []
    c = config["landing"]
    n_steps = max(1, round(c["duration_s"] / c["filter"]["dt_s"]))
    names = workflow_names(root)
    studies = config.get("studies") or {}
    made: dict[str, str] = {}       # rule name -> the study that makes it; a study's derived rules
    for pattern in STUDY_RULES[::-1]:   # (study_<x>_outputs) first: 'x_outputs' is the name to blame
        for name in studies:
            if isinstance(name, str):
                made.setdefault(pattern.format(name), name)
    for name, spec in studies.items():
        if not isinstance(name, str):                   # a YAML 1.1 key (on:, 1:) given in process
            out.append(f"invalid config key 'studies': the study name {name!r} is not a string")
            continue
        for rule in (pattern.format(name) for pattern in STUDY_RULES):
            owner = made.get(rule)
            if names is not None and (rule in names.rules or any(r.fullmatch(rule) for r in names.made)):
                out.append(f"invalid config key 'studies.{name}': the name makes the rule {rule}, which the "
                           "workflow has already (choose another name)")
                break
            if owner != name:
                out.append(f"invalid config key 'studies.{name}': the name makes the rule {rule}, which study "
                           f"'{owner}' makes too (choose another name)")
                break
        sid, paper = spec.get("id"), spec.get("paper")
        if isinstance(sid, str) and names is not None and sid in names.outputs:
            out.append(f"invalid config key 'studies.{name}.id' (study '{name}'): {sid} is an output id of the "
                       f"workflow (workflow/report/{sid}.rst); a study's id names its own outputs: choose another, "
                       f"e.g. {next(f'{sid[0]}-X{k}' for k in range(1, 999) if f'{sid[0]}-X{k}' not in names.outputs)}")
        elif isinstance(sid, str) and paper in PAPER_LETTER and not sid.startswith(PAPER_LETTER[paper] + "-"):
            out.append(f"invalid config key 'studies.{name}.id' (study '{name}'): {sid} names paper "
                       f"{sid[0]}, the study flies paper {PAPER_LETTER[paper]} ({paper}); an id starts with its "
                       f"paper's letter ({PAPER_LETTER[paper]}-...)")
        runs = spec.get("runs", study_spec_defaults()["runs"])
        if spec.get("paper") == "landing" and runs * n_steps > MAX_LANDING_RUN_STEPS:
            out.append(f"invalid config key 'studies.{name}.runs' (study '{name}'): {runs} runs x {n_steps} filter "
                       f"steps exceeds the limit {MAX_LANDING_RUN_STEPS} (memory, as landing.mc.n_runs)")
    return out


#: The letter of each paper in output ids (A-T1, B-X2; a study's default id is A-S or B-S).
PAPER_LETTER = {"approach": "A", "landing": "B"}


class WorkflowNames(NamedTuple):
    """What the checkout's workflow names: its rules (``rule NAME:``), the patterns of the
    rules it makes in loops (``name: f"approach_mc_pack{_i}"`` -> ``approach_mc_pack.+``; a
    study's own rules left out) and its output ids (``workflow/report/<id>.rst``)."""
    rules: frozenset
    made: tuple
    outputs: frozenset


_RULE_RE = re.compile(r"^\s*(?:rule\s+(\w+)\s*:|use\s+rule\s+.*?\bas\s+(\w+))", re.M)
_MADE_RE = re.compile(r"^\s*name:\s*(?:\n\s*)?f?([\"'])(.+?)\1", re.M)
_OUTPUT_ID_RE = re.compile(r"[A-Z]-[A-Z]+[0-9]+")


def workflow_names(root: str | Path | None = None) -> WorkflowNames | None:
    """:class:`WorkflowNames` of the checkout ``root`` (default: the one holding the working
    directory, else the package's), read from ``workflow/rules/*.smk`` and
    ``workflow/report/``; None where there is no workflow (an installed package)."""
    base = _checkout(root)
    return None if base is None else _workflow_names(str(base))


def _checkout(root) -> Path | None:
    cands = [Path(root)] if root is not None else [Path.cwd(), *Path.cwd().parents,
                                                    Path(__file__).resolve().parents[3]]
    for c in cands:
        if (c / "workflow" / "rules").is_dir() and (c / "Snakefile").is_file():
            return c.resolve()
    return None


@functools.lru_cache(maxsize=4)
def _workflow_names(root: str) -> WorkflowNames:
    rules, made = set(), []
    probe = "zz0probe"                                    # a study's own rules match any name
    for f in [Path(root, "Snakefile"), *sorted(Path(root, "workflow", "rules").glob("*.smk"))]:
        text = f.read_text(errors="replace")
        rules |= {a or b for a, b in _RULE_RE.findall(text)}
        for _, name in _MADE_RE.findall(text):
            parts = re.split(r"\{[^{}]*\}", name)
            rx = re.compile(".+".join(map(re.escape, parts)))
            if not any(rx.fullmatch(p.format(probe)) for p in STUDY_RULES):
                made.append(rx)
    outputs = {f.name.split(".")[0] for f in Path(root, "workflow", "report").glob("*.rst")}
    return WorkflowNames(frozenset(rules), tuple(made), frozenset(o for o in outputs if _OUTPUT_ID_RE.fullmatch(o)))


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
                         workdir: str | Path | None = None, owner: bool = True) -> list[str]:
    """``results_dir`` (the key of ``config_or_dir``, a config mapping, or the path
    itself): non-empty, no NUL or other control character, no unexpanded ``$VAR``, not
    under /proc, /sys or /dev, no symlink loop, not owned by another checkout or profile
    (:func:`owner_problems`, given a config and ``root``, unless ``owner`` is false: the
    caller found the config's ``profile`` broken), at most :data:`MAX_PATH_CHARS` characters (and
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
    ctrl = next((ch for ch in results_dir if ord(ch) < 32 or 127 <= ord(ch) < 160), None)
    if ctrl is not None:
        return [k + f"{results_dir[:60]!r} holds a control character (U+{ord(ctrl):04X}); a folder name has none"]
    env = re.search(r"\$(?:\{[^}]*\}|[A-Za-z_][A-Za-z0-9_]*)", results_dir)
    if env:
        return [k + f"{results_dir[:60]!r} holds {env.group(0)}, which is not expanded (a folder literally named "
                f"{env.group(0)!r} would be made); write the path itself"]
    bad = next((ch for ch in results_dir if ch in _PATH_SPECIAL or ch.isspace()), None)
    if bad is not None:
        why = _PATH_SPECIAL.get(bad, "a space splits the path in the commands and LaTeX inputs that name it")
        return [k + f"{results_dir[:60]!r} holds {bad!r}: {why}; use letters, digits and . _ - / only"]
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
    shown = repr(results_dir if len(results_dir) <= 80 else results_dir[:77] + "...")
    p = p if p.is_absolute() else Path(workdir or base) / p
    try:
        p = p.resolve(strict=False)
    except (RuntimeError, OSError) as exc:      # a symlink loop (RuntimeError before Python 3.13)
        return [k + f"{shown} cannot be resolved ({' '.join(str(exc).split())[:80]}): a symlink loop?"]
    for top in KERNEL_DIRS:
        if p.parts[:2] == ("/", top) or Path(os.path.abspath(results_dir)).parts[:2] == ("/", top):
            return [k + f"{shown} is under /{top} (a kernel file system, not a place for results)"]
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
    nested = nested_problems(p, base, shown)
    if nested:
        return nested
    if owner and cfg is not None and root is not None and p.is_dir():
        return owner_problems(p, root, str(cfg.get("profile", "full")))
    return []


#: Characters results_dir may not hold, and why (Snakemake reads every output path as a
#: pattern: a path that names it is expanded before any job).
_PATH_SPECIAL = {"{": "Snakemake reads {...} in an output path as a wildcard", "}": "Snakemake reads {...} in an "
                 "output path as a wildcard", "*": "a glob character ('*' matches any name)",
                 "?": "a glob character ('?' matches any character)", "[": "a glob character ('[...]')",
                 "]": "a glob character ('[...]')", "\\": "a backslash is no folder separator here",
                 '"': "a quote", "'": "a quote", "`": "a backquote", ";": "a shell separator",
                 "&": "a shell operator", "|": "a shell operator", "<": "a shell redirection",
                 ">": "a shell redirection"}


def nested_problems(p: Path, base: Path, shown_dir: str | None = None) -> list[str]:
    """``p`` (a resolved results_dir) strictly inside another build's results folder: one
    holding an :data:`OWNER_MARKER`, or the ``results_dir`` of a profile in the checkout
    ``base``'s ``config/`` (results, results/quick), unless ``p`` is itself one of those
    (the quick profile's results/quick inside results/ is the project's own layout). Two
    builds would write one tree, and one's outputs would stand where the other has its own."""
    known = _profile_dirs(str(base))
    if p in known or (p / OWNER_MARKER).is_file():
        return []
    owners = {a for a in p.parents if (a / OWNER_MARKER).is_file()} | {d for d in known if d in p.parents}
    if not owners:
        return []
    outer = max(owners, key=lambda a: len(a.parts))           # the nearest one
    try:
        shown = outer.relative_to(base).as_posix()
    except ValueError:
        shown = str(outer)
    return [f"invalid config key 'results_dir': {shown_dir or repr(str(p))} is inside the results folder {shown}/ of another build "
            f"(its outputs and this config's would mix); choose a folder beside it, e.g. '{shown}-mine'"]


@functools.lru_cache(maxsize=4)
def _profile_dirs(base: str) -> frozenset:
    """The resolved results_dir of each config file in ``base``/config (the checkout's
    profiles), read with the strict reader; a file it refuses names none."""
    from opnav.core.yamlfile import read_config_file
    from opnav.core.errors import ConfigError

    out = set()
    for f in sorted(Path(base, "config").glob("*.yaml")):
        try:
            d = read_config_file(f).get("results_dir", "results")
        except ConfigError:
            continue
        if isinstance(d, str) and d.strip():
            out.add((Path(base) / d).resolve())
    return frozenset(out)


#: results_dir's length limit (characters).
MAX_PATH_CHARS = 1024
#: Top-level folders of kernel file systems results_dir may not be under (root passes
#: os.access there).
KERNEL_DIRS = ("proc", "sys", "dev")

#: The marker inside results_dir naming the checkout (and config) that writes there.
OWNER_MARKER = ".opnav-owner.json"


def owner_problems(results_dir: str | Path, root: str | Path, profile: str) -> list[str]:
    """A results_dir another checkout (or another profile) owns: its :data:`OWNER_MARKER`
    names a different checkout, or the same checkout's other ``profile`` (full and quick
    outputs would mix). Editing the config and rebuilding in place is the normal use, so
    the config digest the marker records is information, not a refusal."""
    import json

    marker = Path(results_dir) / OWNER_MARKER
    try:
        owner = json.loads(marker.read_text())
    except FileNotFoundError:
        return []
    except (OSError, ValueError) as exc:
        return [f"invalid config key 'results_dir': its owner marker {marker} is unreadable ({exc}); remove it "
                "if this checkout owns the folder"]
    here = str(Path(root).resolve())
    if owner.get("checkout") != here:
        return [f"invalid config key 'results_dir': {str(results_dir)!r} belongs to the checkout "
                f"{owner.get('checkout')!r} ({marker}); two checkouts writing one folder take each other's "
                "outputs as up to date: give this checkout its own results_dir (or, if that checkout was moved "
                "here, delete the marker)"]
    if owner.get("profile") not in (None, profile):
        return [f"invalid config key 'results_dir': {str(results_dir)!r} holds the {owner.get('profile')!r} "
                f"profile's outputs ({marker}); give the {profile!r} profile its own results_dir"]
    return []


def claim_results_dir(results_dir: str | Path, root: str | Path, config: Mapping) -> Path:
    """Write :data:`OWNER_MARKER` into ``results_dir`` (made if missing): the checkout, the
    profile and a digest of the config (the Snakefile's ``onstart``, so a dry run writes
    nothing). Returns the marker's path."""
    import hashlib
    import json

    d = Path(results_dir)
    d.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha256(json.dumps(config, sort_keys=True, default=repr).encode()).hexdigest()[:16]
    marker = d / OWNER_MARKER
    tmp = marker.with_suffix(".tmp")
    tmp.write_text(json.dumps({"checkout": str(Path(root).resolve()), "profile": config.get("profile"),
                               "config_digest": digest}, indent=1) + "\n")
    tmp.replace(marker)
    return marker


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
