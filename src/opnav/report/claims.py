"""The claims table: one row per distinct published claim of each paper, with a verdict.

The scorecard (:mod:`opnav.report.scorecard`) sets every published *number* beside ours; this
table answers which of the papers' *claims* reproduce. It is built in three steps with one home
each (docs/claims-engine.md): the evidence rows (:mod:`opnav.report.evidence`, written by the
extractors :mod:`opnav.report.approach_claims` and :mod:`opnav.report.landing_claims`), the
analysis plan's declared tests (:mod:`opnav.report.plan`), and the generic scorer
(:mod:`opnav.report.scorer`). :func:`build` puts them together into :class:`ClaimRow` records;
CSV and JSON only at the scripts' edge. Verdicts (:data:`VERDICTS`):

``reproduced``
    the paper as written (our reading of it, no addition) meets the claim's test;
``reproduced_with_addition``
    only a variant that adds something the paper does not state meets it; ``named`` says what
    (a variant given the truth never counts: it is a diagnostic);
``not_reproduced``
    neither the method as written nor a faithful variant meets it; the cause quotes the
    interval on which the test failed;
``not_reproducible``
    not reproduced, and an information bound (Cramér-Rao) of the stated data fails the test
    itself (only claims whose plan entry has ``bound: information``);
``depends_on_choice``
    the verdict differs between readings of a choice the paper leaves open (the camera, the
    SVD implementation, the arc length); ``named`` is that choice;
``not_tested``
    our evidence cannot test it (no evidence, every baseline picking depth's landmark, a band
    too wide); ``named`` says why;
``unstable``
    the main and replication samples give different verdicts *and* an estimate the test reads
    differs between them (the plan's ``sample_difference`` test); samples that agree in their
    estimates but not in their verdicts are read pooled (flag ``replication_underpowered``);
``suspect``
    an accuracy beats its own information bound by more than the plan's factor (in either
    sample: the flag ``suspect`` names which), a leak or a bug until shown otherwise.

``flags`` qualify a verdict without changing it (``control_also_meets``, ``beats_bound``,
``floor_not_bound``, ``not_tested_vs``, ``replication_underpowered``, ``verdict_main``,
``sample_too_small``...). Every claim row prints the plan's version and checksum (``plan``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import pandas as pd

from opnav.report import scorer as S
from opnav.report.evidence import EvidenceRow, for_claims, pooled

REPRODUCED = S.REPRODUCED
WITH_ADDITION = S.WITH_ADDITION
NOT_REPRODUCED = S.NOT_REPRODUCED
NOT_REPRODUCIBLE = S.NOT_REPRODUCIBLE
DEPENDS = S.DEPENDS
NOT_TESTED = S.NOT_TESTED
UNSTABLE = S.UNSTABLE
SUSPECT = S.SUSPECT
VERDICTS = (REPRODUCED, WITH_ADDITION, NOT_REPRODUCED, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED, UNSTABLE, SUSPECT)
#: verdicts that must name something (the addition, the choice, the bound, the reason)
NEEDS_NAMED = (WITH_ADDITION, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED, UNSTABLE, SUSPECT)
#: a cause is one sentence a reader takes in at once
MAX_CAUSE_WORDS = 40

#: the verdicts as the at-a-glance table prints them
VERDICT_SHORT = {
    "reproduced": "reproduced", "reproduced_with_addition": "with an addition", "not_reproduced": "not reproduced",
    "not_reproducible": "not reproducible", "depends_on_choice": "depends on a choice", "not_tested": "not tested",
    "unstable": "unstable", "suspect": "suspect",
}
#: how each verdict reads in running text (abstract, conclusion)
VERDICT_TEXT = {
    REPRODUCED: "reproduced",
    WITH_ADDITION: "reproduced only with an addition",
    NOT_REPRODUCED: "not reproduced",
    NOT_REPRODUCIBLE: "not reproducible under the stated assumptions",
    DEPENDS: "depends on a choice the paper leaves open",
    NOT_TESTED: "not tested",
    UNSTABLE: "unstable between two independent runs (the replication: other seeds; for planning times, a second replay)",
    SUSPECT: "suspect: better than its own information bound",
}

# ------------------------------------------------------------ the analysis plan
# the plan's one home is opnav.report.plan; these names stay importable from here
from opnav.report.plan import PLAN_COLUMNS, PLAN_FILE, Plan, PlanError, load_plan  # noqa: E402,F401

COMPARISONS = ("band", "equivalence", "superiority", "order", "sign", "count")
INPUT_COLUMNS = ["input", "ours", "published", "how_derived", "what_would_match"]


def fmt(x: Any, nd: int = 3, unit: str = "") -> str:
    """A number as claim-table text: ``nd`` significant digits, ``"n/a"`` if missing."""
    s = S.fmt(x, nd)
    return f"{s} {unit}".rstrip() if unit and s != "n/a" else s


from opnav.report.plan import join  # noqa: E402,F401  ('a, b and c')


# ------------------------------------------------------------ the claim row
@dataclass(frozen=True)
class ClaimRow:
    """One row of results/paper/claims.csv (a typed record; CSV only at the script's edge).

    ``claim``/``published``: the claim's title and the published value (from published.yaml,
    through the evidence); ``ours_as_written``, ``ours_best`` (+ ``best_variant``), ``bound``,
    ``ours_replication``: the evidence rows the verdict read, quoted; ``verdict`` /
    ``verdict_replication``: the verdict over both samples and the replication's alone;
    ``flags``: 'name: value' joined by '; '; ``named``: the addition, choice, bound or reason
    the verdict names; ``would_take``: what the claim would take where it is not reproduced as
    written; ``cause``: one sentence quoting the interval the test turned on; ``evidence``: the
    outputs the quoted rows come from; ``sample``: 'full' or 'quick'; ``plan``: the plan's
    version and checksum."""

    paper: str
    claim_id: str
    claim: str
    published: str
    ours_as_written: str = ""
    ours_best: str = ""
    best_variant: str = ""
    bound: str = ""
    ours_replication: str = ""
    verdict: str = NOT_TESTED
    verdict_replication: str = ""
    flags: str = ""
    named: str = ""
    would_take: str = ""
    cause: str = ""
    evidence: str = ""
    sample: str = "full"
    plan: str = ""

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"{self.claim_id}: verdict {self.verdict!r} is not one of {VERDICTS}")
        if self.verdict in NEEDS_NAMED and not self.named:
            raise ValueError(f"{self.claim_id}: verdict {self.verdict} needs 'named'")


COLUMNS = [f.name for f in fields(ClaimRow)]


def flag_text(flags: Iterable) -> str:
    """Flags as the table writes them: 'name: value' joined by '; '."""
    out = []
    for f in flags:
        name, value = (f, "") if isinstance(f, str) else f
        out.append(f"{name}: {value}" if value != "" else str(name))
    return "; ".join(dict.fromkeys(out))


def one_sentence(claim_id: str, cause: str) -> str:
    """The cause as one sentence of at most :data:`MAX_CAUSE_WORDS` words: a longer one drops
    its parentheses, then its clauses after the first semicolon or comma-and (never a number the
    test turned on: those sit before them), and raises if still too long."""
    cause = " ".join(cause.split()).rstrip(".")
    for cut in (lambda c: re.sub(r" \((?:[^()]|\([^()]*\))*\)", "", c), lambda c: c.split("; ")[0],
                lambda c: re.sub(r", (and|but|while|so) [^0-9]*$", "", c),
                lambda c: " ".join(c.split()[:MAX_CAUSE_WORDS])):
        if len(cause.split()) <= MAX_CAUSE_WORDS:
            break
        cause = cut(cause)
    cause += "."
    if ". " in cause.replace("e.g. ", "").replace("i.e. ", "").replace("vs. ", ""):
        cause = cause.replace(". ", "; ")
    n = len(cause.split())
    if n > MAX_CAUSE_WORDS:
        raise ValueError(f"{claim_id}: the cause has {n} words (at most {MAX_CAUSE_WORDS}): {cause!r}")
    return cause[0].upper() + cause[1:]


def frame(rows: Iterable[ClaimRow | dict]) -> pd.DataFrame:
    """The claims table, columns in :data:`COLUMNS` order, ids unique."""
    recs = [asdict(r) if isinstance(r, ClaimRow) else dict(r) for r in rows]
    df = pd.DataFrame(recs, columns=COLUMNS)
    dup = df["claim_id"][df["claim_id"].duplicated()].tolist()
    if dup:
        raise ValueError(f"claim ids defined twice: {dup}")
    return df.fillna("")


def records(df: pd.DataFrame) -> list[ClaimRow]:
    """The claims table's rows as records (claims.csv read back)."""
    return [ClaimRow(**{k: ("" if pd.isna(v) else str(v)) for k, v in r.items() if k in COLUMNS})
            for r in df.to_dict("records")]


