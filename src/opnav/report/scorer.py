"""The one scorer: a claim's verdict from the evidence table and the plan's declared test.

No per-claim branch: :func:`judge` reads a claim's :class:`opnav.report.plan.ClaimTest` and
applies it to the evidence rows (:class:`opnav.report.evidence.EvidenceRow`) keyed to the
claim. The steps, in order (the plan file's header states the schema):

1. **Outcomes.** Each condition judged on one row (a unit = a method, in a scope, against a
   baseline): ``pass``, ``fail`` or ``undecided`` (no row, no interval, a band too wide, a
   zero margin), with the threshold it was judged against and, when it fails, how far.
2. **A unit's reading.** Every condition in every selected scope against every baseline of
   ``versus`` (a baseline the ``guard`` finds picking depth's landmark is left out, flagged):
   any fail -> fail; else any undecided -> undecided; else pass.
3. **A sample's verdict.** suspect (``suspect``: an error beating its own bound) -> the
   as-written unit passes: reproduced (a negative control that passes too: flag
   ``control_also_meets``, or void with ``effect: decide``) -> a faithful unit passes:
   reproduced_with_addition (the one adding least) -> the ``bound`` (information: the
   as-written bound row fails -> not_reproducible; floor: depends_on_choice) -> undecided:
   not_tested -> not_reproduced. ``alternatives`` (an open choice with an as-written value)
   turn not_reproduced into depends_on_choice when one of them reproduces; ``scopes.combine:
   choice`` reads each scope alone and combines (the same verdict, else depends_on_choice).
4. **Two samples** (:func:`judge`): the same verdict -> it; different verdicts and rows that
   differ by the plan's ``sample_difference`` test -> unstable; different verdicts and rows
   that agree -> the pooled sample's verdict, flag ``replication_underpowered``. ``suspect``
   in either sample is the verdict and a flag naming the sample.
5. **would_take** (:func:`would_take`): sweeps of a setting (where the condition flips,
   interpolated log-log where every value is positive, else linearly), margins that would pass, the scopes or alternatives where it holds.

Every number a claim row quotes is the estimate, lo or hi of a row the scorer read
(:attr:`Judgement.quoted`), a plan number or a published row.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from scipy import special

from opnav.core import wording
from opnav.report.evidence import QUANTITIES, Evidence, EvidenceRow, quantity
from opnav.report.plan import ClaimTest, Condition, Plan, PlanError

REPRODUCED = "reproduced"
WITH_ADDITION = "reproduced_with_addition"
NOT_REPRODUCED = "not_reproduced"
NOT_REPRODUCIBLE = "not_reproducible"
DEPENDS = "depends_on_choice"
NOT_TESTED = "not_tested"
UNSTABLE = "unstable"
SUSPECT = "suspect"

PASS, FAIL, UNDECIDED = "pass", "fail", "undecided"


# ------------------------------------------------------------ numbers as text
def fmt(x: Any, nd: int = 3) -> str:
    """A number as claim-table text: ``nd`` significant digits, ``n/a`` if missing
    (:func:`opnav.core.wording.num`: a ratio of 0.9999 is not '1')."""
    return wording.num(x, nd)


def _signed(x: float) -> str:
    s = fmt(x)
    return s if s.startswith("-") or s in ("0", "n/a") else "+" + s


def _setting_value(s: str, name: str) -> float | None:
    for part in s.split(";"):
        k, _, v = part.partition("=")
        if k == name:
            try:
                return float(v)
            except ValueError:
                return None
    return None


def setting_text(name: str, value: float) -> str:
    return f"{name}={value:g}"


# ------------------------------------------------------------ outcomes
@dataclass
class Outcome:
    """One condition judged on one row (or, for an order, on a chain of rows)."""

    status: str
    cond: Condition
    rows: tuple[EvidenceRow, ...] = ()
    threshold: str = ""             # what it was judged against, as text ('at most 2 arcsec')
    limit: float = math.nan         # the numeric boundary the estimate is judged against
    severity: float = 0.0           # how far past the boundary (relative), for the worst failure
    why: str = ""                   # undecided: why
    scope: str = ""
    versus: str = ""
    #: the numbers ``threshold`` quotes (band ends, +-margin, a threshold), for the derived rows
    numbers: tuple[float, ...] = ()
    #: a band's centre (the published value), where a sweep aims
    target: float = math.nan

    @property
    def row(self) -> EvidenceRow | None:
        return self.rows[0] if self.rows else None


@dataclass
class UnitReading:
    """A method (unit) judged by every condition in its scopes and against its baselines."""

    method: str
    role: str
    status: str
    outcomes: list[Outcome] = field(default_factory=list)
    flags: list[tuple[str, str]] = field(default_factory=list)
    why: str = ""

    def worst(self, status: str = FAIL) -> Outcome | None:
        sel = [o for o in self.outcomes if o.status == status]
        return max(sel, key=lambda o: (o.severity, -o.cond.index)) if sel else None

    def tightest(self) -> Outcome | None:
        """The passing outcome of the claim's first condition (its quantity) closest to failing
        (the one a 'reproduced' cause quotes); another condition's only when the first has none."""
        sel = [o for o in self.outcomes if o.status == PASS and o.row is not None]
        first = [o for o in sel if o.cond.index == min(x.cond.index for x in sel)] if sel else []
        return max(first, key=lambda o: o.severity) if first else None

    def first(self) -> Outcome | None:
        sel = [o for o in self.outcomes if o.row is not None]
        return sel[0] if sel else None


@dataclass
class Reading:
    """One sample's verdict of a claim."""

    verdict: str
    named: str = ""
    flags: list[tuple[str, str]] = field(default_factory=list)
    cause: str = ""
    lit: UnitReading | None = None
    best: UnitReading | None = None
    bound: Outcome | None = None
    quoted: list[EvidenceRow] = field(default_factory=list)
    per_scope: dict[str, Reading] = field(default_factory=dict)
    sample: str = ""
    units: list[UnitReading] = field(default_factory=list)
    #: the outcomes the cause quotes
    cited: list[Outcome] = field(default_factory=list)


@dataclass
class Judgement:
    """A claim's verdict over both samples, with everything the claim row prints."""

    claim_id: str
    verdict: str
    named: str
    flags: list[tuple[str, str]]
    cause: str
    main: Reading
    replication: Reading | None = None
    pooled: Reading | None = None
    would_take: str = ""
    sweeps: list[dict] = field(default_factory=list)
    quoted: list[EvidenceRow] = field(default_factory=list)
    #: rows the scorer computed (would_take's flips and margins), written to the evidence table
    derived: list[EvidenceRow] = field(default_factory=list)


