"""The analysis plan (``data/analysis_plan.yaml``): every claim's test, frozen, with its amendments.

:func:`load_plan` parses and checks the file (its header states the test schema; a malformed
entry stops with one line naming the key). :class:`Plan` gives the scorer
(:mod:`opnav.report.scorer`) each claim's :class:`ClaimTest`, resolves the numbers a test names
(``{margin: ...}``, ``{setting: ...}``; published values come from the evidence rows of role
``published``), and records what was read so :meth:`Plan.unused` can name a margin no verdict
reads. :attr:`Plan.version` and :attr:`Plan.checksum` (sha256 of the file) are printed in the
claims table; :meth:`Plan.amended` rebuilds the plan as it stood before an amendment, so the
scorer can recompute an amendment's verdicts before and after on the same evidence.
"""

from __future__ import annotations

import copy
import hashlib
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from opnav.core import published

PLAN_FILE = published.PUBLISHED_FILE.with_name("analysis_plan.yaml")
COMPARISONS = ("band", "equivalence", "superiority", "order", "sign", "count")
UNIT_ROLES = ("as_written", "faithful", "diagnostic", "beyond")
_CLAIM_KEYS = ("paper", "title", "sentence", "where", "published", "quantity", "units", "comparison", "margins",
               "variants", "depends_on", "test")
#: parameters of each comparison whose value is a number reference ({margin:}, {setting:}, {published:})
NUMBER_PARAMS = {
    "band": ("lower", "upper", "center", "abs", "rel", "spread_k", "max_rel", "factor", "upper_factor"),
    "equivalence": ("margin",),
    "superiority": ("margin", "min_effect"),
    "order": (),
    "sign": ("above", "below"),
    "count": ("equals", "at_most", "at_least"),
}


#: settings the pipeline reads to compute evidence (not named in a test): who reads each
EVIDENCE_SETTINGS = {
    "converge_threshold_sweep_m": "workflow/scripts/landing_summary.py (B-C2's sweep)",
    "converge_threshold_m": "workflow/scripts/landing_summary.py and B-C2's condition",
    "optimum_angle_grid": "rule landing_optima (B-C8's count)",
    "converge_frac_of_bound": "paper A's converged label (approach.setup.EMSettings, every rule's params via "
                              "workflow/rules/common.smk's PLAN_IN_PARAMS)",
}


def join(items, none: str = "none") -> str:
    """'a', 'a and b', 'a, b and c' (``none`` for no item)."""
    items = [i for i in items if i]
    if not items:
        return none
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


class PlanError(ValueError):
    """The analysis plan is malformed or lacks an entry a verdict needs (one line, naming the key)."""


def _margin_ok(m: Any) -> bool:
    return (isinstance(m, Mapping) and isinstance(m.get("value"), (int, float)) and not isinstance(m.get("value"), bool)
            and math.isfinite(float(m["value"])) and isinstance(m.get("reason"), str) and m["reason"].strip() != "")


@dataclass(frozen=True)
class Condition:
    """One condition of a claim's test (the plan header: ``conditions``)."""

    quantity: str
    comparison: str
    params: Mapping[str, Any]
    index: int

    def get(self, k: str, default: Any = None) -> Any:
        return self.params.get(k, default)


@dataclass(frozen=True)
class WouldTake:
    """One ``would_take`` entry: ``kind`` sweep | margin | choice | quote, and its parameters."""

    kind: str
    params: Mapping[str, Any]