#: the claim row columns whose numbers must be rows of the evidence (or of the plan)
QUOTING_COLUMNS = ("cause", "would_take", "ours_as_written", "ours_best", "ours_replication", "bound", "named")
#: ids and symbols a row quotes that are not numbers of the evidence
_NOT_NUMBERS = re.compile(r"T1-\d+|B-C\d+|A-C\d+|v\d+ sha256:\w+|O\(n\^3\)|O\(1\)|\b3-sigma\b")


def unquoted_numbers(plan: Plan, rows: Iterable[ClaimRow], evidence: Iterable[EvidenceRow]) -> list[str]:
    """Each number a claim row quotes (:data:`QUOTING_COLUMNS`) that is not an estimate, lo or
    hi of one of that claim's evidence rows, a published value (or the plan's margins applied to
    it, or to a compared method's mean error), or a number of the plan: issue 52's rule that
    every number a verdict quotes is in the evidence table. ``[]`` when all are."""
    ev = list(evidence)
    plan_nums = set()
    for c in plan.claims.values():
        plan_nums |= {float(m["value"]) for m in (c.get("margins") or {}).values()}
    for st in plan.raw["settings"].values():
        plan_nums |= {float(v) for v in st.get("values", [st.get("value", 0)])}
    fmt = S.fmt
    out = []
    for r in rows:
        mine = [e for e in ev if e.claim_id == r.claim_id]
        pubs = [p.estimate for p in mine if p.role == "published"]
        nums = {fmt(x) for e in mine for x in (e.estimate, e.lo, e.hi) if math.isfinite(x)}
        nums |= {fmt(abs(x)) for e in mine for x in (e.estimate, e.lo, e.hi) if math.isfinite(x)}
        nums |= {fmt(x) for x in plan_nums} | {fmt(x * abs(p)) for x in plan_nums for p in pubs}
        nums |= {fmt(p * (1 + sg * f)) for f in plan_nums for sg in (-1, 1) for p in pubs}
        nums |= {fmt(m.estimate * f) for f in plan_nums for m in mine if m.quantity.startswith("err_mean")}
        for col in QUOTING_COLUMNS:
            text = _NOT_NUMBERS.sub("", str(getattr(r, col)))
            for x in S.numbers_in(text):
                v = x.lstrip("+")
                if not (v in nums or fmt(float(v)) in nums or v.lstrip("-") in nums):
                    out.append(f"{r.claim_id}.{col} quotes {x}, in no evidence row: {text}")
    return out