class _Index:
    """The evidence rows of one claim, by key."""

    def __init__(self, rows: Iterable[EvidenceRow]):
        self.rows = list(rows)
        self.by_key: dict[tuple, EvidenceRow] = {}
        self.published: dict[tuple, EvidenceRow] = {}
        for r in self.rows:
            if r.role == "published":
                self.published.setdefault((r.quantity, r.scope), r)
                continue
            self.by_key.setdefault((r.sample, r.scope, r.method, r.versus, r.quantity, r.setting), r)

    def get(self, sample, scope, method, versus, quantity, setting="") -> EvidenceRow | None:
        return self.by_key.get((sample, scope, method, versus, quantity, setting))

    def pub(self, quantity: str, scope: str) -> EvidenceRow | None:
        return self.published.get((quantity, scope)) or self.published.get((quantity, ""))

    def select(self, **kw) -> list[EvidenceRow]:
        return Evidence(self.rows).select(**kw)


class _Ctx:
    """What judging one claim in one sample needs."""

    def __init__(self, plan: Plan, test: ClaimTest, idx: _Index, sample: str, level: float,
                 versus: tuple[str, ...] | None = None, setting: str = ""):
        self.plan, self.test, self.idx, self.sample, self.level = plan, test, idx, sample, level
        self.versus = tuple(test.versus) if versus is None else versus
        self.setting = setting
        self.quoted: list[EvidenceRow] = []

    # ---------------------------------------------------------------- numbers
    def num(self, ref: Any, cond: Condition, scope: str, row: EvidenceRow | None) -> tuple[float, EvidenceRow | None]:
        """A number reference of the plan -> (value, the evidence row it came from or None)."""
        cid = self.test.claim_id
        if ref == "published":
            p = self.idx.pub(cond.quantity, scope)
            return (p.estimate, p) if p is not None else (math.nan, None)
        if isinstance(ref, Mapping):
            if "margin" in ref:
                return self.plan.margin(cid, ref["margin"]), None
            if "setting" in ref:
                v = self.plan.setting(ref["setting"])
                return (float(v) if not isinstance(v, list) else math.nan), None
            if "published" in ref:
                p = self.idx.pub(ref["published"], scope)
                return (p.estimate, p) if p is not None else (math.nan, None)
            if "relative_to" in ref:
                f, _ = self.num(ref["factor"], cond, scope, row)
                of = ref.get("of", "versus")
                a = self._ref_row(ref["relative_to"], of, scope, row)
                if a is None:
                    return math.nan, None
                val = a.estimate
                if ref.get("minus"):
                    b = self._ref_row(ref["relative_to"], ref["minus"], scope, row)
                    if b is None:
                        return math.nan, None
                    val -= b.estimate
                    self.quoted.append(b)
                self.quoted.append(a)
                return f * val, a
        raise PlanError(f"claims.{cid}: cannot resolve the number {ref!r}")

    def _ref_row(self, quantity: str, of: str, scope: str, row: EvidenceRow | None) -> EvidenceRow | None:
        if of == "versus":
            of = row.versus if row is not None else ""
        if of == "best":
            cands = [r for r in self.idx.rows if r.sample == self.sample and r.scope == scope and r.quantity == quantity
                     and r.versus == "" and r.setting == "" and r.role != "published"]
            return min(cands, key=lambda r: (r.estimate, r.method)) if cands else None
        return self.idx.get(self.sample, scope, of, "", quantity, "")

    def row(self, cond: Condition, scope: str, method: str, versus: str) -> EvidenceRow | None:
        sample = cond.get("sample", self.sample)
        st = self.setting
        if cond.get("setting"):
            st = ";".join(setting_text(k, self.num(v, cond, scope, None)[0]) for k, v in cond.get("setting").items())
        r = self.idx.get(sample, scope, method, versus, cond.quantity, st)
        return r.at_level(self.level) if r is not None else None


def _u(unit: str) -> str:
    return f" {unit}" if unit and unit not in ("", "1") else ("" if unit != "%" else " %")


def evaluate(ctx: _Ctx, cond: Condition, scope: str, method: str, versus: str) -> Outcome:
    """One condition on the row of (scope, method, versus) in the context's sample."""
    comp = cond.comparison
    if comp == "order":
        return _order(ctx, cond, scope, method)
    row = ctx.row(cond, scope, method, versus)
    if row is None:
        return Outcome(UNDECIDED, cond, (), why=f"no {cond.quantity} row", scope=scope, versus=versus)
    est, unit = row.estimate, _u(row.unit)
    if not math.isfinite(est):
        return Outcome(UNDECIDED, cond, (row,), why=f"{cond.quantity} is not a number", scope=scope, versus=versus)
    o = Outcome(PASS, cond, (row,), scope=scope, versus=versus)
    if comp == "band":
        lo_b, hi_b, text, why = _band(ctx, cond, scope, row)
        if cond.get("center") is not None and not cond.get("upper_factor") and not cond.get("factor"):
            o.target = ctx.num(cond.get("center"), cond, scope, row)[0]
        o.threshold = text
        o.numbers = tuple(x for x in (lo_b, hi_b) if math.isfinite(x))  # quoted even when undecided
        if why:
            o.status, o.why = UNDECIDED, why
            return o
        ok = lo_b <= est <= hi_b
        if est > hi_b:
            o.limit, o.severity = hi_b, (est - hi_b) / max(abs(hi_b), 1e-300)
        elif est < lo_b:
            o.limit, o.severity = lo_b, (lo_b - est) / max(abs(lo_b), 1e-300)
        else:
            near = min(hi_b - est if math.isfinite(hi_b) else math.inf, est - lo_b if math.isfinite(lo_b) else math.inf)
            o.limit = hi_b if math.isfinite(hi_b) and (hi_b - est) <= (est - lo_b if math.isfinite(lo_b) else math.inf) else lo_b
            o.severity = -near / max(abs(o.limit), 1e-300) if math.isfinite(o.limit) else -math.inf
        o.status = PASS if ok else FAIL
        return o
    if comp == "equivalence":
        m, ref_row = ctx.num(cond.get("margin"), cond, scope, row)
        o.threshold = f"+-{fmt(m)}{unit}"
        o.limit, o.numbers = m, (m,)
        if not (math.isfinite(m) and m > 0):
            o.status, o.why = UNDECIDED, "the margin is zero (the reference's mean is not positive)"
            return o
        if not row.has_interval:
            o.status, o.why = UNDECIDED, f"no interval for {cond.quantity}"
            return o
        far = max(abs(row.lo), abs(row.hi))
        o.severity = (far - m) / m
        o.status = PASS if (-m < row.lo and row.hi < m) else FAIL
        return o
    if comp == "superiority":
        m, _ = ctx.num(cond.get("margin"), cond, scope, row)
        eff = ctx.num(cond.get("min_effect"), cond, scope, row)[0] if cond.get("min_effect") is not None else 0.0
        below = cond.get("direction") == "below"
        if not row.has_interval:
            o.status, o.why = UNDECIDED, f"no interval for {cond.quantity}"
            return o
        o.threshold = (f"below {fmt(-m)}{unit}" if below else f"above {fmt(m)}{unit}") + (
            f", by at least {fmt(eff)}{unit}" if eff else "")
        o.limit = -m if below else m
        o.numbers = (-m if below else m, eff)
        side = (row.hi < -m) if below else (row.lo > m)
        size = (-est >= eff) if below else (est >= eff)
        edge = row.hi if below else -row.lo
        scale = max(abs(est), 1e-300)
        if not side:       # how far the interval's edge is on the wrong side of the margin
            o.severity = (edge + m) / scale
        elif not size:     # the right side, but smaller than the effect the plan asks for
            o.severity = (eff - abs(est)) / max(eff, 1e-300)
        else:              # passing: how much room is left (negative)
            o.severity = -min(-(edge + m) / scale, (abs(est) - eff) / max(eff, 1e-300) if eff else math.inf)
        o.status = PASS if (side and size) else FAIL
        return o
    if comp == "sign":
        key = "above" if cond.get("above") is not None else "below"
        t, _ = ctx.num(cond.get(key), cond, scope, row)
        o.threshold, o.limit, o.numbers = f"{key} {fmt(t)}{unit}", t, (t,)
        ok = est > t if key == "above" else est < t
        o.severity = (t - est if key == "above" else est - t) / max(abs(t), 1e-300)
        o.status = PASS if ok else FAIL
        return o
    if comp == "count":
        key = next(k for k in ("equals", "at_most", "at_least") if cond.get(k) is not None)
        t, _ = ctx.num(cond.get(key), cond, scope, row)
        o.threshold, o.limit = {"equals": "equal to", "at_most": "at most", "at_least": "at least"}[key] + f" {fmt(t)}", t
        o.numbers = (t,)
        ok = {"equals": abs(est - t) < 1e-9, "at_most": est <= t, "at_least": est >= t}[key]
        o.severity = abs(est - t)
        o.status = PASS if ok else FAIL
        return o
    raise PlanError(f"comparison {comp!r}")


