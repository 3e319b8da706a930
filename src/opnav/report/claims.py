"""The claims table: one row per distinct published claim of each paper, with a verdict.

The scorecard (:mod:`opnav.report.scorecard`) sets every published *number* beside ours, cell
by cell; this module answers the reader's question instead: which of the papers'
*claims* reproduce. Each paper's rows are computed from its summary files by
:mod:`opnav.report.approach_claims` (paper A) and :mod:`opnav.report.landing_claims` (paper B) and
assembled here. Columns (:data:`COLUMNS`) and verdicts (:data:`VERDICTS`):

``reproduced``
    the paper as written (our reading of it, no addition) gives the claim (a
    negative control that also gives it is flagged, not a reason to withhold it);
``reproduced_with_addition``
    only a variant that adds something the paper does not state gives it; ``named``
    says what (a variant that uses the true state never counts: it is a diagnostic,
    reported in the cause as "what it would take");
``not_reproduced``
    no faithful variant gives it; the cause says what we get instead;
``not_reproducible``
    not reproduced, and an information bound (Cramér-Rao) of the stated
    measurements and prior says no unbiased estimator could give it; ``named`` is the
    bound (only an information bound: a Monte-Carlo floor of one filter is evidence
    for "not reproduced" or "depends on a choice");
``depends_on_choice``
    whether it reproduces depends on a choice the paper leaves open; ``named`` is that choice;
``not_tested``
    our runs cannot test it (e.g. the compared methods pick the same landmarks, so
    equal accuracy follows by construction); ``named`` says why;
``unstable``
    the main sample and the replication sample (an independent seed base) give
    different verdicts; the cause gives both;
``suspect``
    an accuracy beats its own information bound by more than the plan's factor
    (judged with the seeds' spread): a leak or a bug, never "reproduced".

``flags`` qualifies a verdict without changing it: ``control_also_meets: closest``
(the claim holds, but a negative control meets it too, so the test cannot credit the
method), ``beats_bound: 14x``, ``floor_not_bound`` (a Monte-Carlo floor of one filter,
evidence but not an information bound), ``sample_too_small: quick profile``.

Every margin, tolerance and threshold of a verdict is a fixed number of the analysis
plan (``data/analysis_plan.yaml``, :func:`load_plan`), with its reason; the scorer
reads them from there and :meth:`Plan.unused` names any the verdicts never read.

Accuracy claims are scored as accuracy: our error about the truth against the
published error and the bound, never "our estimate within 10 % of a published
noise realisation". Every ``cause`` is one sentence generated from the numbers.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from opnav.core import published

COLUMNS = ["paper", "claim_id", "claim", "published", "ours_as_written", "ours_best", "best_variant",
           "bound", "ours_replication", "verdict", "verdict_replication", "flags", "named", "would_take",
           "cause", "evidence", "sample"]

REPRODUCED = "reproduced"
WITH_ADDITION = "reproduced_with_addition"
NOT_REPRODUCED = "not_reproduced"
NOT_REPRODUCIBLE = "not_reproducible"
DEPENDS = "depends_on_choice"
NOT_TESTED = "not_tested"
UNSTABLE = "unstable"
SUSPECT = "suspect"
VERDICTS = (REPRODUCED, WITH_ADDITION, NOT_REPRODUCED, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED, UNSTABLE, SUSPECT)
#: verdicts that must name something (the addition, the choice, the bound, the reason)
NEEDS_NAMED = (WITH_ADDITION, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED, UNSTABLE, SUSPECT)
#: a cause is one sentence a reader takes in at once (issue 42: about 40 words)
MAX_CAUSE_WORDS = 45

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
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return "n/a"
    s = f"{v:.{nd}g}" if abs(v) < 10 ** nd else f"{v:.0f}"
    return f"{s} {unit}".rstrip() if unit else s


def join(items: Iterable[str], none: str = "none") -> str:
    """'a', 'a and b', 'a, b and c'."""
    items = [i for i in items if i]
    if not items:
        return none
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


@dataclass
class Outcome:
    """One variant's reading of one claim: does it give the claim, and what it shows.

    ``bound``/``n``: for an accuracy, the information bound (1-sigma) of the data the
    variant used and the number of seeds behind ``err`` (the RMS error), for the bound
    guard (:func:`beats_bound`)."""
    label: str
    ok: bool
    text: str                 # our value, as text with units
    score: float = math.inf   # lower is better (to pick the best variant)
    diagnostic: bool = False  # uses the truth: never earns "reproduced"
    beyond: bool = False      # beyond the paper (what practitioners do): never earns "reproduced" either
    err: float = math.nan
    bound: float = math.nan
    n: int = 0
    extra: dict = field(default_factory=dict)


def beats_bound(err: float, bound: float, n: int, plan: Plan) -> float | None:
    """The factor by which an RMS error ``err`` over ``n`` seeds beats its information
    bound ``bound`` (same units), or None if it does not by more than the plan's
    ``bound_factor``. The seeds' spread enters as ``spread_k`` standard errors of an
    RMS over ``n`` seeds (about ``err / sqrt(2 n)``): the error must stay below
    ``bound / bound_factor`` even at ``err (1 + spread_k / sqrt(2 n))``."""
    factor, k = plan.guard("bound_factor"), plan.guard("spread_k")
    if not (math.isfinite(err) and math.isfinite(bound)) or bound <= 0 or n < 1:
        return None
    upper = err * (1.0 + k / math.sqrt(2.0 * n))
    if upper * factor < bound:
        return math.inf if err <= 0 else bound / err
    return None


@dataclass
class Decision:
    verdict: str
    lit: Outcome | None
    best: Outcome | None
    named: str
    flags: list = field(default_factory=list)
    #: of the faithful variants that give the claim, the one adding least (fewest '+' parts)
    smallest: Outcome | None = None


def decide(outcomes: Mapping[str, Outcome], as_written: str, describe: Callable[[str], str],
           bound_blocks: str = "", plan: Plan | None = None) -> Decision:
    """The verdict of a claim from its per-variant outcomes.

    ``as_written``: the label of the paper-as-written variant; ``describe(label)``: the
    addition a variant makes (for ``named``); ``bound_blocks``: non-empty (the bound, as
    text) when an *information bound* of the as-written variant excludes the claim (a
    Monte-Carlo floor of one filter is not one: pass it as evidence, not here);
    ``plan``: the analysis plan, for the bound guard (any non-diagnostic variant whose
    error beats its bound by more than the plan's factor makes the claim ``suspect``).
    Negative controls that also meet a claim are the paper-B scorer's flag
    (``control_also_meets``), not a verdict."""
    lit = outcomes.get(as_written)
    faithful = [o for k, o in outcomes.items() if k != as_written and not o.diagnostic and not o.beyond]
    best = min(faithful, key=lambda o: (not o.ok, o.score, o.label), default=None)
    flags: list = []
    if plan is not None:
        hits = []
        for o in outcomes.values():
            r = None if o.diagnostic else beats_bound(o.err, o.bound, o.n, plan)
            if r is not None:
                hits.append((r, o.label))
        if hits:
            r, lab = max(hits)
            flags.append(("beats_bound", f"{fmt(r, 2)}x ({lab})"))
            return Decision(SUSPECT, lit, best, f"{lab} is {fmt(r, 2)} times below its own bound", flags)
    if lit is not None and lit.ok:
        verdict, named = REPRODUCED, ""
    elif best is not None and best.ok:
        verdict, named = WITH_ADDITION, describe(best.label)
        smallest = min((o for o in faithful if o.ok), key=lambda o: (o.label.count("+"), o.score, o.label))
        return Decision(verdict, lit, best, named, flags, smallest)
    elif bound_blocks:
        return Decision(NOT_REPRODUCIBLE, lit, None if best is None else best, bound_blocks, flags)
    else:
        return Decision(NOT_REPRODUCED, lit, best, "", flags)
    return Decision(verdict, lit, None if verdict == REPRODUCED else best, named, flags)


def diagnostic_note(outcomes: Mapping[str, Outcome]) -> str:
    """'what it would take': the best diagnostic (truth-using) variant and the best variant
    beyond the paper, as clauses (never a verdict)."""
    out = []
    beyond = [o for o in outcomes.values() if o.beyond]
    if beyond:
        b = min(beyond, key=lambda o: (not o.ok, o.score, o.label))
        out.append(f"beyond the paper, {b.label} " + ("reaches it" if b.ok else "comes closest") + f" ({b.text})")
    diag = [o for o in outcomes.values() if o.diagnostic]
    if diag:
        d = min(diag, key=lambda o: (not o.ok, o.score, o.label))
        out.append(f"the {d.label} diagnostic, which is given the true state, "
                   + ("reaches it" if d.ok else "comes closest") + f" ({d.text})")
    return "; ".join(out)


def flag_text(flags: Iterable) -> str:
    """Flags as the table writes them: 'name: value' joined by '; '."""
    out = []
    for f in flags:
        name, value = (f, "") if isinstance(f, str) else f
        out.append(f"{name}: {value}" if value != "" else str(name))
    return "; ".join(out)


def _one_sentence(claim_id: str, cause: str) -> str:
    cause = " ".join(cause.split())
    if not cause.endswith("."):
        cause += "."
    if ". " in cause.replace("e.g. ", "").replace("i.e. ", "").replace("vs. ", ""):
        raise ValueError(f"{claim_id}: the cause must be one sentence: {cause!r}")
    n = len(cause.split())
    if n > MAX_CAUSE_WORDS:
        raise ValueError(f"{claim_id}: the cause has {n} words (at most {MAX_CAUSE_WORDS}): {cause!r}")
    return cause[0].upper() + cause[1:]


def row(paper: str, claim_id: str, claim: str, published: str, verdict: str, cause: str,
        evidence: str, ours_as_written: str = "", ours_best: str = "", best_variant: str = "",
        bound: str = "", named: str = "", flags: Iterable = (), would_take: str = "",
        sample: str = "full", ours_replication: str = "", verdict_replication: str = "") -> dict:
    """One claims-table row, checked: a stated verdict, ``named`` where the verdict needs
    it, and a cause of one sentence of at most :data:`MAX_CAUSE_WORDS` words."""
    if verdict not in VERDICTS:
        raise ValueError(f"{claim_id}: verdict {verdict!r} is not one of {VERDICTS}")
    if verdict in NEEDS_NAMED and not named:
        raise ValueError(f"{claim_id}: verdict {verdict} needs 'named'")
    return {"paper": paper, "claim_id": claim_id, "claim": claim, "published": published,
            "ours_as_written": ours_as_written, "ours_best": ours_best, "best_variant": best_variant,
            "bound": bound, "ours_replication": ours_replication, "verdict": verdict,
            "verdict_replication": verdict_replication, "flags": flag_text(flags), "named": named,
            "would_take": would_take, "cause": _one_sentence(claim_id, cause), "evidence": evidence,
            "sample": sample}


def frame(rows: Iterable[dict]) -> pd.DataFrame:
    """The claims table, columns in :data:`COLUMNS` order, ids unique."""
    df = pd.DataFrame(list(rows), columns=COLUMNS)
    dup = df["claim_id"][df["claim_id"].duplicated()].tolist()
    if dup:
        raise ValueError(f"claim ids defined twice: {dup}")
    return df.fillna("")


def check_plan_covers(df: pd.DataFrame, plan: Plan) -> None:
    """Every claim row has a plan entry (raises :class:`PlanError` naming the first that has none)."""
    for cid in df["claim_id"]:
        plan.entry(cid)


def _add_flag(flags: str, name: str, value: str) -> str:
    new = f"{name}: {value}"
    return f"{flags}; {new}" if flags else new


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


def with_replication(main: pd.DataFrame, rep: pd.DataFrame, ids: Iterable[str] | None = None) -> pd.DataFrame:
    """The main table with the replication sample's reading beside it.

    ``rep``: the claims table of the same claims scored on the replication sample (an
    independent seed base). Its verdict and as-written value fill ``verdict_replication``
    and ``ours_replication``; a claim whose two verdicts differ reads ``unstable``, with
    both verdicts in the cause and the main one kept in ``flags``. Claims the
    replication does not score (or, given ``ids``, not among them) keep their verdict, with
    an empty replication."""
    out = main.copy()
    r = rep.set_index("claim_id")
    if ids is not None:
        r = r[r.index.isin(list(ids))]
    for i, row_ in out.iterrows():
        cid = row_["claim_id"]
        if cid not in r.index:
            continue
        v1, v2 = row_["verdict"], r.loc[cid, "verdict"]
        out.at[i, "verdict_replication"] = v2
        out.at[i, "ours_replication"] = r.loc[cid, "ours_as_written"]
        if v1 != v2 and NOT_TESTED not in (v1, v2):
            out.at[i, "flags"] = _add_flag(out.at[i, "flags"], "verdict_main", v1)
            out.at[i, "verdict"] = UNSTABLE
            out.at[i, "named"] = f"{VERDICT_SHORT[v1]} in the main sample, {VERDICT_SHORT[v2]} in the replication"
            out.at[i, "cause"] = _one_sentence(cid, (
                f"The main sample reads {VERDICT_SHORT[v1]} and the replication sample, on an independent seed "
                f"base, reads {VERDICT_SHORT[v2]}, so this verdict moves with the seeds and neither is reported"))
    return out


def mark_sample(df: pd.DataFrame, profile: str) -> pd.DataFrame:
    """``sample`` = the profile's sample ('full' or 'quick'); quick rows carry the flag
    ``sample_too_small: quick profile`` (its sample is too small for verdicts)."""
    out = df.copy()
    quick = profile != "full"
    out["sample"] = "quick" if quick else "full"
    if quick:  # one sample flag: the profile's (a row's own seed count says the same)
        out["flags"] = [_add_flag("; ".join(x for x in f.split("; ") if x and not x.startswith("sample_too_small:")),
                                  "sample_too_small", f"{profile} profile") for f in out["flags"]]
    return out


def sample_sentence(df: pd.DataFrame) -> str:
    """Page 1's sentence on the sample (empty for a full-profile table)."""
    if df.empty or (df["sample"] == "full").all():
        return ""
    return ("This build is the quick profile: its Monte-Carlo samples are too small for verdicts, so every "
            "verdict below only shows that the pipeline runs, not what the papers' claims are.")


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

