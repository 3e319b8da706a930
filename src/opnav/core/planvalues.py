"""The analysis plan's numbers that the pipeline itself computes with, read without the report layer.

The analysis plan (``data/analysis_plan.yaml``, parsed and checked by :mod:`opnav.report.plan`) is
the one home of every verdict margin. A few of them also set what the paper packages compute:
paper A's accuracy target (A-C1's ``target_arcsec``) is the threshold of the identifiable label,
the stars study's attitude objection, the roll-rate search and the A-X1 rows; the plan's
``settings`` (numbers the pipeline computes evidence with, e.g. ``converge_frac_of_bound``, paper
A's converged label) likewise. This module reads those numbers from the same file
(``claims.<id>.margins.<name>.value``, ``settings.<name>.value``), so that ``approach/`` and
``core/checks.py`` need not import ``report/`` and no config key holds a second copy. Units: those
of the margin or setting (its name says them).
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import yaml

PLAN_FILE = Path(__file__).resolve().parents[1] / "data" / "analysis_plan.yaml"

#: paper A's accuracy claim: A-C1's target (arcsec), the threshold the approach code computes with
ACCURACY_TARGET = ("A-C1", "target_arcsec")


@lru_cache(maxsize=8)
def _values(path: str, mtime_ns: int) -> tuple[tuple[str, object], ...]:
    """Every ``(dotted key, value)`` the plan at ``path`` holds as a number's home:
    ``claims.<id>.margins.<name>`` and ``settings.<name>`` (``mtime_ns``: part of the cache key
    only, so an edited plan is read again)."""
    del mtime_ns
    raw = yaml.load(Path(path).read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    claims = raw.get("claims") if isinstance(raw, dict) else None
    if not isinstance(claims, dict):
        raise ValueError(f"{path}: the analysis plan needs a 'claims' mapping")
    out = [(f"claims.{cid}.margins.{name}", m.get("value") if isinstance(m, dict) else None)
           for cid, c in claims.items() if isinstance(c, dict) for name, m in (c.get("margins") or {}).items()]
    settings = raw.get("settings") or {}
    out += [(f"settings.{name}", m.get("value") if isinstance(m, dict) else None)
            for name, m in (settings.items() if isinstance(settings, dict) else ())]
    return tuple(out)


def _number(key: str, path: str | Path | None) -> float:
    """The number at the plan's dotted ``key`` (``.value``); ValueError naming it when absent or not a number."""
    p = Path(path) if path is not None else PLAN_FILE
    try:
        values = _values(str(p), p.stat().st_mtime_ns)
    except OSError as exc:
        raise ValueError(f"{p}: cannot read the analysis plan ({exc.strerror})") from None
    value = next((v for k, v in values if k == key), None)
    if value is None:
        raise ValueError(f"{p}: {key}.value is missing")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{p}: {key}.value must be a number, got {value!r}")
    return float(value)


def margin(claim_id: str, name: str, path: str | Path | None = None) -> float:
    """``claims.<claim_id>.margins.<name>.value`` of the analysis plan at ``path`` (default: the
    package's ``data/analysis_plan.yaml``); ValueError naming the key when it is absent or not a number."""
    return _number(f"claims.{claim_id}.margins.{name}", path)


def setting(name: str, path: str | Path | None = None) -> float:
    """``settings.<name>.value`` of the analysis plan at ``path`` (default: the package's plan)."""
    return _number(f"settings.{name}", path)


#: The plan's settings the paper code computes with, by the config section and sub-section whose
#: rules carry them in their params (where the config would hold them: a change reruns the rule)
IN_PARAMS = {"approach": {"em": ("converge_frac_of_bound",)}}


def with_plan_values(section: str, values: Mapping) -> dict:
    """``values`` (a rule's part of the config section ``section``) with the plan's numbers of
    :data:`IN_PARAMS` inside the sub-sections that use them (the workflow's rule params and the
    studies' simulation shapes both build on this)."""
    out = dict(values)
    for sub, names in IN_PARAMS.get(section, {}).items():
        if sub in out:
            out[sub] = {**out[sub], **{n: setting(n) for n in names}}
    return out


def converge_frac_of_bound(path: str | Path | None = None) -> float:
    """Paper A's converged label: a run within this fraction of the 1-sigma bound of its data
    from the ML estimate of that data (dimensionless; the plan's ``settings.converge_frac_of_bound``)."""
    return setting("converge_frac_of_bound", path)


def accuracy_target_arcsec(path: str | Path | None = None) -> float:
    """Paper A's claimed accuracy, arcsec: A-C1's ``target_arcsec`` (:data:`ACCURACY_TARGET`)."""
    return margin(*ACCURACY_TARGET, path=path)