# ------------------------------------------------------------ evidence -> claims
def evidence_table(plan: Plan, rows: Iterable[EvidenceRow]) -> list[EvidenceRow]:
    """The evidence table: every row keyed to the claims that read its quantity
    (:func:`opnav.report.evidence.for_claims`), plus each claim's pooled sample (its two
    readings' samples pooled, :func:`opnav.report.evidence.pooled`). Intervals are restated at
    the plan's level wherever a row has a standard error (a summary's 95 % interval becomes the
    plan's 90 %), so the table holds the intervals the verdicts read."""
    level = plan.level
    keyed = [r.at_level(level) for r in for_claims(rows, plan.reads())]
    out = list(keyed)
    for cid, t in plan.tests().items():
        mine = [r for r in keyed if r.claim_id == cid]
        a = [r for r in mine if r.sample == t.samples["main"]]
        b = [r for r in mine if r.sample == t.samples["replication"]]
        if a and b:
            out += pooled(a, b)
    return out


def replication_plan(plan: Plan, cfg: Mapping[str, Any]) -> list[str]:
    """The claims the replication sample re-judges (plan ``replication.claims``), after
    checking that the plan states the size the config flies (one line naming the key)."""
    rep = plan.raw.get("replication") or {}
    for k in ("seed_offset", "approach_n_seeds", "landing_n_runs"):
        if k not in rep:
            raise PlanError(f"{plan.source}: replication.{k} is missing (the plan states the sample's size)")
        if cfg.get("enabled", True) and k in cfg and rep[k] != cfg[k]:
            raise PlanError(f"{plan.source}: replication.{k} = {rep[k]} but the config's replication.{k} = {cfg[k]}: "
                            "the plan must state the size that is flown")
    ids = list(rep.get("claims") or [])
    unknown = [c for c in ids if c not in plan.claims]
    if unknown:
        raise PlanError(f"{plan.source}: replication.claims names claims without an entry: {unknown}")
    return ids