def _band(ctx: _Ctx, cond: Condition, scope: str, row: EvidenceRow) -> tuple[float, float, str, str]:
    """(lower, upper, text, why-undecided) of a band condition."""
    unit = _u(row.unit)
    lo_b, hi_b = -math.inf, math.inf
    if cond.get("lower") is not None:
        lo_b = ctx.num(cond.get("lower"), cond, scope, row)[0]
    if cond.get("upper") is not None:
        hi_b = ctx.num(cond.get("upper"), cond, scope, row)[0]
    why = ""
    if cond.get("center") is not None:
        c, crow = ctx.num(cond.get("center"), cond, scope, row)
        if crow is not None:
            ctx.quoted.append(crow)
        if not math.isfinite(c):
            return lo_b, hi_b, "", "no published value to centre the band on"
        if cond.get("factor") is not None:
            f = ctx.num(cond.get("factor"), cond, scope, row)[0]
            lo_b, hi_b = c / f, c * f
        elif cond.get("upper_factor") is not None:
            hi_b = c * ctx.num(cond.get("upper_factor"), cond, scope, row)[0]
        else:
            hw = 0.0
            if cond.get("abs") is not None:
                hw = max(hw, ctx.num(cond.get("abs"), cond, scope, row)[0])
            if cond.get("rel") is not None:
                hw = max(hw, ctx.num(cond.get("rel"), cond, scope, row)[0] * abs(c))
            spread = 0.0
            if cond.get("spread_k") is not None:
                sd = row.se * math.sqrt(max(row.n, 1)) if math.isfinite(row.se) else 0.0
                spread = ctx.num(cond.get("spread_k"), cond, scope, row)[0] * sd
                hw = max(hw, spread)
            if cond.get("max_rel") is not None:
                mx = ctx.num(cond.get("max_rel"), cond, scope, row)[0] * abs(c)
                if spread > mx:
                    why = (f"its spread ({fmt(spread)}{unit} at {fmt(ctx.num(cond.get('spread_k'), cond, scope, row)[0])} "
                           f"sd) is wider than {fmt(mx)}{unit}, too wide to decide")
            lo_b, hi_b = c - hw, c + hw
    if math.isfinite(lo_b) and math.isfinite(hi_b):
        text = f"{fmt(lo_b)} to {fmt(hi_b)}{unit}"
    elif math.isfinite(hi_b):
        text = f"at most {fmt(hi_b)}{unit}"
    else:
        text = f"at least {fmt(lo_b)}{unit}"
    return lo_b, hi_b, text, why


def _order(ctx: _Ctx, cond: Condition, scope: str, method: str) -> Outcome:
    rows, fails, undecided = [], [], []
    items = cond.get("items")
    for a, b in cond.get("chain"):
        if cond.get("by") == "estimate":
            if items == "scope":
                ra, rb = ctx.row(cond, a, method, ""), ctx.row(cond, b, method, "")
            else:
                ra, rb = ctx.row(cond, scope, a, ""), ctx.row(cond, scope, b, "")
            if ra is None or rb is None or not (math.isfinite(ra.estimate) and math.isfinite(rb.estimate)):
                undecided.append((a, b))
                continue
            rows += [ra, rb]
            if not ra.estimate < rb.estimate:
                fails.append((a, b, ra, rb))
        else:
            sa = a if items == "scope" else scope
            r = ctx.row(cond, sa, a if items == "method" else method, b if items == "method" else "")
            flip = False
            if r is None and items == "method":
                r, flip = ctx.row(cond, scope, b, a), True
            if r is None or not r.has_interval:
                undecided.append((a, b))
                continue
            rows.append(r)
            ok = (r.hi < 0) if flip else (r.lo > 0)
            if not ok:
                fails.append((a, b, r, None))
    o = Outcome(PASS, cond, tuple(rows), scope=scope, threshold="each pair ordered")
    if fails:
        o.status = FAIL
        a, b, ra, rb = fails[0]
        o.rows = (ra,) + ((rb,) if rb is not None else ()) + tuple(r for r in rows if r is not ra and r is not rb)
        o.threshold = (f"{a} before {b}" if items == "scope" else f"{ctx.plan.name(a)} before {ctx.plan.name(b)}")
        o.severity = float(len(fails))
    elif undecided:
        o.status, o.why = UNDECIDED, f"no {'interval' if cond.get('by') == 'interval' else 'value'} for " + ", ".join(
            f"{a} against {b}" for a, b in undecided)
    return o


# ------------------------------------------------------------ a unit, a sample
def _scopes(ctx: _Ctx) -> list[str]:
    sel = ctx.test.scopes.get("select", "all")
    if sel != "all":
        return [str(s) for s in sel]
    q = ctx.test.conditions[0].quantity
    sample = ctx.test.conditions[0].get("sample", ctx.sample)
    return list(dict.fromkeys(r.scope for r in ctx.idx.rows
                              if r.quantity == q and r.sample == sample and r.role in ctx.test.units))


