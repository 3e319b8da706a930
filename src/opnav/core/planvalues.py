"""The analysis plan's numbers that the pipeline itself computes with, read without the report layer.

The analysis plan (``data/analysis_plan.yaml``, parsed and checked by :mod:`opnav.report.plan`) is
the one home of every verdict margin. A few of them also set what the paper packages compute:
paper A's accuracy target (A-C1's ``target_arcsec``) is the threshold of the identifiable label,
the stars study's attitude objection, the roll-rate search and the A-X1 rows. This module reads
those numbers from the same file (``claims.<id>.margins.<name>.value``), so that ``approach/`` and
``core/checks.py`` need not import ``report/`` and no config key holds a second copy. Units: those
of the margin (its name says them).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import yaml

PLAN_FILE = Path(__file__).resolve().parents[1] / "data" / "analysis_plan.yaml"

#: paper A's accuracy claim: A-C1's target (arcsec), the threshold the approach code computes with
ACCURACY_TARGET = ("A-C1", "target_arcsec")


@lru_cache(maxsize=8)
def _margins(path: str, mtime_ns: int) -> tuple[tuple[str, str, object], ...]:
    """Every ``(claim id, margin name, value)`` of the plan at ``path`` (``mtime_ns``: part of the
    cache key only, so an edited plan is read again)."""
    del mtime_ns
    raw = yaml.load(Path(path).read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    claims = raw.get("claims") if isinstance(raw, dict) else None
    if not isinstance(claims, dict):
        raise ValueError(f"{path}: the analysis plan needs a 'claims' mapping")
    return tuple((str(cid), str(name), m.get("value") if isinstance(m, dict) else None)
                 for cid, c in claims.items() if isinstance(c, dict)
                 for name, m in (c.get("margins") or {}).items())


def margin(claim_id: str, name: str, path: str | Path | None = None) -> float:
    """``claims.<claim_id>.margins.<name>.value`` of the analysis plan at ``path`` (default: the
    package's ``data/analysis_plan.yaml``); ValueError naming the key when it is absent or not a number."""
    p = Path(path) if path is not None else PLAN_FILE
    try:
        margins = _margins(str(p), p.stat().st_mtime_ns)
    except OSError as exc:
        raise ValueError(f"{p}: cannot read the analysis plan ({exc.strerror})") from None
    value = next((v for cid, n, v in margins if (cid, n) == (claim_id, name)), None)
    if value is None:
        raise ValueError(f"{p}: claims.{claim_id}.margins.{name}.value is missing")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{p}: claims.{claim_id}.margins.{name}.value must be a number, got {value!r}")
    return float(value)


def accuracy_target_arcsec(path: str | Path | None = None) -> float:
    """Paper A's claimed accuracy, arcsec: A-C1's ``target_arcsec`` (:data:`ACCURACY_TARGET`)."""
    return margin(*ACCURACY_TARGET, path=path)