def _published_text(plan: Plan, cid: str, rows: list[EvidenceRow], scope: str) -> str:
    pubs = [r for r in rows if r.role == "published"]

    def one(m: re.Match) -> str:
        key = m.group(1)
        agg, _, key = key.rpartition(":")
        q, _, sc = key.partition("@")
        sel = [r for r in pubs if r.quantity == q]
        if agg in ("min", "max") and sel:
            v = (min if agg == "min" else max)(r.estimate for r in sel)
            return f"{v:g}"   # a published number as printed in the paper
        for want in (sc, scope, ""):
            hit = next((r for r in sel if r.scope == want), None)
            if hit is not None:
                return f"{hit.estimate:g}"
        return "n/a"

    return re.sub(r"{([^}]+)}", one, str(plan.entry(cid)["published"]))


def _first(rd: S.Reading | None) -> S.UnitReading | None:
    if rd is None:
        return None
    if rd.lit is not None:
        return rd.lit
    for r in rd.per_scope.values():
        if isinstance(r, S.Reading) and r.lit is not None:
            return r.lit
    return None


class _ScopeReading:
    """A scope's reading of the method as written, quoted as a best variant is: the scope
    (the choice that gives the claim) as its name, its tightest passing outcome first."""

    def __init__(self, scope: str, unit: S.UnitReading):
        self.method, self._unit = scope, unit

    def first(self) -> S.Outcome | None:
        return self._unit.tightest() or self._unit.first()


class _FailingReading:
    """The method as written in the scope where it fails, quoted by its worst outcome."""

    def __init__(self, unit: S.UnitReading):
        self.method, self._unit = unit.method, unit

    def first(self) -> S.Outcome | None:
        return self._unit.worst() or self._unit.first()


def _choice_readings(j: S.Judgement) -> tuple[_FailingReading, _ScopeReading] | None:
    """For a claim that depends on a choice of scope (the camera), the reading where the method
    as written fails (quoted as 'ours, as written') and the one where it holds (quoted as the
    best reading, named by its scope). The best reading is only ever one that passes, so a
    scope where the claim fails (depth worse than SVD) is never shown as the best (issue 55
    item 9). ``None`` for any other verdict."""
    if j.verdict != DEPENDS or not j.main.per_scope:
        return None
    scoped = {s: r for s, r in j.main.per_scope.items() if s != "alternatives" and isinstance(r, S.Reading)}
    good = [(s, r) for s, r in scoped.items() if r.verdict == REPRODUCED and r.lit is not None]
    bad = [(s, r) for s, r in scoped.items() if r.verdict != REPRODUCED and r.lit is not None]
    if not good or not bad:
        return None
    return _FailingReading(bad[0][1].lit), _ScopeReading(good[0][0], good[0][1].lit)


def _ours(u: S.UnitReading | None, plan: Plan, cited: list | None = None) -> str:
    if u is None:
        return ""
    o = u.first()
    if o is not None and cited is not None:
        cited.append(o)
    return S.quote(o, plan) if o is not None else ""


def _small(j: S.Judgement, plan: Plan) -> list[tuple[str, str]]:
    """``sample_too_small`` when a quoted reading rests on fewer Monte-Carlo seeds or runs than
    the plan's ``min_full_seeds``. A planning-time claim (its main sample ``between_replays``) is
    exempt: its ``n`` counts independent replays of the recorded calls (the plan's design, whose
    spread widens the band), not seeds."""
    if plan.test(j.claim_id).samples.get("main") == "between_replays":
        return []
    ns = [r.n for r in j.quoted if r.role in ("as_written", "faithful") and r.sample in ("main", "replication")
          and r.n > 0]
    if not ns:
        return []
    n = min(ns)
    return [("sample_too_small", f"{n} seeds or runs")] if n < plan.guard("min_full_seeds") else []