def _units(ctx: _Ctx, scopes: list[str], roles: Iterable[str]) -> list[tuple[str, str]]:
    """(method, role) of the rows of the test's quantities in these scopes with one of ``roles``."""
    qs = {c.quantity for c in ctx.test.conditions}
    roles = set(roles)
    out = {}
    for r in ctx.idx.rows:
        if r.sample == ctx.sample and r.scope in scopes and r.quantity in qs and r.role in roles:
            out.setdefault(r.method, r.role)
    return sorted(out.items(), key=lambda mr: (("as_written", "faithful", "diagnostic", "beyond", "control").index(mr[1])
                                               if mr[1] in ("as_written", "faithful", "diagnostic", "beyond", "control")
                                               else 9, mr[0].count("+"), mr[0]))


def _read_unit(ctx: _Ctx, method: str, role: str, scopes: list[str], versus: tuple[str, ...]) -> UnitReading:
    u = UnitReading(method, role, PASS)
    t = ctx.test
    vs = versus or ("",)
    for s in scopes:
        live = []
        for b in vs:
            if t.guard and b:
                g = ctx.idx.get(ctx.sample, s, method, b, t.guard["quantity"], "")
                if g is not None and math.isfinite(g.estimate):
                    lim = ctx.num(t.guard["at_least"], t.conditions[0], s, g)[0]
                    if g.estimate >= lim:
                        ctx.quoted.append(g)
                        u.flags.append(("not_tested_vs", f"{ctx.plan.name(b)} ({s}: {t.guard.get('why', '')} in "
                                                         f"{fmt(g.estimate)} % of the calls)"))
                        continue
            live.append(b)
        if not live:
            u.outcomes.append(Outcome(UNDECIDED, t.conditions[0], (), scope=s,
                                      why=f"every baseline {t.guard.get('why', 'is guarded') if t.guard else ''}"))
            continue
        for c in t.conditions:
            if c.comparison == "order":
                if c.get("items") == "scope" and s != scopes[0]:
                    continue
                u.outcomes.append(evaluate(ctx, c, s, method, ""))
                continue
            for b in live:
                u.outcomes.append(evaluate(ctx, c, s, method, b))
    sts = {o.status for o in u.outcomes}
    u.status = FAIL if FAIL in sts else UNDECIDED if (UNDECIDED in sts or not u.outcomes) else PASS
    if u.status == UNDECIDED:
        w = next((o for o in u.outcomes if o.status == UNDECIDED), None)
        u.why = w.why if w is not None else "no evidence"
    for o in u.outcomes:
        ctx.quoted += list(o.rows)
    return u


def beats_bound(err: float, bound: float, n: int, plan: Plan) -> float | None:
    """The factor by which an RMS error ``err`` over ``n`` seeds beats its bound, or None if it
    does not by more than the plan's ``bound_factor`` (judged at ``err (1 + spread_k / sqrt(2 n))``)."""
    factor, k = plan.guard("bound_factor"), plan.guard("spread_k")
    if not (math.isfinite(err) and math.isfinite(bound)) or bound <= 0 or n < 1:
        return None
    if err * (1.0 + k / math.sqrt(2.0 * n)) * factor < bound:
        return math.inf if err <= 0 else bound / err
    return None


def _verdict(ctx: _Ctx, scopes: list[str]) -> Reading:
    """One sample's verdict of the claim over ``scopes`` (step 3 of the module docstring)."""
    t, plan = ctx.test, ctx.plan
    rd = Reading(NOT_TESTED, sample=ctx.sample)
    units = [_read_unit(ctx, m, r, scopes, ctx.versus) for m, r in _units(ctx, scopes, t.units)]
    rd.units = units
    for u in units:
        rd.flags += u.flags
    # suspect: an error beating its own bound (never a diagnostic)
    if t.suspect:
        hits = []
        for u in units:
            if u.role == "diagnostic":
                continue
            for s in scopes:
                e = ctx.idx.get(ctx.sample, s, u.method, "", t.suspect["estimate"])
                b = ctx.idx.get(ctx.sample, s, u.method, "", t.suspect["bound"])
                if e is None or b is None:
                    continue
                r = beats_bound(e.estimate, b.estimate, e.n, plan)
                if r is not None:
                    hits.append((r, u.method, s, e, b))
        if hits:
            r, m, s, e, b = max(hits, key=lambda h: (h[0], h[1]))
            ctx.quoted += [e, b]
            rd.verdict, rd.named = SUSPECT, f"{m} is {fmt(r, 2)} times below its own bound"
            rd.flags.append(("beats_bound", f"{fmt(r, 2)}x ({m}, {s})"))
            rd.cause = (f"{m} ends at {fmt(e.estimate)}{_u(e.unit)} ({s}), {fmt(r, 2)} times below the {fmt(b.estimate)}"
                        f"{_u(b.unit)} bound of the data it uses, which points to a leak or a bug, not to reproduction")
            rd.quoted = list(ctx.quoted)
            return rd
    lit = next((u for u in units if u.role == "as_written"), None)
    faithful = [u for u in units if u.role == "faithful"]
    rd.lit = lit
    passing = [u for u in faithful if u.status == PASS]
    rd.best = (min(passing, key=lambda u: (u.method.count("+"), u.method)) if passing else
               min(faithful, key=lambda u: ({FAIL: 1, UNDECIDED: 2}.get(u.status, 0),
                                            (u.worst().severity if u.worst() else 0.0), u.method), default=None))
    # controls: the same conditions against the control baseline
    met = []
    if t.controls:
        cv = (t.controls.get("versus"),) if t.controls.get("versus") else ()
        for m, _ in _units(ctx, scopes, ("control",)):
            cu = _read_unit(ctx, m, "control", scopes, cv)
            if cu.status == PASS:
                met.append(m)
    if lit is not None and lit.status == PASS:
        if met and (t.controls or {}).get("effect") == "decide":
            rd.verdict, rd.named = NOT_TESTED, f"the control {', '.join(met)} meets it too"
        else:
            rd.verdict = REPRODUCED
            if met:
                rd.flags.append(("control_also_meets", f"{', '.join(met)} ({', '.join(scopes)})"))
    elif passing and (lit is None or lit.status == UNDECIDED):
        # a faithful variant meets it but the method as written was never judged: not tested as
        # written (an addition is only named where the paper as written fails)
        rd.verdict = NOT_TESTED
        rd.named = f"no evidence for the method as written ({lit.why if lit is not None else 'no rows'})"
        rd.flags.append(("holds_with", f"{rd.best.method} ({plan.addition(rd.best.method)})"))
    elif passing:
        rd.verdict, rd.named = WITH_ADDITION, plan.addition(rd.best.method)
    else:
        bound_fail = None
        if t.bound and lit is not None:
            cond = t.conditions[t.bound["like"]]
            bc = Condition(t.bound["quantity"], cond.comparison, cond.params, cond.index)
            for s in scopes:
                o = evaluate(ctx, bc, s, lit.method, "")
                if o.status == FAIL:
                    bound_fail = o if bound_fail is None or o.severity > bound_fail.severity else bound_fail
            if bound_fail is not None:
                ctx.quoted += list(bound_fail.rows)
                rd.bound = bound_fail
        if bound_fail is not None and t.bound["rule"] == "information":
            b = bound_fail.row
            rd.verdict = NOT_REPRODUCIBLE
            rd.named = (f"the bound {fmt(b.estimate)}{_u(b.unit)} of the data as written ({bound_fail.scope}), "
                        f"not {bound_fail.threshold}")
        elif bound_fail is not None:
            rd.verdict, rd.named = DEPENDS, t.choice
            rd.flags.append(("floor_not_bound", f"{bound_fail.row.quantity} {fmt(bound_fail.row.estimate)}"
                                                f"{_u(bound_fail.row.unit)}"))
        elif lit is None or lit.status == UNDECIDED:
            rd.verdict = NOT_TESTED
            rd.named = lit.why if lit is not None else "no evidence for the method as written"
        else:
            rd.verdict = NOT_REPRODUCED
    rd.quoted = list(ctx.quoted)
    return rd


