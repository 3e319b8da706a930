"""Configuration: read the user's YAML files strictly, validate against the project schema.

The schema (``opnav/schemas/config.schema.yaml``, shipped with the package, and the
section files it references) is the single source of defaults, types, ranges and the
registry of names. :func:`load_config` reads every file with the strict reader
(:mod:`opnav.core.yamlfile`, also the Snakefile's for every ``--configfile``), merges them
as ``snakemake --configfile`` does, and validates with the schema and the physics-free
cross-key checks (:mod:`opnav.core.checks`). It imports nothing above the core (no paper
package, numba, scipy or pandas): the checks that need a paper's physics and the study
planner run in :func:`opnav.preflight.check_config`, which the Snakefile and the CLI call.
"""

from __future__ import annotations

import functools
import math
import re
from pathlib import Path
from typing import Any

import yaml


from opnav.core.errors import ConfigError  # noqa: E402  (defined in the base layer; its home for users)
from opnav.core.yamlfile import dotted as _dotted, read_config_file

__all__ = ["ConfigError", "validate_config", "load_config", "read_config_file", "schema_problems", "core_problems"]


_INSTANCE_RE = re.compile(r"On instance((?:\[[^\]]+\])*)")
_MESSAGE_RE = re.compile(r"ValidationError: (.*)")


def _instance_path_to_key(instance: str) -> str:
    parts = re.findall(r"\[([^\]]+)\]", instance)
    return ".".join(p.strip("'\"") for p in parts)


def describe_validation_error(exc: BaseException) -> str:
    """One readable line naming the offending config key.

    Turns Snakemake's ``Error validating config file ... On instance['a']['b']``
    text into ``invalid config key 'a.b': <reason>``. For unknown keys the
    reason names the unexpected key itself.
    """
    text = str(exc)
    inst = _INSTANCE_RE.search(text)
    msg = _MESSAGE_RE.search(text)
    key = _instance_path_to_key(inst.group(1)) if inst else ""
    reason = msg.group(1).strip() if msg else text.strip().splitlines()[0]
    where = f"config key '{key}'" if key else "config (top level)"
    return f"invalid {where}: {reason}"


#: The project schema, shipped as package data.
SCHEMA_PATH = Path(__file__).resolve().parents[1] / "schemas" / "config.schema.yaml"


def repo_root(start: Path | None = None) -> Path:
    """The checkout that holds ``config/config.yaml`` (searching upwards from ``start``)."""
    here = (start or Path.cwd()).resolve()
    for cand in [here, *here.parents, Path(__file__).resolve().parents[3]]:
        if (cand / "config" / "config.yaml").is_file() and (cand / "Snakefile").is_file():
            return cand
    raise ConfigError(
        "cannot find config/config.yaml: run from the opnav-repro checkout or pass --config"
    )


def _is_integer(checker, instance) -> bool:
    """JSON-schema ``integer``: a Python int only (``3.0`` is refused, so a value
    that passes validation works in ``range()`` inside a rule)."""
    return isinstance(instance, int) and not isinstance(instance, bool)


def _is_number(checker, instance) -> bool:
    """JSON-schema ``number``: a finite int or float (NaN passes every
    ``minimum`` comparison and inf every key without a ``maximum``)."""
    return (isinstance(instance, (int, float)) and not isinstance(instance, bool)
            and math.isfinite(instance))


#: libyaml's loader where PyYAML has it (same documents, several times faster).
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def read_yaml(path: str | Path) -> Any:
    """The YAML document in the package file ``path`` (the config schemas), read with
    libyaml's safe loader where available (the pure-Python one is ~10x slower, and every
    workflow parse reads these files). User config files go through :func:`load_config`,
    whose error messages name the line and column. (``opnav.core.published``, a lower layer,
    makes the same loader choice for the published values.)"""
    return yaml.load(Path(path).read_text(), Loader=_YAML_LOADER)