def claim_row(plan: Plan, cid: str, ev: list[EvidenceRow], replicated: bool, profile: str = "full") -> tuple[ClaimRow, S.Judgement, list[S.Sweep]]:
    """One claim's row, its judgement and the sweeps behind its would_take."""
    j = S.judge(plan, cid, ev, replicated=replicated)
    wt, sweeps = S.would_take(plan, cid, ev, j)
    c = plan.entry(cid)
    mine = [r for r in ev if r.claim_id == cid]
    lit = _first(j.main)
    best = j.main.best
    choice = _choice_readings(j)
    if choice is not None:  # a choice the paper leaves open decides: ours as written where it fails, best where it holds
        lit, best = choice
    if j.verdict == WITH_ADDITION and best is not None:
        wt = "; ".join(x for x in (f"{best.method.replace('+', ', ')} added ({plan.addition(best.method)})", wt) if x)
    scopes = [s for s in (j.main.per_scope or {}) if s != "alternatives"]
    head_scope = scopes[0].split("+")[0] if scopes else ""
    bound = ""
    if j.main.bound is not None:
        bound = S.quote(j.main.bound, plan)
    else:
        t = plan.test(cid)
        if t.bound and lit is not None:
            b = next((r for r in mine if r.quantity == t.bound["quantity"] and r.method == lit.method
                      and r.sample == t.samples["main"] and r.setting == ""
                      and (not head_scope or r.scope == head_scope)), None)
            if b is not None:
                bound = f"{S.QUANTITIES[b.quantity].text if b.quantity in S.QUANTITIES else b.quantity} " \
                        f"{fmt(b.estimate)}{S._u(b.unit)} ({b.scope or lit.method})"
                j.quoted.append(b)
    flags = list(j.flags) + _small(j, plan)
    if profile != "full":
        flags = [f for f in flags if f[0] != "sample_too_small"] + [("sample_too_small", f"{profile} profile")]
    t = plan.test(cid)
    for fl in t.flags:
        hit = next((r for r in mine if r.quantity == fl["quantity"] and r.sample == t.samples["main"]), None)
        if hit is not None and abs(hit.estimate - float(fl["equals"])) < 1e-12:
            flags.append((fl["flag"], fl.get("text", "")))
            j.quoted.append(hit)
    cited = list(j.main.cited) + list(j.replication.cited if j.replication is not None else []) + list(
        j.pooled.cited if j.pooled is not None else [])
    if j.main.bound is not None:
        cited.append(j.main.bound)
    sources = sorted({r.source.split("#")[0].rsplit("/", 1)[-1] for r in j.quoted if r.source})
    row = ClaimRow(
        paper=c["paper"], claim_id=cid, claim=c["title"], published=_published_text(plan, cid, mine, head_scope),
        ours_as_written=_ours(lit, plan, cited), ours_best=_ours(best, plan, cited) if best is not None and best is not lit else "",
        best_variant=best.method if best is not None and best is not lit else "",
        bound=bound,
        ours_replication=_ours(_first(j.replication), plan, cited) if j.replication is not None else "",
        verdict=j.verdict, verdict_replication=j.replication.verdict if j.replication is not None else "",
        flags=flag_text(flags), named=j.named or ("" if j.verdict not in NEEDS_NAMED else j.verdict),
        would_take=wt, cause=one_sentence(cid, j.cause or j.named or j.verdict),
        evidence=", ".join(sources), sample="full" if profile == "full" else "quick", plan=plan.stamp)
    seen = set()
    for o in cited:
        for d in S.cited_rows(o, cid):
            k = (d.sample,) + d.key()
            if k not in seen:
                seen.add(k)
                j.derived.append(d)
    return row, j, sweeps


def build(plan: Plan, evidence: Iterable[EvidenceRow], replicated: Iterable[str] = (),
          profile: str = "full") -> tuple[list[ClaimRow], list[S.Judgement], list[S.Sweep]]:
    """Every claim of the plan scored on the evidence table (:func:`evidence_table`'s rows):
    the claim rows, the judgements and the would_take sweeps (for the figures). The numbers
    the scorer computes (would_take's flips and margins) are each judgement's ``derived`` rows
    (:func:`derived_rows`), which belong in the evidence table beside the rest."""
    ev = list(evidence)
    rep = set(replicated)
    rows, js, sweeps = [], [], []
    for cid in plan.claims:
        r, j, sw = claim_row(plan, cid, ev, cid in rep, profile)
        rows.append(r)
        js.append(j)
        sweeps += sw
    return rows, js, sweeps


def derived_rows(judgements: Iterable[S.Judgement]) -> list[EvidenceRow]:
    """The rows the scorer computed (role ``derived``), for evidence.csv."""
    return [r for j in judgements for r in j.derived]


