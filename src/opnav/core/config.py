"""Configuration: load a YAML config, validate it against the project schema.

The schema (``opnav/schemas/config.schema.yaml``, shipped with the package, and
the section files it references) is the single source of defaults, types and ranges. Snakemake
validates with :func:`snakemake.utils.validate`; the command-line tools use
:func:`load_config`, which applies the same schema with the same defaults so a
CLI run and a pipeline run see the same parameters.
"""

from __future__ import annotations

import functools
import math
import re
from pathlib import Path
from typing import Any

import yaml


from opnav.core.errors import ConfigError  # noqa: E402  (defined in the base layer; its home for users)

__all__ = ["ConfigError", "validate_config", "load_config", "read_config_file", "validate_study_value"]


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
                yield ValidationError(f"{instance!r} is not an integer (write {int(instance)})")
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


def _dotted(path) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _copy(value: Any) -> Any:
    import copy

    return copy.deepcopy(value)


def validate_config(config: dict, schema_path: Path = SCHEMA_PATH, *, physics: bool = True,
                    root: str | Path | None = None, workdir: str | Path | None = None,
                    sections: tuple[str, ...] | None = None, workflow: bool = False) -> dict:
    """Validate ``config`` in place (filling defaults); raise :class:`ConfigError`
    with one line per problem, each naming its key: every problem of every layer
    in one pass, before any job runs.

    The layers: every number anywhere must be finite (:func:`non_finite_keys`);
    the JSON schema (integer keys take ints only); and, with ``physics``, on each
    section the schema passed, the cross-key checks of
    :func:`opnav.core.checks.config_problems` (``results_dir``; durations, rates,
    geometry, camera scenarios, method names, ...; the parameter studies, each value
    checked as its own config; the job-graph bounds). ``root`` is the checkout,
    ``workdir`` where a relative ``results_dir`` lands (default ``root``);
    ``sections`` limits the physics checks to those sections (a study value's
    config: its paper's); ``workflow`` adds what only the workflow reads (the studies,
    growing windows, job-graph bounds): the Snakefile and ``opnav study`` set it.
    """
    bad = non_finite_keys(config)
    lines = [f"invalid config key '{k}': {v} is not a finite number "
             "(NaN and infinity are refused)" for k, v in bad.items()]
    validator = _validator(schema_path)
    for err in sorted(validator.iter_errors(config), key=lambda e: [str(p) for p in e.absolute_path]):
        key = _dotted(err.absolute_path)
        if key not in bad:
            where = f"config key '{key}'" if key else "config (top level)"
            lines.append(f"invalid {where}: {err.message}")
    if physics:
        from opnav.core.checks import config_problems

        broken = {_top(line) for line in lines}
        if "" not in broken:        # a top-level schema error: no section is safe to read
            lines += config_problems(config, root, workdir, skip=broken, sections=sections, workflow=workflow,
                                     plan_studies=_plan_studies)
    if lines:
        raise ConfigError("\n".join(dict.fromkeys(lines)))
    return config


def _plan_studies(config: dict) -> None:
    from opnav.studies import plan

    plan(config, validate_paper=validate_study_value)


def validate_study_value(merged: dict, paper: str) -> None:
    """A parameter study's value: its merged config (every study removed) through the
    schema and the physics checks of the study's paper section (:func:`opnav.studies.plan`)."""
    validate_config(merged, sections=(paper,))


def _top(line: str) -> str:
    """The top-level section a problem line names ('' for the top level itself)."""
    m = re.match(r"invalid config key '([^'.\[]+)", line)
    return m.group(1) if m else ""


#: Upper bound on the nodes of a config file once its aliases are expanded (a "billion
#: laughs" file of a few lines expands to 10^9; every config of the project has < 5,000).
MAX_YAML_NODES = 100_000


class _StrictLoader(_YAML_LOADER):  # type: ignore[misc, valid-type]
    """The safe loader, refusing a key given twice in one mapping (YAML keeps the
    last silently: a duplicated ``landing:`` block would drop the first)."""

    def construct_mapping(self, node, deep=False):
        seen: dict = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue                 # `<<: *anchor`: its keys may be overridden
            key = self.construct_object(key_node, deep=True)
            try:
                hash(key)
            except TypeError:
                continue                 # SafeConstructor raises its own error below
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r} (first given on line {seen[key] + 1})",
                    key_node.start_mark)
            seen[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)