@dataclass(frozen=True)
class ClaimTest:
    """A claim's test as the plan declares it (the plan header gives each field's meaning)."""

    claim_id: str
    conditions: tuple[Condition, ...]
    units: tuple[str, ...] = UNIT_ROLES
    versus: tuple[str, ...] = ()
    controls: Mapping[str, Any] | None = None
    scopes: Mapping[str, Any] = field(default_factory=lambda: {"select": "all", "combine": "all"})
    samples: Mapping[str, str] = field(default_factory=lambda: {"main": "main", "replication": "replication"})
    guard: Mapping[str, Any] | None = None
    bound: Mapping[str, Any] | None = None
    suspect: Mapping[str, Any] | None = None
    alternatives: tuple[Mapping[str, Any], ...] = ()
    choice: str = ""
    would_take: tuple[WouldTake, ...] = ()
    flags: tuple[Mapping[str, Any], ...] = ()
    level: float = 0.9

    def reads(self) -> list[str]:
        """Every quantity the test reads (conditions, guard, bound, suspect, would_take, flags)."""
        qs = [c.quantity for c in self.conditions]
        for c in self.conditions:
            for v in list(c.params.values()) + list((c.get("setting") or {}).values()):
                if isinstance(v, Mapping):
                    if "relative_to" in v:
                        qs.append(v["relative_to"])
                    if "published" in v:
                        qs.append(v["published"])
        for part in (self.guard, self.bound):
            if part and part.get("quantity"):
                qs.append(part["quantity"])
        if self.suspect:
            qs += [self.suspect["estimate"], self.suspect["bound"]]
        for w in self.would_take:
            if w.params.get("quantity"):
                qs.append(w.params["quantity"])
            if w.kind == "quote":
                qs.append(w.params["quote"])
        qs += [f["quantity"] for f in self.flags]
        return list(dict.fromkeys(qs))