# ------------------------------------------------------------ amendments
AMENDMENT_COLUMNS = ["date", "what", "why", "commit", "claim_id", "verdict_before", "verdict_after", "how"]


def amendments(plan: Plan, evidence: Iterable[EvidenceRow], replicated: Iterable[str] = ()) -> pd.DataFrame:
    """results/paper/amendments.csv: per amendment of the plan (oldest first), each claim whose
    verdict it changed, before -> after, computed by the scorer on the same evidence (the plan
    right after the amendment: today's with every later amendment undone; before: that with this
    one undone too); an amendment that changed no verdict has one row saying so. An amendment
    whose old rule the schema cannot express carries the verdicts recorded in the build it names."""
    ev = raw_rows(evidence)
    rep = set(replicated)
    ams = plan.amendments()
    out = []
    for k, am in enumerate(ams):
        base = {"date": am.get("date", ""), "what": " ".join(str(am.get("what", "")).split()),
                "why": " ".join(str(am.get("why", "")).split()), "commit": str(am.get("commit", ""))}
        if "recorded" in am:
            rec = dict(am["recorded"])
            build_name = rec.pop("build", "")
            for cid, v in rec.items():
                after = _verdicts(plan, ev, rep, [cid]).get(cid, "")
                out.append({**base, "claim_id": cid, "verdict_before": v, "verdict_after": after,
                            "how": f"before: recorded in the {build_name} build; after: this plan on this evidence"})
            continue
        later: dict = {}
        for a in reversed(ams[k + 1:]):
            later.update(a.get("before") or {})
        after_plan = plan.amended(later) if later else plan
        before_plan = plan.amended({**later, **(am.get("before") or {})})
        va, vb = _verdicts(after_plan, ev, rep), _verdicts(before_plan, ev, rep)
        changed = [cid for cid in va if va[cid] != vb.get(cid)]
        if not changed:
            out.append({**base, "claim_id": "", "verdict_before": "", "verdict_after": "",
                        "how": "recomputed on this evidence: no verdict changed"})
        for cid in changed:
            out.append({**base, "claim_id": cid, "verdict_before": vb.get(cid, ""), "verdict_after": va[cid],
                        "how": "recomputed on this evidence"})
    return pd.DataFrame(out, columns=AMENDMENT_COLUMNS)


def _verdicts(plan: Plan, raw: list[EvidenceRow], rep: set, ids: Iterable[str] | None = None) -> dict[str, str]:
    rows = evidence_table(plan, raw)
    return {cid: S.judge(plan, cid, rows, replicated=cid in rep).verdict for cid in (ids or plan.claims)}


def amendments_latex(df: pd.DataFrame, plan: Plan, prose_tex=lambda s: s) -> str:
    """The report appendix's list of the plan's amendments: a sentence with the plan's version
    and checksum, then a table (a longtable, so it may break across pages) with a row per
    amendment: its date, what changed, why, and the verdicts it changed, before -> after, on
    this build's evidence. ``prose_tex``: the text-to-LaTeX function
    (``opnav.report.manuscript.prose_tex``)."""
    n = len(plan.amendments())
    out = [prose_tex(f"The analysis plan is version {plan.version} (sha256 {plan.checksum}). It was amended "
                     f"{n} {'time' if n == 1 else 'times'} after results existed. The table below lists each change "
                     "with the verdicts it moved, before -> after, recomputed by the scorer on this build's evidence."),
           "", r"{\footnotesize\setlength{\tabcolsep}{4pt}",   # a longtable: it may break across pages
           r"\begin{longtable}{@{}p{0.09\linewidth}p{0.34\linewidth}p{0.30\linewidth}p{0.23\linewidth}@{}}",
           r"\toprule date & what changed & why & verdicts before $\to$ after \\ \midrule\endfirsthead",
           r"\toprule date & what changed & why & verdicts before $\to$ after \\ \midrule\endhead",
           r"\bottomrule\endfoot"]
    for (date, what), g in df.groupby(["date", "what"], sort=False):
        r0 = g.iloc[0]
        ch = [f"{r.claim_id}: {prose_tex(VERDICT_SHORT.get(r.verdict_before, r.verdict_before) or 'not in the plan')} $\\to$ "
              f"{prose_tex(VERDICT_SHORT.get(r.verdict_after, r.verdict_after))}" for r in g.itertuples() if r.claim_id]
        how = "; ".join(dict.fromkeys(g["how"]))
        recorded = " " + prose_tex(f"({how})") if "recorded in" in how else ""
        cell = ("; ".join(ch) + recorded) if ch else "no verdict moved"
        out.append(f"{prose_tex(str(date))} & {prose_tex(what)} & {prose_tex(str(r0['why']))} & {cell} \\\\")
    out += [r"\end{longtable}}", ""]
    return "\n".join(out)