@functools.lru_cache(maxsize=8)
def _validator(schema_path: Path):
    import jsonschema
    from jsonschema import Draft202012Validator, ValidationError
    from referencing import Registry, Resource
    from referencing.jsonschema import DRAFT202012

    def load(path: Path) -> dict:
        # Without "$schema" the extended class below (which fills defaults) is
        # kept for referenced section files too: jsonschema otherwise switches
        # to the plain Draft 2020-12 validator for every schema naming its
        # dialect, and nested sections were never filled.
        contents = read_yaml(path)
        contents.pop("$schema", None)
        return contents

    # The registry is immutable: without a cache every validation (the Snakefile
    # validates each study value's config too) re-read every section file.
    @functools.lru_cache(maxsize=None)
    def retrieve(uri: str) -> Resource:
        path = Path(uri.removeprefix("file://"))
        return Resource.from_contents(load(path), default_specification=DRAFT202012)

    schema = load(schema_path)
    schema["$id"] = schema_path.resolve().as_uri()
    registry = Registry(retrieve=retrieve)

    base = Draft202012Validator
    validate_props = base.VALIDATORS["properties"]
    validate_type = base.VALIDATORS["type"]

    def set_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for prop, sub in properties.items():
                if "default" in sub and prop not in instance:
                    instance[prop] = _copy(sub["default"])
        yield from validate_props(validator, properties, instance, schema)

    def strict_type(validator, types, instance, schema):
        errors = list(validate_type(validator, types, instance, schema))
        wanted = [types] if isinstance(types, str) else list(types)
        if errors and isinstance(instance, float) and {"number", "integer"} & set(wanted):
            if not math.isfinite(instance):
                yield ValidationError(f"{instance} is not a finite number (NaN and infinity are refused)")
                return
            if "integer" in wanted and instance.is_integer():
                # a float holds every integer exactly only up to 2**53: beyond, no digits to suggest
                hint = f"write {int(instance)}" if abs(instance) < 2 ** 53 else "and far beyond any count here"
                yield ValidationError(f"{instance!r} is not an integer ({hint})")
                return
        yield from errors

    checker = base.TYPE_CHECKER.redefine_many({"integer": _is_integer, "number": _is_number})
    cls = jsonschema.validators.extend(base, {"properties": set_defaults, "type": strict_type},
                                       type_checker=checker)
    return cls(schema, registry=registry)


def non_finite_keys(value: Any, path: tuple = ()) -> dict[str, float]:
    """``{dotted key: value}`` of every NaN or infinite number anywhere in
    ``value`` (a config mapping), whatever the schema says of the key; list
    items are named ``key[i]``."""
    if isinstance(value, float) and not math.isfinite(value):
        return {_dotted(path): value}
    out: dict[str, float] = {}
    if isinstance(value, dict):
        for n, v in value.items():
            out.update(non_finite_keys(v, (*path, str(n))))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            out.update(non_finite_keys(v, (*path, i)))
    return out


def non_string_keys(value: Any, path: tuple = ()) -> list[tuple[str, Any]]:
    """(dotted key of the mapping, key) of every key that is not a string anywhere in
    ``value`` (a config mapping as another reader than :mod:`opnav.core.yamlfile` made it)."""
    out: list[tuple[str, Any]] = []
    if isinstance(value, dict):
        for n, v in value.items():
            if not isinstance(n, str):
                out.append((_dotted(path), n))
            else:
                out += non_string_keys(v, (*path, n))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            out += non_string_keys(v, (*path, i))
    return out


def _copy(value: Any) -> Any:
    import copy

    return copy.deepcopy(value)


def schema_problems(config: dict, schema_path: Path = SCHEMA_PATH) -> list[str]:
    """The schema's problems of ``config`` (filling defaults in place), one line each naming
    its key: every number anywhere finite (:func:`non_finite_keys`), then the JSON schema
    (types, ranges, patterns, the registry of names; integer keys take ints only)."""
    keys = non_string_keys(config)
    if keys:        # every later layer indexes and sorts by name: refuse first
        return [f"invalid {f'config key {where!r}' if where else 'config (top level)'}: the key {k!r} is not a "
                "string (YAML 1.1 reads on/off/yes/no, null and numbers as such; quote it)" for where, k in keys]
    bad = non_finite_keys(config)
    lines = [f"invalid config key '{k}': {v} is not a finite number "
             "(NaN and infinity are refused)" for k, v in bad.items()]
    validator = _validator(schema_path)
    # one line per key, its first problem: that 1e300 for a count is also over the maximum is noise
    seen = set(bad)
    for err in sorted(validator.iter_errors(config), key=lambda e: [str(p) for p in e.absolute_path]):
        key = _dotted(err.absolute_path)
        if key not in seen:
            seen.add(key)
            where = f"config key '{key}'" if key else "config (top level)"
            lines.append(f"invalid {where}: {_message(err)}")
    return lines


#: Config keys that moved out of the config, and their one home now: a config that still sets
#: one is told where it went (the schema alone would say only "unexpected").
MOVED_KEYS = {
    "approach.accuracy_target_arcsec": "the analysis plan's claims.A-C1.margins.target_arcsec",
    "approach.em.converge_frac_of_bound": "the analysis plan's settings.converge_frac_of_bound",
    "landing.mc.yaw_ratio": "the analysis plan's claims.B-C3.margins.yaw_ratio",
    "landing.equivalence.alpha": "the analysis plan's level (one interval level for every verdict)",
}