class Plan:
    """The parsed analysis plan; :meth:`number` and :meth:`guard` record what was read."""

    def __init__(self, raw: Mapping[str, Any], source: str = "analysis_plan.yaml", text: str | None = None):
        self.source = source
        if not isinstance(raw, Mapping) or not isinstance(raw.get("claims"), Mapping):
            raise PlanError(f"{source}: needs a 'claims' mapping")
        for sect in ("guards", "replication", "inputs", "settings", "names"):
            if not isinstance(raw.get(sect, {}), Mapping):
                raise PlanError(f"{source}: '{sect}' must be a mapping")
        if not isinstance(raw.get("version"), int):
            raise PlanError(f"{source}: 'version' must be an integer")
        lv = raw.get("level")
        if not _margin_ok(lv) or not 0.5 < float(lv["value"]) < 1.0:
            raise PlanError(f"{source}: 'level' needs a 'value' in (0.5, 1) and a 'reason'")
        for name, m in raw.get("guards", {}).items():
            if not _margin_ok(m):
                raise PlanError(f"{source}: guards.{name} needs a numeric 'value' and a 'reason'")
        for name, m in raw.get("settings", {}).items():
            ok = _margin_ok(m) or (isinstance(m, Mapping) and isinstance(m.get("values"), list)
                                   and all(isinstance(v, (int, float)) for v in m["values"]) and m.get("reason"))
            if not ok:
                raise PlanError(f"{source}: settings.{name} needs a numeric 'value' (or 'values') and a 'reason'")
        self.raw = raw
        self._text = text
        self.claims: dict = dict(raw["claims"])
        self._read: set[str] = set()
        self._tests: dict[str, ClaimTest] = {}
        for cid, c in self.claims.items():
            if not isinstance(c, Mapping):
                raise PlanError(f"{source}: claims.{cid} must be a mapping")
            for k in _CLAIM_KEYS:
                if k not in c:
                    raise PlanError(f"{source}: claims.{cid}.{k} is missing")
            for name, m in (c["margins"] or {}).items():
                if not _margin_ok(m):
                    raise PlanError(f"{source}: claims.{cid}.margins.{name} needs a numeric 'value' and a 'reason'")
            self._tests[cid] = self._parse_test(cid, c)

    # ---------------------------------------------------------------- identity
    @property
    def version(self) -> int:
        return int(self.raw["version"])

    @property
    def text(self) -> str:
        """The plan file's text (an amended plan's: its entries dumped, sorted)."""
        if self._text is None:
            self._text = yaml.safe_dump(dict(self.raw), sort_keys=True)
        return self._text

    @property
    def checksum(self) -> str:
        """sha256 of the plan file's text, first 12 hex digits."""
        return hashlib.sha256(self.text.encode("utf-8")).hexdigest()[:12]

    @property
    def stamp(self) -> str:
        """'v2 sha256:0123456789ab': what the claims table prints."""
        return f"v{self.version} sha256:{self.checksum}"

    @property
    def level(self) -> float:
        self._read.add("level")
        return float(self.raw["level"]["value"])

    # ---------------------------------------------------------------- parsing
    def _parse_test(self, cid: str, c: Mapping[str, Any]) -> ClaimTest:
        src = f"{self.source}: claims.{cid}.test"
        t = c["test"]
        if not isinstance(t, Mapping) or not isinstance(t.get("conditions"), list) or not t["conditions"]:
            raise PlanError(f"{src}.conditions must be a non-empty list")
        conds = []
        for i, cd in enumerate(t["conditions"]):
            if not isinstance(cd, Mapping) or not isinstance(cd.get("quantity"), str):
                raise PlanError(f"{src}.conditions.{i} needs a 'quantity'")
            comp = cd.get("comparison")
            if comp not in COMPARISONS:
                raise PlanError(f"{src}.conditions.{i}.comparison {comp!r} is not one of {COMPARISONS}")
            params = {k: v for k, v in cd.items() if k not in ("quantity", "comparison")}
            self._check_condition(f"{src}.conditions.{i}", cid, comp, params)
            conds.append(Condition(cd["quantity"], comp, params, i))
        units = tuple(t.get("units") or UNIT_ROLES)
        bad = [u for u in units if u not in UNIT_ROLES]
        if bad:
            raise PlanError(f"{src}.units: {bad} are not among {UNIT_ROLES}")
        scopes = dict(t.get("scopes") or {"select": "all", "combine": "all"})
        if scopes.get("combine", "all") not in ("all", "choice"):
            raise PlanError(f"{src}.scopes.combine must be 'all' or 'choice'")
        if scopes.get("combine") == "choice" and not scopes.get("choice"):
            raise PlanError(f"{src}.scopes.choice: a 'choice' combine names the choice")
        bound = t.get("bound")
        if bound is not None:
            if bound.get("rule") not in ("information", "floor") or not isinstance(bound.get("like"), int) \
                    or not 0 <= bound["like"] < len(conds):
                raise PlanError(f"{src}.bound needs rule information|floor, a quantity and 'like' (a condition index)")
        wt = []
        for j, w in enumerate(t.get("would_take") or []):
            kind = next((k for k in ("sweep", "margin", "choice", "quote") if k in w), None)
            if kind is None:
                raise PlanError(f"{src}.would_take.{j} needs one of sweep, margin, choice, quote")
            if kind in ("sweep", "margin") and not (isinstance(w.get("like"), int) and 0 <= w["like"] < len(conds)):
                raise PlanError(f"{src}.would_take.{j}.like must be a condition index")
            if kind == "margin" and w["margin"] not in (c["margins"] or {}):
                raise PlanError(f"{src}.would_take.{j}.margin {w['margin']!r} is not a margin of {cid}")
            wt.append(WouldTake(kind, dict(w)))
        level = self.raw["level"]["value"]
        if "level" in c:
            if not c.get("level_reason"):
                raise PlanError(f"{self.source}: claims.{cid}.level needs a 'level_reason' (one level for the plan)")
            level = c["level"]
        samples = {"main": "main", "replication": "replication", **dict(t.get("samples") or {})}
        return ClaimTest(
            claim_id=cid, conditions=tuple(conds), units=units, versus=tuple(t.get("versus") or ()),
            controls=t.get("controls"), scopes=scopes, samples=samples, guard=t.get("guard"), bound=bound,
            suspect=t.get("suspect"), alternatives=tuple(t.get("alternatives") or ()),
            choice=str(t.get("choice") or scopes.get("choice") or c.get("depends_on") or ""),
            would_take=tuple(wt), flags=tuple(t.get("flags") or ()), level=float(level))

    def _check_condition(self, where: str, cid: str, comp: str, params: Mapping[str, Any]) -> None:
        for k in NUMBER_PARAMS[comp]:
            if k in params:
                self._check_number(f"{where}.{k}", cid, params[k])
        if comp == "band" and not any(k in params for k in ("lower", "upper", "center")):
            raise PlanError(f"{where}: a band needs lower, upper or center")
        if comp == "equivalence" and "margin" not in params:
            raise PlanError(f"{where}: an equivalence needs a margin")
        if comp == "superiority" and params.get("direction") not in ("below", "above"):
            raise PlanError(f"{where}.direction must be below or above")
        if comp == "order":
            if params.get("items") not in ("method", "scope") or params.get("by") not in ("estimate", "interval") \
                    or not isinstance(params.get("chain"), list) or not params["chain"]:
                raise PlanError(f"{where}: an order needs items method|scope, by estimate|interval and a chain")
        if comp == "sign" and sum(k in params for k in ("above", "below")) != 1:
            raise PlanError(f"{where}: a sign needs one of above, below")
        if comp == "count" and sum(k in params for k in ("equals", "at_most", "at_least")) != 1:
            raise PlanError(f"{where}: a count needs one of equals, at_most, at_least")
        for name, ref in (params.get("setting") or {}).items():
            self._check_number(f"{where}.setting.{name}", cid, ref)

    def _check_number(self, where: str, cid: str, ref: Any) -> None:
        if ref == "published":
            return
        if not isinstance(ref, Mapping):
            raise PlanError(f"{where}: a number is {{margin: name}}, {{setting: name}} or {{published: quantity}}, "
                            f"never a literal ({ref!r})")
        if "relative_to" in ref:
            self._check_number(f"{where}.factor", cid, ref.get("factor"))
            return
        if "margin" in ref:
            if ref["margin"] not in (self.claims[cid].get("margins") or {}):
                raise PlanError(f"{where}: claims.{cid}.margins.{ref['margin']} is missing")
        elif "setting" in ref:
            if ref["setting"] not in self.raw.get("settings", {}):
                raise PlanError(f"{where}: settings.{ref['setting']} is missing")
        elif "published" not in ref:
            raise PlanError(f"{where}: a number is {{margin: name}}, {{setting: name}} or {{published: quantity}}")

    # ---------------------------------------------------------------- access
    def entry(self, claim_id: str) -> dict:
        """The plan entry of a claim (raises :class:`PlanError` if there is none)."""
        if claim_id not in self.claims:
            raise PlanError(f"{self.source}: claim {claim_id} has no entry (claims.{claim_id})")
        self._read.add(f"claims.{claim_id}")
        return self.claims[claim_id]

    def test(self, claim_id: str) -> ClaimTest:
        self.entry(claim_id)
        return self._tests[claim_id]

    def tests(self) -> dict[str, ClaimTest]:
        return dict(self._tests)

    def reads(self) -> dict[str, list[str]]:
        """Claim id -> the quantities its test reads and its ``published`` text quotes (to key
        the evidence rows)."""
        out = {}
        for cid, t in self._tests.items():
            pub = [m.split(":")[-1].split("@")[0] for m in re.findall(r"{([^}]+)}", str(self.claims[cid]["published"]))]
            out[cid] = list(dict.fromkeys(t.reads() + pub))
        return out

    def margin(self, claim_id: str, name: str) -> float:
        """A margin, tolerance or threshold of a claim's verdict (a fixed number of the plan)."""
        c = self.entry(claim_id)
        if name not in (c.get("margins") or {}):
            raise PlanError(f"{self.source}: claims.{claim_id}.margins.{name} is missing")
        self._read.add(f"claims.{claim_id}.margins.{name}")
        return float(c["margins"][name]["value"])

    def setting(self, name: str) -> float | list[float]:
        """A number the pipeline computes evidence with (``settings``)."""
        s = self.raw.get("settings", {})
        if name not in s:
            raise PlanError(f"{self.source}: settings.{name} is missing")
        self._read.add(f"settings.{name}")
        return [float(v) for v in s[name]["values"]] if "values" in s[name] else float(s[name]["value"])

    def guard(self, name: str) -> float:
        """A rule that applies to every claim (``guards``)."""
        g = self.raw.get("guards", {})
        if name not in g:
            raise PlanError(f"{self.source}: guards.{name} is missing")
        self._read.add(f"guards.{name}")
        return float(g[name]["value"])

    def variants(self, claim_id: str) -> dict:
        return dict(self.entry(claim_id).get("variants") or {})

    def name(self, key: str) -> str:
        """How a method reads in the text (``names``; the key itself when absent)."""
        v = (self.raw.get("names") or {}).get(key)
        return v if isinstance(v, str) else key

    def addition(self, label: str) -> str:
        """What a variant label (``roll+growing+squarem``) adds to the paper as written, in words."""
        add = (self.raw.get("names") or {}).get("additions") or {}
        parts = [p for p in label.split("+") if p and p != "literal"]
        return join([add.get(p, p) for p in parts], none="nothing")

    def keys(self) -> list[str]:
        """Every entry a verdict may read: claims, their margins, guards, settings, the level."""
        out = ["level"]
        for cid, c in self.claims.items():
            out.append(f"claims.{cid}")
            out += [f"claims.{cid}.margins.{m}" for m in (c.get("margins") or {})]
        out += [f"guards.{g}" for g in self.raw.get("guards", {})]
        out += [f"settings.{s}" for s in self.raw.get("settings", {})]
        return out

    def unreferenced(self) -> list[str]:
        """Margins and settings no claim's test names (a static check of the plan: every number
        of it is read by some verdict or evidence)."""
        text = yaml.safe_dump({cid: c.get("test") for cid, c in self.claims.items()}, sort_keys=True)
        out = []
        for cid, c in self.claims.items():
            t = yaml.safe_dump(c.get("test"), sort_keys=True)
            for m in (c.get("margins") or {}):
                if not re.search(rf"margin: {re.escape(m)}\b", t):
                    out.append(f"claims.{cid}.margins.{m}")
        for name in self.raw.get("settings") or {}:
            if not re.search(rf"setting: {re.escape(name)}\b", text) and not (self.raw["settings"][name] or {}).get(
                    "config") and name not in EVIDENCE_SETTINGS:
                out.append(f"settings.{name}")
        return out

    def unused(self) -> list[str]:
        """Plan entries no verdict has read (in plan order)."""
        return [k for k in self.keys() if k not in self._read]

    def mark_read(self, key: str) -> None:
        self._read.add(key)

    def amended(self, patch: Mapping[str, Any]) -> Plan:
        """The plan with ``patch`` applied (dotted paths -> values; ``None`` deletes the key):
        the plan as it stood before an amendment."""
        raw = copy.deepcopy(dict(self.raw))
        for path, value in patch.items():
            _set_path(raw, path, value)
        return Plan(raw, f"{self.source} (before an amendment)")

    def amendments(self) -> list[dict]:
        return list(self.raw.get("amendments") or [])

    def not_claims(self) -> list[dict]:
        return list(self.raw.get("not_claims") or [])

    def table(self):
        """results/paper/analysis_plan.csv: one row per claim, margins with their reasons."""
        import pandas as pd

        rows = []
        for cid, c in self.claims.items():
            ms = c.get("margins") or {}
            v = c.get("variants") or {}
            t = self._tests[cid]
            rows.append({
                "claim_id": cid, "paper": c["paper"], "sentence": " ".join(str(c["sentence"]).split()),
                "where": c["where"], "quantity": c["quantity"], "units": c["units"], "comparison": c["comparison"],
                "test": "; ".join(f"{cd.quantity} {cd.comparison}" for cd in t.conditions)
                        + (f" vs {join(list(t.versus))}" if t.versus else ""),
                "margin": "; ".join(f"{k} = {m['value']:g}" for k, m in ms.items()),
                "margin_reason": "; ".join(f"{k}: {' '.join(m['reason'].split())}" for k, m in ms.items()),
                "variants": "; ".join(f"{k}: {join(x if isinstance(x, list) else [x], none='none')}"
                                      for k, x in v.items() if k != "controls"),
                "controls": join(list(v.get("controls") or []), none=""),
                "depends_on": c["depends_on"], "plan": self.stamp})
        return pd.DataFrame(rows, columns=PLAN_COLUMNS)