def _sample_reading(plan: Plan, test: ClaimTest, idx: _Index, sample: str, level: float) -> Reading:
    """A sample's verdict: scopes combined (all, or an open choice), alternatives applied."""
    base = _Ctx(plan, test, idx, sample, level)
    scopes = _scopes(base)
    if not scopes:
        held = sorted({r.sample for r in idx.rows if r.role != "published"
                       and r.quantity == test.conditions[0].quantity})
        why = (f"no {test.conditions[0].quantity} in the {sample} sample"
               + (f" (only in {', '.join(held)})" if held else ""))
        if sample == "between_replays" and held:
            why = "one replay only: no spread between independent replays to judge it on"
        rd = Reading(NOT_TESTED, named=why, sample=sample)
        rd.cause = _cause(rd, test, plan)
        return rd
    groups = [[s] for s in scopes] if test.scopes.get("combine") == "choice" else [scopes]
    per: dict[str, Reading] = {}
    for g in groups:
        ctx = _Ctx(plan, test, idx, sample, level)
        rd = _verdict(ctx, g)
        if rd.verdict in (NOT_REPRODUCED, NOT_TESTED) and test.alternatives:
            alts = []
            for alt in test.alternatives:
                actx = _Ctx(plan, test, idx, sample, level, versus=(alt["versus"],) if "versus" in alt else None,
                            setting=str(alt.get("setting", "")))
                ard = _verdict(actx, g)
                if ard.verdict == REPRODUCED:
                    alts.append((alt, ard))
            if alts:
                rd.verdict, rd.named = DEPENDS, test.choice
                rd.flags.append(("holds_with", "; ".join(_alt_text(plan, a) for a, _ in alts)))
                rd.per_scope["alternatives"] = alts[0][1]
                rd.quoted += [q for _, a in alts for q in a.quoted]
        rd.cause = _cause(rd, test, plan, g)
        per["+".join(g)] = rd
    if len(per) == 1:
        out = next(iter(per.values()))
        out.per_scope = {**out.per_scope, **per}
        return out
    return _combine_scopes(per, test, plan, sample)


def _alt_text(plan: Plan, alt: Mapping[str, Any]) -> str:
    return plan.name(alt["versus"]) if "versus" in alt else str(alt.get("setting", ""))


def _combine_scopes(per: dict[str, Reading], test: ClaimTest, plan: Plan, sample: str) -> Reading:
    decided = {s: r for s, r in per.items() if r.verdict != NOT_TESTED}
    pool = decided or per
    vs = {r.verdict for r in pool.values()}
    if SUSPECT in vs:
        out = next(r for r in pool.values() if r.verdict == SUSPECT)
    elif len(vs) == 1:
        out = replace(next(iter(pool.values())))
        out.flags = [f for r in per.values() for f in r.flags]
        if len(decided) < len(per):
            out.flags.append(("not_tested_in", ", ".join(s for s in per if s not in decided)))
        if out.verdict == REPRODUCED:
            out.cause = _cause(out, test, plan, list(pool), every=True)
    else:
        first = next(iter(pool.values()))
        out = Reading(DEPENDS, named=test.scopes.get("choice") or test.choice, sample=sample,
                      lit=first.lit, best=first.best, flags=[f for r in per.values() for f in r.flags])
        out.quoted = [q for r in per.values() for q in r.quoted]
        out.per_scope = dict(per)
        out.cause = _choice_cause(per, test, plan, out)
    out.per_scope = dict(per)
    out.sample = sample
    out.quoted = [q for r in per.values() for q in r.quoted]
    return out


# ------------------------------------------------------------ causes
def cited_rows(o: Outcome | None, claim_id: str) -> list[EvidenceRow]:
    """The derived rows of the numbers an outcome's threshold quotes (band ends, the margin):
    computed from plan numbers and evidence rows, written to the evidence table so that every
    number a claim row quotes is one of its rows."""
    if o is None or o.row is None:
        return []
    r = o.row
    q = quantity(f"limit_{r.quantity}", r.unit, "none", f"the test's boundary for {r.quantity}")
    return [EvidenceRow(claim_id=claim_id, sample=r.sample, scope=r.scope, method=r.method, versus=r.versus,
                        role="derived", quantity=q, estimate=float(x), unit=r.unit, setting=f"boundary={k}",
                        source=f"scorer: condition {o.cond.index} ({o.cond.comparison}) of the plan on {r.quantity}")
            for k, x in enumerate(o.numbers) if math.isfinite(x)]


def quote(o: Outcome | None, plan: Plan | None = None, with_scope: bool = True) -> str:
    """An outcome's row as the cause quotes it: 'depth - SVD err_diff_lastlm_m -0.0085 m
    [-0.017, -9.5e-05] against +-0.0376 m (interior)'."""
    if o is None or o.row is None:
        return "no evidence"
    r = o.row
    name = (lambda k: plan.name(k)) if plan is not None else (lambda k: k)
    q = QUANTITIES.get(r.quantity)
    what = q.text if q is not None else r.quantity
    # the method as written alone needs no name ('RMS error 20 arcsec', not 'of EM as written')
    who = "" if r.role == "bound" or (r.role == "as_written" and not r.versus) else name(r.method) + (
        f" minus {name(r.versus)}" if r.versus and r.quantity.startswith(("err_diff", "converge_time"))
        else f" against {name(r.versus)}" if r.versus else "")
    if o.cond.comparison == "order" and len(o.rows) >= 2 and o.rows[1] is not None and o.cond.get("by") == "estimate":
        a, b = o.rows[0], o.rows[1]
        left = a.scope if o.cond.get("items") == "scope" else name(a.method)
        right = b.scope if o.cond.get("items") == "scope" else name(b.method)
        return f"{what} {fmt(a.estimate)}{_u(a.unit)} ({left}) against {fmt(b.estimate)}{_u(b.unit)} ({right})"
    val = (_signed(r.estimate) if r.versus and r.quantity.startswith(("err_diff", "converge_time")) else fmt(r.estimate))
    iv = f" [{_signed(r.lo)}, {_signed(r.hi)}]" if r.has_interval and o.cond.comparison in (
        "equivalence", "superiority", "order") else ""
    s = (f"{what} of {who}" if who else what) + f" {val}{_u(r.unit)}{iv}"
    if o.threshold:
        s += f" against {o.threshold}"
    pooled = "both samples pooled" if r.sample == "pooled" else ""
    where = ", ".join(x for x in ((r.scope if with_scope else ""), pooled) if x)
    if where:
        s += f" ({where})"
    return s