def raw_rows(evidence: Iterable[EvidenceRow]) -> list[EvidenceRow]:
    """The evidence rows before keying (each once, claim_id empty), from a keyed table."""
    seen, out = set(), []
    for r in evidence:
        if r.sample == "pooled":
            continue
        k = (r.sample, r.role) + r.key()
        if k not in seen:
            seen.add(k)
            out.append(EvidenceRow(**{**asdict(r), "claim_id": ""}))
    return out


def mark_sample(df: pd.DataFrame, profile: str) -> pd.DataFrame:
    """``sample`` = the profile's sample ('full' or 'quick'); quick rows carry the flag
    ``sample_too_small: quick profile`` (its sample is too small for verdicts)."""
    out = df.copy()
    quick = profile != "full"
    out["sample"] = "quick" if quick else "full"
    if quick:
        out["flags"] = ["; ".join([x for x in f.split("; ") if x and not x.startswith("sample_too_small:")]
                                  + ["sample_too_small: " + f"{profile} profile"]) for f in out["flags"]]
    return out


def sample_sentence(df: pd.DataFrame) -> str:
    """Page 1's sentence on the sample (empty for a full-profile table)."""
    if df.empty or (df["sample"] == "full").all():
        return ""
    return "This build is the quick profile: its samples are too small for verdicts."


def inputs_frame(rows: Iterable[dict]) -> pd.DataFrame:
    """results/paper/inputs.csv: inputs we derive (not claims, outside the verdict counts)."""
    return pd.DataFrame(list(rows), columns=INPUT_COLUMNS).fillna("")


# ------------------------------------------------------------ generated prose
def counts(df: pd.DataFrame) -> dict:
    """{paper: {verdict: n}} plus ``n_claims`` per paper, for macros and the at-a-glance table."""
    out: dict = {}
    for p, g in df.groupby("paper"):
        c = g["verdict"].value_counts().to_dict()
        out[p] = {"n_claims": len(g), **{v: int(c.get(v, 0)) for v in VERDICTS}}
    return out


PAPER_NAMES = {"A": "paper A (EM-EKF camera misalignment on Mars approach)",
               "B": "paper B (depth-error landmark selection for powered descent)"}


def _paper_sentence(p: str, g: pd.DataFrame) -> str:
    """'Of the 9 claims of paper A, 2 reproduced (x, A-C3; y, A-C9), 1 not reproduced (z, A-C1).'"""
    parts = []
    for v in VERDICTS:
        sel = g[g["verdict"] == v]
        if sel.empty:
            continue
        names = [f"{r.claim_short}, {r.claim_id}" for r in sel.itertuples()]
        parts.append(f"{len(sel)} {VERDICT_TEXT[v]} ({'; '.join(names)})")
    return f"Of the {len(g)} claims of {PAPER_NAMES.get(p, 'paper ' + p)}, " + ", ".join(parts) + "."


def _short(claim: str) -> str:
    """The claim up to its first parenthesis: the name a sentence uses."""
    claim = claim.split(" (", 1)[0]
    return claim[0].lower() + claim[1:] if claim[:2] != claim[:2].upper() else claim


def _with_short(df: pd.DataFrame) -> pd.DataFrame:
    df = df.copy()
    df["claim_short"] = df["claim"].map(_short)
    return df


def key_numbers(df: pd.DataFrame, headline_ids: Iterable[str]) -> list[str]:
    """One sentence per headline claim with its verdict and key numbers: published, ours as
    written, the best faithful variant, and what the verdict names (bound, addition, choice)."""
    out = []
    for r in _with_short(df).itertuples():
        if r.claim_id not in headline_ids:
            continue
        verb = VERDICT_TEXT[r.verdict] if r.verdict == DEPENDS else "is " + VERDICT_TEXT[r.verdict]
        s = (f"{r.claim_short[0].upper() + r.claim_short[1:]} ({r.claim_id}) {verb}"
             + (f" ({r.named})" if r.named else "") + f": published {r.published}, ours {r.ours_as_written}")
        if r.best_variant and r.ours_best:
            s += f", with {r.best_variant} {r.ours_best}"
        out.append(s + ".")
    return out