def _message(err) -> str:
    """jsonschema's message, shortened where it would print a long instance; a key that moved
    out of the config (:data:`MOVED_KEYS`) named with its new home."""
    if err.validator == "additionalProperties" and isinstance(err.instance, dict):
        allowed = set((err.schema or {}).get("properties") or {})
        where = _dotted(err.absolute_path)
        moved = [(k, MOVED_KEYS[f"{where}.{k}" if where else k]) for k in err.instance
                 if k not in allowed and (f"{where}.{k}" if where else k) in MOVED_KEYS]
        if moved:
            k, home = moved[0]
            return (f"'{k}' is no config key any more: its one home is {home} "
                    "(src/opnav/data/analysis_plan.yaml); remove it from the config")
    if err.validator == "pattern" and isinstance(err.instance, str):
        shown = err.instance if len(err.instance) <= 60 else err.instance[:57] + "..."
        return f"{shown!r} is not a valid name here (pattern {err.validator_value})"
    if err.validator == "maxLength" and isinstance(err.instance, str):
        return (f"{err.instance[:24]!r}{'...' if len(err.instance) > 24 else ''} has {len(err.instance)} characters, "
                f"at most {err.validator_value} (it names files and rules)")
    msg = err.message
    return msg if len(msg) <= 300 else msg[:297] + "..."


def core_problems(config: dict, schema_path: Path = SCHEMA_PATH, *, root: str | Path | None = None,
                  workdir: str | Path | None = None, sections: tuple[str, ...] | None = None,
                  workflow: bool = False) -> list[str]:
    """The problem lines of the schema and :mod:`opnav.core.checks` (no physics): what
    :func:`validate_config` raises; :func:`opnav.preflight.check_config` adds the paper
    packages' physics checks and the studies to the same lines."""
    lines = schema_problems(config, schema_path)
    broken = {section_of(line) for line in lines}
    if "" not in broken:        # a top-level schema error: no section is safe to read
        from opnav.core.checks import config_problems

        lines += config_problems(config, root, workdir, skip=broken, sections=sections, workflow=workflow)
    return list(dict.fromkeys(lines))


def validate_config(config: dict, schema_path: Path = SCHEMA_PATH, *, root: str | Path | None = None,
                    workdir: str | Path | None = None, sections: tuple[str, ...] | None = None,
                    workflow: bool = False) -> dict:
    """Validate ``config`` in place (filling defaults); raise :class:`ConfigError` with one
    line per problem, each naming its key: the schema (:func:`schema_problems`) and the
    physics-free cross-key checks of :func:`opnav.core.checks.config_problems`
    (``results_dir``, names, bounds). ``root`` is the checkout, ``workdir`` where a relative
    ``results_dir`` lands (default ``root``); ``sections`` limits the cross-key checks to
    those sections; ``workflow`` adds what only the workflow reads (growing windows,
    job-graph bounds, study names and sizes). The physics checks and the study planner
    run in :func:`opnav.preflight.check_config` (the Snakefile's and the CLI's)."""
    lines = core_problems(config, schema_path, root=root, workdir=workdir, sections=sections,
                          workflow=workflow)
    if lines:
        raise ConfigError("\n".join(lines))
    return config


def section_of(line: str) -> str:
    """The top-level section a problem line names ('' for the top level itself)."""
    m = re.match(r"invalid config key '([^'.\[]+)", line)
    return m.group(1) if m else ""


def load_config(path: str | Path | None = None, overlays: list[str | Path] = (), *,
                workflow: bool = False, validate: bool = True) -> dict:
    """Read ``path`` (default: the checkout's ``config/config.yaml``, or, for an
    installed package run outside a checkout, nothing: the schema's defaults,
    which a test keeps equal to ``config/config.yaml``), merge the
    ``overlays`` in order (nested keys merged, as ``snakemake --configfile``
    does), validate, return.

    ``config/quick.yaml`` is an overlay: ``load_config(overlays=[quick])``.
    Every file is read by :func:`read_config_file` (the strict reader: errors name the
    file, line and key); a bad value raises :class:`ConfigError` naming the key
    (:func:`validate_config`: schema and physics-free checks; ``validate=False`` returns
    the merged files unvalidated, for a caller that sets more keys and checks once).
    """
    if path is None:
        try:
            path = repo_root() / "config" / "config.yaml"
        except ConfigError:
            path = None  # installed without a checkout: the schema defaults alone
    files = [*([Path(path)] if path is not None else []), *map(Path, overlays)]
    config: dict = {}
    for f in files:
        _merge(config, read_config_file(f))
    # results_dir is relative to the checkout that holds config/config.yaml
    root = Path(path).resolve().parents[1] if path is not None and Path(path).parent.name == "config" else None
    if not validate:
        return config
    return validate_config(config, SCHEMA_PATH, root=root, workflow=workflow)


def _merge(base: dict, new: dict) -> None:
    for k, v in new.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge(base[k], v)
        else:
            base[k] = v