PLAN_COLUMNS = ["claim_id", "paper", "sentence", "where", "quantity", "units", "comparison", "test", "margin",
                "margin_reason", "variants", "controls", "depends_on", "plan"]


def _set_path(raw: dict, path: str, value: Any) -> None:
    parts = path.split(".")
    # claim ids contain '-' but no '.'; list indexes are integers
    cur: Any = raw
    for p in parts[:-1]:
        key: Any = int(p) if isinstance(cur, list) else p
        if isinstance(cur, list):
            cur = cur[key]
        else:
            if key not in cur or cur[key] is None:
                cur[key] = {}
            cur = cur[key]
    last: Any = int(parts[-1]) if isinstance(cur, list) else parts[-1]
    if value is None and not isinstance(cur, list):
        cur.pop(last, None)
    else:
        cur[last] = copy.deepcopy(value)


def load_plan(path: str | Path | None = None) -> Plan:
    """The analysis plan, parsed and checked (a fresh :class:`Plan`: its record of what
    was read starts empty)."""
    p = Path(path) if path is not None else PLAN_FILE
    try:
        text = p.read_text()
    except OSError as exc:
        raise PlanError(f"{p}: cannot read the analysis plan ({exc.strerror})") from None
    try:
        raw = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError as exc:
        raise PlanError(f"{p}: not valid YAML ({str(exc).splitlines()[0]})") from None
    return Plan(raw, p.name, text)