def _q(rd: Reading, o: Outcome | None, plan: Plan, with_scope: bool = True) -> str:
    """:func:`quote`, remembering the outcome as cited by the reading's cause."""
    if o is not None:
        rd.cited.append(o)
    return quote(o, plan, with_scope)


def _cause(rd: Reading, test: ClaimTest, plan: Plan, scopes: list[str] | None = None, every: bool = False) -> str:
    v = rd.verdict
    where = f"in {', '.join(scopes)}" if scopes and len(scopes) <= 2 else "in every case"
    if v == SUSPECT:
        return rd.cause
    if v == REPRODUCED:
        o = rd.lit.tightest() if rd.lit else None
        tail = ", so the test cannot credit the method" if any(f[0] == "control_also_meets" for f in rd.flags) else ""
        return (f"As written it holds {'in every scope' if every else where}: {_q(rd, o, plan)}" + tail)
    if v == WITH_ADDITION:
        o, b = (rd.lit.worst() if rd.lit else None), (rd.best.tightest() if rd.best else None)
        return f"As written it fails ({_q(rd, o, plan)}), while {rd.best.method} passes ({_q(rd, b, plan, False)})"
    if v == NOT_REPRODUCIBLE:
        b = rd.bound.row
        return (f"The bound of the data the method as written uses, {fmt(b.estimate)}{_u(b.unit)} ({b.scope}), is "
                f"not {rd.bound.threshold}, so no unbiased estimator on the stated data meets it")
    if v == DEPENDS and rd.bound is not None:
        return f"Even the floor, {_q(rd, rd.bound, plan)}, fails the test, so the claim hinges on {test.choice}"
    if v == DEPENDS:
        return (f"As written it fails ({_q(rd, rd.lit.worst() if rd.lit else None, plan)}), but holds with "
                f"{dict(rd.flags).get('holds_with', 'another choice')}, a choice the paper leaves open")
    if v == NOT_TESTED:
        return f"Not tested: {rd.named}"
    o = rd.lit.worst() if rd.lit else None
    tail = ", and no faithful variant passes" if any(u.role == "faithful" for u in rd.units) else ""
    return f"As written it fails: {_q(rd, o, plan)}{tail}"


def _choice_cause(per: dict[str, Reading], test: ClaimTest, plan: Plan, rd: Reading | None = None) -> str:
    ok = [s for s, r in per.items() if r.verdict == REPRODUCED]
    bad = [s for s, r in per.items() if r.verdict not in (REPRODUCED, NOT_TESTED)]
    o = None
    for s in bad:
        r = per[s]
        if r.lit is not None and r.lit.worst() is not None:
            o = r.lit.worst()
            break
    why = f" ({_q(rd, o, plan) if rd is not None else quote(o, plan)})" if o is not None else ""
    return (f"It holds in {', '.join(ok) or 'no scope'} but not in {', '.join(bad) or 'the others'}{why}; the "
            f"choice is {test.scopes.get('choice') or test.choice}")


# ------------------------------------------------------------ two samples
def _z(level: float) -> float:
    return float(special.ndtri(0.5 + level / 2.0))


def _reading_keys(rd: Reading) -> list[tuple]:
    keys = []
    units = [u for u in rd.units if u.role in ("as_written", "faithful")]
    for r in list(rd.per_scope.values()) or [rd]:
        units += [u for u in r.units if u.role in ("as_written", "faithful")]
    for u in units:
        for o in u.outcomes:
            for row in o.rows:
                if row is not None:
                    keys.append((row.scope, row.method, row.versus, row.quantity, row.setting))
    return list(dict.fromkeys(keys))


def sample_difference(idx: _Index, test: ClaimTest, keys: list[tuple], s1: str, s2: str, level: float,
                      outcomes: Mapping[tuple, tuple[str, str]] | None = None) -> tuple[EvidenceRow, EvidenceRow, float] | None:
    """The first row (by key) whose two samples' estimates differ (|z| above the plan level's
    normal quantile), as (row in s1, row in s2, z); None when every row agrees. A row without
    a standard error differs when its condition reads differently (``outcomes``)."""
    zc = _z(level)
    worst = None
    for k in keys:
        a, b = idx.get(s1, *k), idx.get(s2, *k)
        if a is None or b is None:
            continue
        if math.isfinite(a.se) and math.isfinite(b.se) and (a.se > 0 or b.se > 0):
            z = (a.estimate - b.estimate) / math.hypot(a.se, b.se)
            if abs(z) > zc and (worst is None or abs(z) > abs(worst[2])):
                worst = (a, b, z)
        elif outcomes is not None and k in outcomes and outcomes[k][0] != outcomes[k][1]:
            if worst is None:
                worst = (a, b, math.inf)
    return worst


def _row_status(rd: Reading) -> dict[tuple, str]:
    out = {}
    for r in list(rd.per_scope.values()) or [rd]:
        for u in r.units + ([rd.lit] if rd.lit else []):
            for o in u.outcomes:
                for row in o.rows:
                    if row is not None:
                        out[(row.scope, row.method, row.versus, row.quantity, row.setting)] = o.status
    return out


