"""The claims table: one row per distinct published claim of each paper, with a verdict.

The scorecard (:mod:`opnav.report.scorecard`) sets every published *number* beside ours, cell
by cell; this module answers the reader's question instead: which of the papers'
*claims* reproduce. Each paper's rows are computed from its summary files by
:mod:`opnav.report.approach_claims` (paper A) and :mod:`opnav.report.landing_claims` (paper B) and
assembled here. Columns (:data:`COLUMNS`) and verdicts (:data:`VERDICTS`):

``reproduced``
    the paper as written (our reading of it, no addition) gives the claim;
``reproduced_with_addition``
    only a variant that adds something the paper does not state gives it; ``named``
    says what (a variant that uses the true state never counts: it is a diagnostic,
    reported in the cause as "what it would take");
``not_reproduced``
    no faithful variant gives it; the cause says what we get instead;
``not_reproducible``
    not reproduced, and an information bound (Cramér-Rao) of the stated
    measurements and prior says no unbiased estimator could give it; ``named`` is the bound;
``depends_on_choice``
    whether it reproduces depends on a choice the paper leaves open; ``named`` is that choice;
``not_tested``
    our runs cannot test it (e.g. the compared methods pick the same landmarks, so
    equal accuracy follows by construction); ``named`` says why.

Accuracy claims are scored as accuracy: our error about the truth against the
published error and the bound, never "our estimate within 10 % of a published
noise realisation". Every ``cause`` is one sentence generated from the numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping

import pandas as pd

COLUMNS = ["paper", "claim_id", "claim", "published", "ours_as_written", "ours_best", "best_variant",
           "bound", "verdict", "named", "cause", "evidence"]

REPRODUCED = "reproduced"
WITH_ADDITION = "reproduced_with_addition"
NOT_REPRODUCED = "not_reproduced"
NOT_REPRODUCIBLE = "not_reproducible"
DEPENDS = "depends_on_choice"
NOT_TESTED = "not_tested"
VERDICTS = (REPRODUCED, WITH_ADDITION, NOT_REPRODUCED, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED)
#: verdicts that must name something (the addition, the choice, the bound, the reason)
NEEDS_NAMED = (WITH_ADDITION, NOT_REPRODUCIBLE, DEPENDS, NOT_TESTED)

#: how each verdict reads in running text (abstract, conclusion)
#: the verdicts as the at-a-glance table prints them
VERDICT_SHORT = {
    "reproduced": "reproduced", "reproduced_with_addition": "with an addition", "not_reproduced": "not reproduced",
    "not_reproducible": "not reproducible", "depends_on_choice": "depends on a choice", "not_tested": "not tested",
}
VERDICT_TEXT = {
    REPRODUCED: "reproduced",
    WITH_ADDITION: "reproduced only with an addition",
    NOT_REPRODUCED: "not reproduced",
    NOT_REPRODUCIBLE: "not reproducible under the stated assumptions",
    DEPENDS: "depends on a choice the paper leaves open",
    NOT_TESTED: "not tested",
}


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
    """One variant's reading of one claim: does it give the claim, and what it shows."""
    label: str
    ok: bool
    text: str                 # our value, as text with units
    score: float = math.inf   # lower is better (to pick the best variant)
    diagnostic: bool = False  # uses the truth: never earns "reproduced"
    beyond: bool = False      # beyond the paper (what practitioners do): never earns "reproduced" either
    extra: dict = field(default_factory=dict)