def abstract(df: pd.DataFrame, headline_ids: Iterable[str] = ("A-C1", "B-C1", "B-C4")) -> str:
    """The findings part of the abstract (plain text), generated from the claims table:
    per paper, which claims reproduced, which did not and why (the causes of the
    headline claims, with their numbers)."""
    if df.empty:
        return "No claim was evaluated in this build."
    d = _with_short(df)
    s = [_paper_sentence(p, g) for p, g in d.groupby("paper")]
    s += key_numbers(df, tuple(headline_ids))
    return " ".join(s)


#: the conclusion's sentence per verdict: (verdict, opening, one claim, closing)
_CONCLUSION = [
    (WITH_ADDITION, "With an addition the papers do not state: ", "{s} ({i}, with {n})", "."),
    (NOT_REPRODUCIBLE, "Excluded by the information in the stated measurements and prior: ", "{s} ({i}; {n})", "."),
    (NOT_REPRODUCED, "Not reproduced: ", "{s} ({i})", "; the claims table gives each cause."),
    (DEPENDS, "Decided by a choice the paper leaves open: ", "{s} ({i}: {n})", "."),
    (NOT_TESTED, "Not tested by our runs: ", "{s} ({i}: {n})", "."),
    (UNSTABLE, "Different between two independent runs, so not reported either way: ", "{s} ({i}: {n})", "."),
    (SUSPECT, "Better than its own information bound, so suspect rather than reproduced: ", "{s} ({i}: {n})", "."),
]


def conclusion(df: pd.DataFrame) -> str:
    """The conclusion (plain text): what reproduced, what needed an addition (named), what
    the bound excludes, what depends on an open choice, generated from the verdicts."""
    if df.empty:
        return "No claim was evaluated in this build."
    d = _with_short(df)
    out = []
    rep = d[d["verdict"] == REPRODUCED]
    out.append(("Reproduced from the papers as written: " + join([f"{r.claim_short} ({r.claim_id})" for r in rep.itertuples()])
                + ".") if len(rep) else "No claim reproduced from the papers as written.")
    for verdict, head, item, tail in _CONCLUSION:
        sel = d[d["verdict"] == verdict]
        if len(sel):
            out.append(head + join([item.format(s=r.claim_short, i=r.claim_id, n=r.named) for r in sel.itertuples()])
                       + tail)
    return " ".join(out)


def limitations(df: pd.DataFrame) -> str:
    """What this reproduction cannot know, and what was easy and hard, from the verdicts."""
    d = _with_short(df)
    choice = d[d["verdict"].isin([DEPENDS, NOT_TESTED])]
    easy = d[d["verdict"] == REPRODUCED]
    hard = d[d["verdict"].isin([NOT_REPRODUCED, NOT_REPRODUCIBLE])]
    s = [("Both papers leave the camera, the geometry and (paper A) the segment sizes unstated, so every "
         "verdict is conditional on the readings listed in docs/modelling-choices.md; a different reading "
         "could change a verdict, and the published runs' own noise realisations cannot be recovered.")]
    if len(choice):
        s.append(f"Of the {len(d)} claims, {len(choice)} hinge on such a reading or cannot be tested by our runs ("
                 + join([r.claim_id for r in choice.itertuples()]) + ").")
    s.append(f"Easy: {join([r.claim_id for r in easy.itertuples()])} reproduced from the text alone; hard: "
             f"{join([r.claim_id for r in hard.itertuples()])}, where the stated model does not give the "
             "published numbers and the cause had to be measured (bounds, stall rule, paired runs).")
    return " ".join(s)


#: the caption of the claims-at-a-glance table (claims.md)
GLANCE_CAPTION = "Claims at a glance: each published claim, ours as written, the verdict."


def glance(df: pd.DataFrame) -> pd.DataFrame:
    """The at-a-glance table: id, claim, published, ours (as written), verdict."""
    show = df[["claim_id", "claim", "published", "ours_as_written", "verdict"]].copy()
    show["verdict"] = show["verdict"].map(lambda v: VERDICT_TEXT.get(v, v))
    return show.rename(columns={"claim_id": "id", "ours_as_written": "ours (as written)"})