def judge(plan: Plan, claim_id: str, evidence: Evidence | Iterable[EvidenceRow], replicated: bool = True) -> Judgement:
    """A claim's verdict from the evidence keyed to it and its plan entry (module docstring)."""
    test = plan.test(claim_id)
    rows = [r for r in evidence if r.claim_id == claim_id]
    idx = _Index(rows)
    level = test.level if test.level else plan.level
    plan.mark_read("level")
    s_main, s_rep = test.samples["main"], test.samples["replication"]
    main = _sample_reading(plan, test, idx, s_main, level)
    has_rep = replicated and any(r.sample == s_rep for r in rows)
    rep = _sample_reading(plan, test, idx, s_rep, level) if has_rep else None
    flags = list(main.flags)
    verdict, named, cause, pooled_rd = main.verdict, main.named, main.cause, None
    quoted = list(main.quoted)
    if rep is not None:
        quoted += rep.quoted
        sus = [s for s, r in (("main", main), ("replication", rep)) if r.verdict == SUSPECT]
        if sus:
            flags.append(("suspect", ", ".join(sus)))
            if main.verdict != SUSPECT:
                verdict, named, cause = SUSPECT, rep.named, rep.cause
        elif main.verdict != rep.verdict:
            mode = (plan.raw.get("sample_difference") or {}).get("test", "")
            keys = list(dict.fromkeys(_reading_keys(main) + _reading_keys(rep)))
            st1, st2 = _row_status(main), _row_status(rep)
            outs = {k: (st1.get(k, ""), st2.get(k, "")) for k in keys}
            diff = None if mode != "verdicts" else ("verdicts",)
            if diff is None:
                diff = sample_difference(idx, test, keys, s_main, s_rep, level, outs)
            flags.append(("verdict_main", main.verdict))
            if diff is not None:
                verdict = UNSTABLE
                named = (f"{main.verdict.replace('_', ' ')} in the main {_sample_word(test)}, "
                         f"{rep.verdict.replace('_', ' ')} in the {_second_word(test)}")
                if diff == ("verdicts",):
                    cause = (f"The main {_sample_word(test)} reads {main.verdict.replace('_', ' ')} and the "
                             f"{_second_word(test)} {rep.verdict.replace('_', ' ')}, so neither is reported")
                else:
                    a, b, z = diff
                    cause = (f"The estimates differ between the two: {_row_text(a, plan)} in the main "
                             f"{_sample_word(test)} against {fmt(b.estimate)} in the {_second_word(test)}, "
                             f"beyond their {level:.0%} intervals")
                    quoted += [a, b]
            else:
                pooled_rd = _sample_reading(plan, test, idx, "pooled", level) if any(
                    r.sample == "pooled" for r in rows) else None
                flags.append(("replication_underpowered", f"main {main.verdict}, replication {rep.verdict}"))
                if pooled_rd is not None and pooled_rd.verdict != NOT_TESTED:
                    verdict, named, cause = pooled_rd.verdict, pooled_rd.named, pooled_rd.cause
                    flags = [f for f in flags if f not in main.flags] + pooled_rd.flags
                    quoted += pooled_rd.quoted
    return Judgement(claim_id, verdict, named, _dedup(flags), cause, main, rep, pooled_rd, quoted=_dedup_rows(quoted))


def _sample_word(test: ClaimTest) -> str:
    return "replays" if test.samples["main"] == "between_replays" else "sample"


def _second_word(test: ClaimTest) -> str:
    return "second replay (the replication's calls)" if test.samples["main"] == "between_replays" else \
        "replication sample (other seeds)"


def _row_text(r: EvidenceRow, plan: Plan) -> str:
    q = QUANTITIES.get(r.quantity)
    who = plan.name(r.method) + (f" against {plan.name(r.versus)}" if r.versus else "")
    return f"{who} {q.text if q else r.quantity} {fmt(r.estimate)}{_u(r.unit)}" + (f" ({r.scope})" if r.scope else "")


def _dedup(flags: list) -> list:
    return list(dict.fromkeys(tuple(f) for f in flags))


def _dedup_rows(rows: list[EvidenceRow]) -> list[EvidenceRow]:
    return list(dict.fromkeys(r for r in rows if r is not None))


# ------------------------------------------------------------ would_take
@dataclass(frozen=True)
class Sweep:
    """One curve of a claim's would_take sweep (:func:`would_take`; the figures'): the claim, the
    swept setting, the unit (method, versus, scope) and quantity, the points ``(value, estimate, lo,
    hi, status)`` in setting order, the setting at which the verdict flips (None: none), the test's
    threshold in words, its limit, the quantity's unit, the band (two numbers where the test is a
    band, else empty) and the published target (NaN: none)."""

    claim_id: str
    setting: str
    method: str
    versus: str
    scope: str
    quantity: str
    points: list[tuple]
    flip: float | None
    threshold: str
    limit: float
    unit: str
    band: tuple
    target: float


def would_take(plan: Plan, claim_id: str, evidence: Evidence | Iterable[EvidenceRow], j: Judgement) -> tuple[str, list[Sweep]]:
    """What a claim not reproduced as written would take (the plan's ``would_take`` entries),
    as one text and the sweeps behind it (:class:`Sweep`, for the figures)."""
    test = plan.test(claim_id)
    rows = [r for r in evidence if r.claim_id == claim_id]
    idx = _Index(rows)
    level = test.level
    parts, sweeps = [], []
    for w in test.would_take:
        if w.kind == "sweep":      # swept whatever the verdict (the figure), quoted where it is not reproduced
            txt, sw = _sweep(plan, test, idx, level, w.params, j)
            sweeps += sw
            if txt and j.verdict != REPRODUCED and not w.params.get("quiet"):
                parts.append(txt)
        elif j.verdict == REPRODUCED:
            continue
        elif w.kind == "margin":
            txt = _margin_take(plan, test, idx, level, w.params, j)
            if txt:
                parts.append(txt)
        elif w.kind == "choice":
            ok = [s for s, r in j.main.per_scope.items() if r.verdict == REPRODUCED and s != "alternatives"]
            holds = dict(j.main.flags).get("holds_with") or dict(j.flags).get("holds_with")
            if ok:
                parts.append(f"the {' or '.join(ok)} reading of {test.scopes.get('choice') or 'the choice'}".replace(
                    ", which the paper does not give", ""))
            if holds:
                parts.append(f"{test.choice}: {holds}")
        elif w.kind == "quote":
            for r in idx.select(quantity=w.params["quote"], sample=[test.samples["main"], "main"]):
                q = QUANTITIES.get(r.quantity)
                parts.append(f"{q.text if q else r.quantity} {fmt(r.estimate)}{_u(r.unit)}" + (f" ({r.scope})" if r.scope else ""))
                j.quoted.append(r)
    return "; ".join(dict.fromkeys(parts)), sweeps