def _expanded_nodes(node, budget: int) -> int:
    """The number of nodes of the document once every alias is expanded, counting
    stops past ``budget``; raises ``ValueError`` for a recursive alias."""
    memo: dict[int, int] = {}
    active: set[int] = set()

    def size(n) -> int:
        i = id(n)
        if i in memo:
            return memo[i]
        if i in active:
            raise ValueError("a recursive alias (an anchor used inside itself)")
        active.add(i)
        total = 1
        if isinstance(n, yaml.SequenceNode):
            for c in n.value:
                total += size(c)
                if total > budget:
                    break
        elif isinstance(n, yaml.MappingNode):
            for k, v in n.value:
                total += size(k) + size(v)
                if total > budget:
                    break
        active.discard(i)
        memo[i] = total
        return total

    return size(node)


def read_config_file(path: str | Path) -> dict:
    """The mapping in the user config file ``path`` (a YAML document), or
    :class:`ConfigError` naming the file and, for a parse error, the line: the file
    missing, unreadable, not UTF-8 text, empty, not valid YAML (a tab in the
    indentation, an unknown ``!!tag``), a key given twice, aliases expanding past
    :data:`MAX_YAML_NODES` nodes, or a top level that is not a mapping. The loader of
    every user config: the ``opnav`` CLI's and the Snakefile's (which re-reads the
    ``--configfile`` files Snakemake has read)."""
    f = Path(path)
    if not f.exists():
        raise ConfigError(f"config file {f}: not found")
    if not f.is_file():
        raise ConfigError(f"config file {f}: not a regular file")
    try:
        raw = f.read_bytes()
    except OSError as exc:
        raise ConfigError(f"config file {f}: cannot be read ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ConfigError(f"config file {f}, line {line}: not UTF-8 text (byte 0x{raw[exc.start]:02x}); "
                          "a YAML config is expected") from None
    if "\0" in text:
        line = text[:text.index("\0")].count("\n") + 1
        raise ConfigError(f"config file {f}, line {line}: a NUL byte (binary data); a YAML config is expected")
    loader = _StrictLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            raise ConfigError(f"config file {f}: empty (no config keys); give a mapping such as "
                              "'landing: {mc: {n_runs: 10}}'")
        try:
            n = _expanded_nodes(node, MAX_YAML_NODES)
        except ValueError as exc:
            raise ConfigError(f"config file {f}, line {node.start_mark.line + 1}: {exc}") from None
        if n > MAX_YAML_NODES:
            raise ConfigError(f"config file {f}: its aliases expand to more than {MAX_YAML_NODES} "
                              "nodes (an alias bomb?); write the values out")
        if not isinstance(node, yaml.MappingNode):
            kind = "a list" if isinstance(node, yaml.SequenceNode) else f"the scalar {node.value[:40]!r}"
            raise ConfigError(f"config file {f}, line {node.start_mark.line + 1}: the top level must be a "
                              f"mapping of config keys (approach, landing, ...), not {kind}")
        data = loader.construct_document(node)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        what = " ".join(filter(None, [getattr(exc, "context", None), getattr(exc, "problem", None)])) \
            or str(exc).splitlines()[0]
        lines = text.splitlines()
        if mark and mark.line < len(lines) and "\t" in lines[mark.line][:mark.column + 1]:
            what += " (a tab: YAML indents with spaces)"
        raise ConfigError(f"config file {f}{where}: not valid YAML: {what}") from None
    finally:
        loader.dispose()
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise ConfigError(f"config file {f}: top-level key {bad[0]!r} is not a name")
    return data


def load_config(path: str | Path | None = None, overlays: list[str | Path] = (), *,
                workflow: bool = False) -> dict:
    """Read ``path`` (default: the checkout's ``config/config.yaml``, or, for an
    installed package run outside a checkout, nothing: the schema's defaults,
    which a test keeps equal to ``config/config.yaml``), merge the
    ``overlays`` in order (nested keys merged, as ``snakemake --configfile``
    does), validate, return.

    ``config/quick.yaml`` is an overlay: ``load_config(overlays=[quick])``.
    Every file is read by :func:`read_config_file` (errors name the file and
    line); a bad value raises :class:`ConfigError` naming the key.
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
    return validate_config(config, SCHEMA_PATH, root=root, workflow=workflow)


def _merge(base: dict, new: dict) -> None:
    for k, v in new.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge(base[k], v)
        else:
            base[k] = v
