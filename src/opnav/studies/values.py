"""A study value in the config: dotted config paths, the simulation's view of a config
(:data:`SIM_KEYS`), its content digest (shared Monte-Carlo jobs) and the value's file label.

Light on purpose (numpy only): a Monte-Carlo job imports it for :func:`config_digest`.
"""

from __future__ import annotations

import copy
import hashlib
import json
import re
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

__all__ = [
    "SIM_KEYS",
    "config_digest",
    "display_value",
    "get_path",
    "in_shape",
    "instance_label",
    "project",
    "set_path",
    "simulation_shapes",
    "slug",
]


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


def in_shape(shape: Mapping, parts: list[str]) -> bool:
    """Whether the key path ``parts`` is one the simulation view ``shape`` reads."""
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
def slug(value) -> str:
    """A value as file-name-safe text: ``45``, ``0.00025``, ``0.1,0.1,0.2``, ``true``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.12g}"
    if isinstance(value, (list, tuple)):
        return ",".join(slug(v) for v in value)
    if isinstance(value, Mapping):
        return ",".join(f"{k}={slug(value[k])}" for k in sorted(value))
    return re.sub(r"[^A-Za-z0-9._,+-]", "_", str(value))


def display_value(value):
    """A swept value for a table cell: lists as '(a, b, c)' (a LaTeX row must not start with '[')."""
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(str(display_value(v)) for v in value) + ")"
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
    return "_".join(f"{short[k]}~{slug(values[k])}" for k in values)



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
    """``{paper: the config section projected on SIM_KEYS[paper]}`` (keys sorted), with the
    analysis plan's numbers the rules carry beside them (:func:`opnav.core.planvalues.with_plan_values`)."""
    from opnav.core.planvalues import with_plan_values

    out: dict[str, dict] = {}
    for paper, keys in SIM_KEYS.items():
        view: dict = {}
        for dotted in keys:
            *parents, last = dotted.split(".")
            src, dst = config[paper], view
            for part in parents:
                src, dst = src[part], dst.setdefault(part, {})
            dst[last] = copy.deepcopy(src[last])
        out[paper] = _sorted(with_plan_values(paper, view))
    return out


def _sorted(x):
    return {k: _sorted(x[k]) for k in sorted(x)} if isinstance(x, Mapping) else x