def decide(outcomes: Mapping[str, Outcome], as_written: str, describe: Callable[[str], str],
           bound_blocks: str = "") -> tuple[str, Outcome | None, Outcome | None, str]:
    """The verdict of a claim from its per-variant outcomes.

    ``as_written``: the label of the paper-as-written variant; ``describe(label)``: the
    addition a variant makes (for ``named``); ``bound_blocks``: non-empty (the bound, as
    text) when an information bound of the as-written variant excludes the claim.
    Returns (verdict, as-written outcome, best faithful outcome or None, named)."""
    lit = outcomes.get(as_written)
    faithful = [o for k, o in outcomes.items() if k != as_written and not o.diagnostic and not o.beyond]
    best = min(faithful, key=lambda o: (not o.ok, o.score, o.label), default=None)
    if lit is not None and lit.ok:
        return REPRODUCED, lit, None, ""
    if best is not None and best.ok:
        return WITH_ADDITION, lit, best, describe(best.label)
    if bound_blocks:
        return NOT_REPRODUCIBLE, lit, best, bound_blocks
    return NOT_REPRODUCED, lit, best, ""


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


def row(paper: str, claim_id: str, claim: str, published: str, verdict: str, cause: str,
        evidence: str, ours_as_written: str = "", ours_best: str = "", best_variant: str = "",
        bound: str = "", named: str = "") -> dict:
    """One claims-table row, checked: a stated verdict, ``named`` where the verdict needs
    it, and a cause of one sentence."""
    if verdict not in VERDICTS:
        raise ValueError(f"{claim_id}: verdict {verdict!r} is not one of {VERDICTS}")
    if verdict in NEEDS_NAMED and not named:
        raise ValueError(f"{claim_id}: verdict {verdict} needs 'named'")
    cause = " ".join(cause.split())
    if not cause.endswith("."):
        cause += "."
    if ". " in cause.replace("e.g. ", "").replace("i.e. ", "").replace("vs. ", ""):
        raise ValueError(f"{claim_id}: the cause must be one sentence: {cause!r}")
    return {"paper": paper, "claim_id": claim_id, "claim": claim, "published": published,
            "ours_as_written": ours_as_written, "ours_best": ours_best, "best_variant": best_variant,
            "bound": bound, "verdict": verdict, "named": named, "cause": cause[0].upper() + cause[1:],
            "evidence": evidence}


def frame(rows: Iterable[dict]) -> pd.DataFrame:
    """The claims table, columns in :data:`COLUMNS` order, ids unique."""
    df = pd.DataFrame(list(rows), columns=COLUMNS)
    dup = df["claim_id"][df["claim_id"].duplicated()].tolist()
    if dup:
        raise ValueError(f"claim ids defined twice: {dup}")
    return df.fillna("")


# ------------------------------------------------------------ generated prose
def counts(df: pd.DataFrame) -> dict:
    """{paper: {verdict: n}} plus ``n_claims`` per paper, for macros and the at-a-glance table."""
    out: dict = {}
    for p, g in df.groupby("paper"):
        c = g["verdict"].value_counts().to_dict()
        out[p] = {"n_claims": int(len(g)), **{v: int(c.get(v, 0)) for v in VERDICTS}}
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
    s = ["Both papers leave the camera, the geometry and (paper A) the segment sizes unstated, so every "
         "verdict is conditional on the readings listed in docs/modelling-choices.md; a different reading "
         "could change a verdict, and the published runs' own noise realisations cannot be recovered."]
    if len(choice):
        s.append(f"Of the {len(d)} claims, {len(choice)} hinge on such a reading or cannot be tested by our runs ("
                 + join([r.claim_id for r in choice.itertuples()]) + ").")
    s.append(f"Easy: {join([r.claim_id for r in easy.itertuples()])} reproduced from the text alone; hard: "
             f"{join([r.claim_id for r in hard.itertuples()])}, where the stated model does not give the "
             "published numbers and the cause had to be measured (bounds, stall rule, paired runs).")
    return " ".join(s)


def glance(df: pd.DataFrame) -> pd.DataFrame:
    """The at-a-glance table: id, claim, published, ours (as written), verdict."""
    show = df[["claim_id", "claim", "published", "ours_as_written", "verdict"]].copy()
    show["verdict"] = show["verdict"].map(lambda v: VERDICT_TEXT.get(v, v))
    return show.rename(columns={"claim_id": "id", "ours_as_written": "ours (as written)"})