def _sweep(plan: Plan, test: ClaimTest, idx: _Index, level: float, w: Mapping[str, Any], j: Judgement) -> tuple[str, list[Sweep]]:
    name, q = w["sweep"], w["quantity"]
    cond0 = test.conditions[w["like"]]
    cond = Condition(q, cond0.comparison, {k: v for k, v in cond0.params.items() if k != "setting"}, cond0.index)
    samples = [test.samples["main"], "main"]
    # the rows of this setting alone (a row also naming another choice, 'arc_s=4100;rule=last', is
    # another curve)
    cands = [r for r in idx.rows if r.quantity == q and r.sample in samples and r.role != "published"
             and ";" not in r.setting and _setting_value(r.setting, name) is not None]
    if not cands:
        return "", []
    meth = w.get("method", "as_written")
    by_unit: dict[tuple, list[EvidenceRow]] = {}
    for r in cands:
        if meth == "as_written" and r.role != "as_written":
            continue
        if meth not in ("as_written", "best") and r.method != meth and r.method.split("+")[0] != meth:
            continue
        if meth == "best" and r.role not in ("as_written", "faithful"):
            continue
        by_unit.setdefault((r.scope, r.method, r.versus), []).append(r)
    sweeps = []
    for (scope, method, versus), rs in sorted(by_unit.items()):
        rs = sorted(rs, key=lambda r: _setting_value(r.setting, name))
        if len(rs) < 2:
            continue
        ctx = _Ctx(plan, test, idx, rs[0].sample, level)
        pts, outs = [], []
        for r in rs:
            ctx.setting = r.setting
            o = evaluate(ctx, cond, scope, method, versus)
            outs.append(o)
            rr = r.at_level(level)
            pts.append((_setting_value(r.setting, name), rr.estimate, rr.lo, rr.hi, o.status))
        flip = None
        for (v1, e1, *_r1, s1), (v2, e2, *_r2, s2), o1, o2 in zip(pts, pts[1:], outs, outs[1:]):
            aim = o1.target if math.isfinite(o1.target) else math.nan
            if math.isfinite(aim) and (e1 - aim) * (e2 - aim) <= 0 and e1 != e2:
                # a band around a published value: where the estimate meets the value itself
                flip = v1 + (aim - e1) * (v2 - v1) / (e2 - e1)
                break
            if s1 != s2 and PASS in (s1, s2) and UNDECIDED not in (s1, s2) and not math.isfinite(aim):
                lim = o2.limit if s2 == PASS else o1.limit
                if math.isfinite(lim) and e2 != e1 and cond.comparison in ("band", "sign"):
                    if min(v1, v2, e1, e2, lim) > 0:     # power laws (bounds, errors): log-log
                        lv = math.log(v1) + (math.log(lim) - math.log(e1)) * (math.log(v2) - math.log(v1)) / (
                            math.log(e2) - math.log(e1))
                        flip = math.exp(lv)
                    else:
                        flip = v1 + (lim - e1) * (v2 - v1) / (e2 - e1)
                else:
                    flip = v2 if s2 == PASS else v1
                break
        if flip is None and pts and pts[0][4] == PASS and not math.isfinite(outs[0].target):
            flip = pts[0][0]
        sweeps.append(Sweep(claim_id=test.claim_id, setting=name, method=method, versus=versus, scope=scope,
                            quantity=q, points=pts, flip=flip, threshold=outs[0].threshold if outs else "",
                            limit=outs[0].limit if outs else math.nan, unit=rs[0].unit,
                            band=tuple(outs[0].numbers) if outs and outs[0].cond.comparison == "band" else (),
                            target=outs[0].target if outs else math.nan))
        j.quoted += rs
    if not sweeps:
        return "", []
    if meth == "best":
        with_flip = [s for s in sweeps if s.flip is not None]
        pick = min(with_flip, key=lambda s: s.flip) if with_flip else min(
            sweeps, key=lambda s: (s.points[-1][1], s.method))
        shown = [pick]
    else:
        shown = sweeps
    texts = []
    for s in shown:
        vals = [p[0] for p in s.points]
        who = f"{plan.name(s.method)}" + (f", {s.scope}" if s.scope else "")
        if s.flip is not None:
            texts.append(w.get("text", "{value}").format(value=fmt(s.flip)) + f" ({who})")
            q = quantity(f"flip_{name}", "", "none", f"{name} at which the verdict flips")
            j.derived.append(EvidenceRow(
                claim_id=test.claim_id, sample=test.samples["main"], scope=s.scope, method=s.method,
                versus=s.versus, role="derived", quantity=q, estimate=float(s.flip),
                n=len(s.points), source=f"scorer: the sweep of {s.quantity} over {name}"))
        else:
            words, unit = wording.key_words(name)
            texts.append(f"no {words} from {fmt(min(vals))} to {fmt(max(vals))}{_u(unit)} gives it ({who})")
    return "; ".join(texts), sweeps


def _margin_take(plan: Plan, test: ClaimTest, idx: _Index, level: float, w: Mapping[str, Any], j: Judgement) -> str:
    """The value of margin ``w.margin`` at which condition ``w.like`` would pass for the
    as-written method in every scope it failed (its worst case)."""
    name, cond = w["margin"], test.conditions[w["like"]]
    rd = j.main
    units = [rd.lit] + [r.lit for r in rd.per_scope.values() if isinstance(r, Reading)]
    need = []
    for u in units:
        if u is None:
            continue
        for o in u.outcomes:
            if o.cond.index != cond.index or o.status != FAIL or o.row is None:
                continue
            v = _needed(o, name, plan, test, idx)
            if v is not None:
                need.append((v, o))
    if not need:
        return ""
    v, o = max(need, key=lambda t: t[0])
    cur = plan.margin(test.claim_id, name)
    q = quantity(f"needed_{name}", "", "none", f"the value of margin {name} at which the test would pass")
    j.derived.append(EvidenceRow(claim_id=test.claim_id, sample=test.samples["main"], scope=o.scope,
                                 method=o.row.method, versus=o.row.versus, role="derived", quantity=q,
                                 estimate=float(v), n=o.row.n,
                                 source=f"scorer: {o.row.quantity} against condition {cond.index} of the plan"))
    return f"{wording.key_value(name, fmt(v))} instead of {fmt(cur)} ({o.scope or o.row.method})"


def _needed(o: Outcome, name: str, plan: Plan, test: ClaimTest, idx: _Index) -> float | None:
    c, r = o.cond, o.row
    ref_is = lambda k: isinstance(c.get(k), Mapping) and c.get(k).get("margin") == name  # noqa: E731
    if c.comparison == "band":
        if ref_is("upper"):
            return r.estimate
        if ref_is("lower"):
            return r.estimate
        if c.get("center") is not None:
            p = idx.pub(c.quantity, r.scope) if c.get("center") == "published" else None
            center = p.estimate if p is not None else math.nan
            if not math.isfinite(center):
                return None
            if ref_is("rel"):
                return abs(r.estimate - center) / abs(center)
            if ref_is("abs"):
                return abs(r.estimate - center)
    if c.comparison == "equivalence":
        m = c.get("margin")
        if isinstance(m, Mapping) and isinstance(m.get("factor"), Mapping) and m["factor"].get("margin") == name \
                and math.isfinite(o.limit) and o.limit > 0 and r.has_interval:
            f = plan.margin(test.claim_id, name)
            return max(abs(r.lo), abs(r.hi)) / (o.limit / f)
    if c.comparison == "superiority" and ref_is("min_effect"):
        side = (r.hi < 0) if c.get("direction") == "below" else (r.lo > 0)
        return abs(r.estimate) if side else None
    return None


_NUM = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def numbers_in(text: str) -> list[str]:
    """The numbers a text quotes (for the test that each is a row of evidence)."""
    return _NUM.findall(text)
