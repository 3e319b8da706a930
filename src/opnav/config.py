"""Configuration: load a YAML config, validate it against the project schema.

The schema (``opnav/schemas/config.schema.yaml``, shipped with the package, and
the section files it references) is the single source of defaults, types and ranges. Snakemake
validates with :func:`snakemake.utils.validate`; the command-line tools use
:func:`load_config`, which applies the same schema with the same defaults so a
CLI run and a pipeline run see the same parameters.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml


class ConfigError(ValueError):
    """A configuration value is missing, of the wrong type or out of range."""


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
SCHEMA_PATH = Path(__file__).resolve().parent / "schemas" / "config.schema.yaml"


def repo_root(start: Path | None = None) -> Path:
    """The checkout that holds ``config/config.yaml`` (searching upwards from ``start``)."""
    here = (start or Path.cwd()).resolve()
    for cand in [here, *here.parents, Path(__file__).resolve().parents[2]]:
        if (cand / "config" / "config.yaml").is_file() and (cand / "Snakefile").is_file():
            return cand
    raise ConfigError(
        "cannot find config/config.yaml: run from the opnav-repro checkout or pass --config"
    )


def _validator(schema_path: Path):
    import jsonschema
    from jsonschema import Draft202012Validator
    from referencing import Registry, Resource

    from referencing.jsonschema import DRAFT202012

    def load(path: Path) -> dict:
        # Without "$schema" the extended class below (which fills defaults) is
        # kept for referenced section files too: jsonschema otherwise switches
        # to the plain Draft 2020-12 validator for every schema naming its
        # dialect, and nested sections were never filled.
        contents = yaml.safe_load(path.read_text())
        contents.pop("$schema", None)
        return contents

    def retrieve(uri: str) -> Resource:
        path = Path(uri.removeprefix("file://"))
        return Resource.from_contents(load(path), default_specification=DRAFT202012)

    schema = load(schema_path)
    schema["$id"] = schema_path.resolve().as_uri()
    registry = Registry(retrieve=retrieve)

    base = Draft202012Validator
    validate_props = base.VALIDATORS["properties"]

    def set_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for prop, sub in properties.items():
                if "default" in sub and prop not in instance:
                    instance[prop] = _copy(sub["default"])
        yield from validate_props(validator, properties, instance, schema)

    cls = jsonschema.validators.extend(base, {"properties": set_defaults})
    return cls(schema, registry=registry)


def _copy(value: Any) -> Any:
    import copy

    return copy.deepcopy(value)


def validate_config(config: dict, schema_path: Path) -> dict:
    """Validate ``config`` in place (filling defaults); raise :class:`ConfigError`."""
    validator = _validator(schema_path)
    errors = sorted(validator.iter_errors(config), key=lambda e: list(e.absolute_path))
    if errors:
        err = errors[0]
        key = ".".join(str(p) for p in err.absolute_path)
        where = f"config key '{key}'" if key else "config (top level)"
        raise ConfigError(f"invalid {where}: {err.message}")
    return config


def load_config(path: str | Path | None = None, overlays: list[str | Path] = ()) -> dict:
    """Read ``path`` (default: the checkout's ``config/config.yaml``, or, for an
    installed package run outside a checkout, nothing: the schema's defaults,
    which a test keeps equal to ``config/config.yaml``), merge the
    ``overlays`` in order (nested keys merged, as ``snakemake --configfile``
    does), validate, return.

    ``config/quick.yaml`` is an overlay: ``load_config(overlays=[quick])``.
    Raises :class:`ConfigError` naming the file if it is missing, or the key if
    a value is invalid.
    """
    if path is None:
        try:
            path = repo_root() / "config" / "config.yaml"
        except ConfigError:
            path = None  # installed without a checkout: the schema defaults alone
    files = [*([Path(path)] if path is not None else []), *map(Path, overlays)]
    config: dict = {}
    for f in files:
        if not f.is_file():
            raise ConfigError(f"config file not found: {f}")
        data = yaml.safe_load(f.read_text()) or {}
        if not isinstance(data, dict):
            raise ConfigError(f"config file {f} must hold a mapping at the top level")
        _merge(config, data)
    return validate_config(config, SCHEMA_PATH)


def _merge(base: dict, new: dict) -> None:
    for k, v in new.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge(base[k], v)
        else:
            base[k] = v
