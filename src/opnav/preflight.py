"""Every check of a config before any job: the workflow's validation step and the CLI's.

:func:`check_config` runs, in one pass, one line per problem naming its key:

1. the schema and the physics-free cross-key checks (:func:`opnav.core.config.core_problems`,
   what :func:`opnav.core.config.load_config` runs everywhere);
2. the physics checks of each paper section that passed step 1, where the physics is
   (:func:`opnav.approach.preflight.approach_problems`,
   :func:`opnav.landing.preflight.landing_problems`);
3. with ``workflow`` (the Snakefile, ``opnav study``): every parameter study planned, each
   value checked as its own config by steps 1 and 2 for its paper
   (:func:`opnav.studies.planning.plan` with :func:`validate_study_value`), once the sections it
   reads are sound and the job graph is within its bounds.

It sits above the core and the papers (it imports both), so the core's config loader
imports no paper package, numba or scipy.
"""

from __future__ import annotations

import re
from pathlib import Path

from opnav.core.config import SCHEMA_PATH, schema_problems, section_of
from opnav.core.errors import ConfigError

__all__ = ["check_config", "problems", "validate_study_value", "check_files"]

#: Lines of the landing section that do not make it unsound for a study: a study flies
#: the base camera, not the scenarios.
_SCENARIO_ONLY = re.compile(r"invalid config key 'landing\.(scenarios|headline_scenario)\b")


def problems(config: dict, *, root: str | Path | None = None, workdir: str | Path | None = None,
             sections: tuple[str, ...] | None = None, workflow: bool = False) -> list[str]:
    """Every problem line of ``config`` (validated in place, defaults filled): module docstring."""
    from opnav.core.checks import config_problems

    lines = schema_problems(config, SCHEMA_PATH)
    unsound = {section_of(ln) for ln in lines}       # a schema problem: the section cannot be read
    if "" in unsound:
        return lines
    found = config_problems(config, root, workdir, skip=set(unsound), sections=sections, workflow=workflow)
    lines += found
    unsound |= {section_of(ln) for ln in found if not _SCENARIO_ONLY.match(ln)}
    want = set(sections) if sections is not None else {"approach", "landing", "studies"}
    for name in ("approach", "landing"):
        if name in want and name not in unsound and name in config:
            if name == "approach":
                from opnav.approach.preflight import approach_problems as check
            else:
                from opnav.landing.preflight import landing_problems as check
            found = check(config[name])
            lines += found
            unsound |= {section_of(ln) for ln in found if not _SCENARIO_ONLY.match(ln)}
    # The studies merge each value into the whole config: planned only when every section
    # but results_dir (paths, not read by a study) is sound, so a broken top-level key is
    # said once, not once per study value (issue 57).
    if workflow and "studies" in want and config.get("studies") and not unsound - {"results_dir"}:
        from opnav.studies.planning import plan

        try:
            plan(config, validate_paper=validate_study_value)
        except ConfigError as exc:
            lines += str(exc).splitlines()
    return list(dict.fromkeys(lines))


def check_config(config: dict, *, root: str | Path | None = None, workdir: str | Path | None = None,
                 sections: tuple[str, ...] | None = None, workflow: bool = False) -> dict:
    """``config`` validated in place by :func:`problems`, or :class:`ConfigError` (one line
    per problem)."""
    lines = problems(config, root=root, workdir=workdir, sections=sections, workflow=workflow)
    if lines:
        raise ConfigError("\n".join(lines))
    return config


def validate_study_value(merged: dict, paper: str) -> None:
    """A parameter study's value: its merged config (every study removed) through the
    schema, the core checks and the physics checks of the study's paper section. Only the
    lines about that section are the value's: the rest are the base config's, said once
    by the base's own check."""
    lines = [ln for ln in problems(merged, sections=(paper,)) if section_of(ln) == paper]
    if lines:
        raise ConfigError("\n".join(lines))


def check_files(files: list[str], root: Path | None = None) -> list[str]:
    """``opnav check``: the problem lines of config ``files`` read as the Snakefile's strict
    reader reads them (:func:`opnav.core.yamlfile.read_config_file`: regular files only,
    opened only after a size check, UTF-8, YAML 1.2 rules where YAML 1.1 reads otherwise,
    duplicate and non-string keys refused, ``__use_yte__`` refused without evaluating
    anything), merged on the checkout's ``config/config.yaml`` in order (as ``snakemake
    --configfile A B`` does) and checked by :func:`problems` with the studies, as the
    workflow checks before any job. Each line begins with the file it names: the last one
    given that sets the key (or a parent or child of it), else all of them."""
    import json

    from opnav.core.config import _merge, read_config_file, repo_root

    lines: list[str] = []
    read: list[tuple[str, dict]] = []
    for f in files:
        try:
            read.append((f, read_config_file(f)))
        except ConfigError as exc:
            lines += str(exc).splitlines()            # each names the file already
    if lines:
        return lines
    try:
        root = root or repo_root()
        base = read_config_file(root / "config" / "config.yaml")
    except ConfigError as exc:
        return str(exc).splitlines()
    config: dict = base
    for _, data in read:
        _merge(config, json.loads(json.dumps(data)))
    return [f"{_owner(line, read)}: {line}" for line in problems(config, root=root, workdir=Path.cwd(),
                                                                 workflow=True)]


def _owner(line: str, read: list[tuple[str, dict]]) -> str:
    """``config file F`` for the last file in ``read`` that sets the key ``line`` names (or a
    parent or a child of it); else every file, merged on the defaults."""
    m = re.match(r"invalid config key '([^']+)'", line)
    parts = [p for p in re.split(r"\.|\[\d+\]", m.group(1)) if p] if m else []
    for f, data in reversed(read):
        node, depth = data, 0
        for p in parts:
            if not isinstance(node, dict) or p not in node:
                break
            node, depth = node[p], depth + 1
        # the whole key, or a parent of it holding a value (a list, a scalar): this file sets it
        if parts and (depth == len(parts) or (depth and not isinstance(node, dict))):
            return f"config file {f}"
    return f"config files {', '.join(f for f, _ in read)} (merged on config/config.yaml)"
