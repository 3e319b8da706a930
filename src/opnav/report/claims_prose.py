"""Page 1's abstract findings, the conclusion and the limitations: plain sentences
generated from the claims table (the rows of :func:`opnav.report.claims.frame`), each
finding once, grouped by verdict (:func:`group_sentences`); :func:`page_one_abstract_tex`
makes the abstract's LaTeX (:func:`opnav.report.manuscript.prose_tex`). Nothing here is
fixed text about a result: every sentence names the claims the table puts in its group.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

from opnav.report.manuscript import cell_text, prose_tex, sentence

if TYPE_CHECKING:  # annotations only
    import pandas as pd


#: the abstract's length limit (words, LaTeX markup not counted)
ABSTRACT_MAX_WORDS = 200
#: the words of the framing sentences main.tex writes before the generated findings
ABSTRACT_FRAMING_WORDS = 40
#: verdicts a reader counts as "not reproduced" in the broad sense (each group gets its cause)
#: (in the order the abstract gives them: what an information bound excludes, what needs an addition first)
NOT_OK = ("not_reproducible", "reproduced_with_addition", "suspect", "unstable", "not_reproduced",
           "depends_on_choice", "not_tested")
_PAPER_WORDS = {"A": "Paper A", "B": "Paper B"}


def verdict_counts_sentence(paper: str, verdicts: Iterable[str]) -> str:
    """'Paper A: of its 10 claims, 2 reproduced, 3 not reproducible and 5 ...' (the
    verdicts of one paper's claims, counted in :data:`opnav.report.claims.VERDICTS` order)."""
    from opnav.report.claims import VERDICT_SHORT, VERDICTS

    verdicts = list(verdicts)
    parts = [f"{n} {VERDICT_SHORT[v]}" for v in VERDICTS if (n := verdicts.count(v))]
    return sentence(f"{_PAPER_WORDS.get(paper, 'Paper ' + paper)}: of its {len(verdicts)} claims, "
                    + ", ".join(parts[:-1]) + (" and " if len(parts) > 1 else "") + parts[-1])


def word_count(text: str) -> int:
    """Words of a (plain or LaTeX) text: tokens with a letter or digit, markup stripped."""
    plain = re.sub(r"\\[A-Za-z]+\*?|[{}$]", " ", text)
    return sum(1 for w in plain.split() if re.search(r"[A-Za-z0-9]", w))


#: how a group of claims with one verdict reads: (plural predicate, singular predicate)
_PREDICATE = {
    "reproduced": ("are reproduced", "is reproduced"),
    "reproduced_with_addition": ("reproduce only with an addition", "reproduces only with an addition"),
    "not_reproduced": ("are not reproduced", "is not reproduced"),
    "not_reproducible": ("are not reproducible", "is not reproducible"),
    "depends_on_choice": ("depend on a choice the paper leaves open", "depends on a choice the paper leaves open"),
    "not_tested": ("are not tested", "is not tested"),
    "unstable": ("differ between two independent runs", "differs between two independent runs"),
    "suspect": ("are suspect, better than their own information bound", "is suspect, better than its own information bound"),
}


def _ids(ids: list[str]) -> str:
    return ", ".join(ids[:-1]) + " and " + ids[-1] if len(ids) > 1 else ids[0]


def group_sentences(grp: list[Mapping], verdict: str, said: set | None = None) -> str:
    """One group of claims with one verdict, each idea once: the claims that share what the
    verdict names (the addition, the choice, the bound) in one sentence that names it once;
    a claim with nothing named gets its cause ('Why', or 'For <id>' in a group); then what
    it would take, unless ``said`` (the texts already written) holds it."""
    said = set() if said is None else said
    by_named: dict[str, list[Mapping]] = {}
    for r in grp:
        by_named.setdefault(cell_text(r, "named"), []).append(r)
    out = []
    for named, rows in by_named.items():
        ids = [r["claim_id"] for r in rows]
        out.append(sentence(f"{_ids(ids)} {_PREDICATE[verdict][len(ids) == 1]}" + (f": {named}" if named else "")))
        cause = cell_text(rows[0], "cause")
        if cause and not named and verdict != "reproduced":
            out.append(sentence(f"{'Why' if len(ids) == 1 else 'For ' + ids[0]}: {cause}"))
        take = cell_text(rows[0], "would_take")
        if take and take not in said:
            said.add(take)
            out.append(sentence(f"What it would take: {take}"))
    return " ".join(out)


def conclusion_text(df: pd.DataFrame) -> str:
    """The conclusion (plain text), each finding once: per paper, what reproduced as written,
    then every other group as page 1 words it (:func:`group_sentences`), nothing dropped."""
    rows = [dict(r) for _, r in df.iterrows()] if len(df) else []
    if not rows:
        return "No claim was evaluated in this build."
    out = []
    for p in dict.fromkeys(r["paper"] for r in rows):
        g = [r for r in rows if r["paper"] == p]
        said: set = set()
        for v in ("reproduced", *NOT_OK):
            grp = [r for r in g if r["verdict"] == v]
            if grp:
                out.append(group_sentences(grp, v, said))
    return " ".join(out)


def limitations_text(df: pd.DataFrame) -> str:
    """The limitations (plain text), from the claims table: what every verdict is conditional
    on, which claims hinge on an open choice directly, and what cannot be recovered."""
    rows = [dict(r) for _, r in df.iterrows()] if len(df) else []
    hinge = [r["claim_id"] for r in rows if r["verdict"] in ("depends_on_choice", "not_tested", "unstable")]
    s = [("Every verdict is conditional on our readings of what the papers leave open, listed in the "
         "table of what we did differently beside the papers' own values; a different reading could change a verdict")]
    if hinge:
        s.append(f"{_ids(hinge)} {'hinge' if len(hinge) > 1 else 'hinges'} on such a reading, or on a test "
                 "our runs cannot make, directly")
    s.append("The published runs' own noise realisations cannot be recovered, so each published value is "
             "compared with the distribution of ours over seeds or runs, never with one run")
    return " ".join(sentence(x) for x in s)


def abstract_findings(df: pd.DataFrame) -> str:
    """The findings of page 1 in plain sentences (plain text; :func:`prose_tex` makes it LaTeX),
    generated from the claims table: per paper, the verdict counts, then each group of claims
    not reproduced as written (:func:`group_sentences`, in :data:`NOT_OK`'s order). Groups are
    dropped from the longer paper's tail until the whole, with the framing sentences of
    ``main.tex``, is at most :data:`ABSTRACT_MAX_WORDS` words."""
    rows = [dict(r) for _, r in df.iterrows()] if len(df) else []
    if not rows:
        return "No claim was evaluated in this build."
    papers = list(dict.fromkeys(r["paper"] for r in rows))
    per_paper: dict[str, list[str]] = {}
    for p in papers:
        g = [r for r in rows if r["paper"] == p]
        s = [verdict_counts_sentence(p, [r["verdict"] for r in g])]
        said: set = set()
        for v in NOT_OK:  # the order of NOT_OK: what an information bound says first
            grp = [r for r in g if r["verdict"] == v]
            if grp:
                s.append(group_sentences(grp, v, said))
        per_paper[p] = s
    budget = ABSTRACT_MAX_WORDS - ABSTRACT_FRAMING_WORDS
    while sum(word_count(" ".join(s)) for s in per_paper.values()) > budget:
        longest = max(per_paper, key=lambda p: (word_count(" ".join(per_paper[p])), papers.index(p)))
        if len(per_paper[longest]) <= 1:
            break
        per_paper[longest].pop()
    return " ".join(" ".join(s) for s in per_paper.values())


def page_one_abstract_tex(df: pd.DataFrame, sample_sentence: str = "") -> str:
    """The generated part of page 1's abstract as LaTeX: the findings and, for a quick-profile
    table, the sentence that its sample is too small for verdicts (first)."""
    text = abstract_findings(df)
    return prose_tex(" ".join(t for t in (sample_sentence, text) if t)) + "\n"


def sample_sentence_of(df: pd.DataFrame) -> str:
    """The claims table's own sentence on its sample (quick profile: too small for verdicts);
    empty for a full build or a table without the ``sample`` column."""
    if "sample" not in df.columns:
        return ""
    from opnav.report.claims import sample_sentence

    return sample_sentence(df)
