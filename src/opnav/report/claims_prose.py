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

from opnav.core import wording
from opnav.report.manuscript import cell_text, prose_tex, sentence

if TYPE_CHECKING:  # annotations only
    import pandas as pd


#: the abstract's length limit (words, LaTeX markup not counted)
ABSTRACT_MAX_WORDS = 200
#: the words of the framing sentence main.tex writes before the generated findings, as printed
#: ("paper A [1]:" three words)
ABSTRACT_FRAMING_WORDS = 30
#: verdicts a reader counts as "not reproduced" in the broad sense (each group gets its cause)
#: (in the order the abstract gives them: what an information bound excludes, what needs an addition first)
NOT_OK = ("not_reproducible", "reproduced_with_addition", "suspect", "unstable", "not_reproduced",
           "depends_on_choice", "not_tested")
_PAPER_WORDS = {"A": "Paper A", "B": "Paper B"}


#: a verdict after a count: (one claim, several claims), agreeing with the number
_COUNTED = {
    "depends_on_choice": ("depends on a choice", "depend on a choice"),
    "unstable": ("unstable", "unstable"),
}


def verdict_counts_sentence(paper: str, verdicts: Iterable[str]) -> str:
    """'Paper A: of its 10 claims, 2 reproduced, 3 not reproducible and 1 depends on a choice'
    (the verdicts of one paper's claims, counted in :data:`opnav.report.claims.VERDICTS`
    order; a verb agrees with its count: '2 depend on a choice')."""
    from opnav.report.claims import VERDICT_SHORT, VERDICTS

    verdicts = list(verdicts)
    parts = []
    for v in VERDICTS:
        n = verdicts.count(v)
        if n:
            word = _COUNTED[v][n != 1] if v in _COUNTED else VERDICT_SHORT[v]
            parts.append(f"{n} {word}")
    return sentence(f"{_PAPER_WORDS.get(paper, 'Paper ' + paper)}: of its {wording.count(len(verdicts), 'claim')}, "
                    + wording.join(parts))


def word_count(text: str) -> int:
    """Words of a (plain or LaTeX) text: tokens with a letter or digit, markup stripped."""
    plain = re.sub(r"\\[A-Za-z]+\*?|[{}$]", " ", text)
    return sum(1 for w in plain.split() if re.search(r"[A-Za-z0-9]", w))


#: how a group of claims with one verdict reads: (plural predicate, singular predicate); the
#: choice of a claim that depends on one follows its predicate directly ('depend on the camera')
_PREDICATE = {
    "reproduced": ("are reproduced", "is reproduced"),
    "reproduced_with_addition": ("reproduce only with an addition", "reproduces only with an addition"),
    "not_reproduced": ("are not reproduced", "is not reproduced"),
    "not_reproducible": ("are not reproducible", "is not reproducible"),
    "depends_on_choice": ("depend on", "depends on"),
    "not_tested": ("are not tested", "is not tested"),
    "unstable": ("differ between two independent runs", "differs between two independent runs"),
    "suspect": ("are suspect, better than their own information bound", "is suspect, better than its own information bound"),
}
#: the scorer's frame around the evidence a cause quotes (opnav.report.scorer._cause), dropped
#: where a sentence names the verdict itself
_CAUSE_FRAME = [re.compile(r"^As written it fails:\s*"), re.compile(r",? and no faithful variant passes\.?$"),
                re.compile(r"^Not tested:\s*")]
#: a scope in parentheses at the end of what a verdict names ('... (T1-01)'): claims whose named
#: texts differ only there share one sentence
_TRAILING_SCOPE = re.compile(r"\s*\((?:T\d+-\d+|interior|site-tilt|[a-z-]+ camera)\)(?=,|$)")


def _ids(ids: list[str]) -> str:
    return wording.join(ids)


def claim_cause(r: Mapping) -> str:
    """A claim's cause without the scorer's frame ('As written it fails: ...'): the evidence
    the verdict turned on, for a sentence that names the verdict itself."""
    text = cell_text(r, "cause").rstrip(".")
    for pat in _CAUSE_FRAME:
        text = pat.sub("", text)
    text = text.strip()
    # after 'is not reproduced:' the cause goes on in lower case (not an acronym: 'SVD', 'EM')
    return text[0].lower() + text[1:] if len(text) > 1 and text[0].isupper() and text[1].islower() else text


def take_text(take: str) -> str:
    """What a claim would take, said once: each distinct part once (the scorer joins one per
    scope with '; ')."""
    return "; ".join(dict.fromkeys(p.strip() for p in take.split("; ") if p.strip()))


class _Said:
    """One generated sentence: its claims, the head that names them and their verdict, and the
    body (the cause, choice or take) that :meth:`shorter` may cut to fit a word budget."""

    def __init__(self, ids: list[str], head: str, body: str = "", joiner: str = ": ", verdict: str = ""):
        self.ids, self.head, self.joiner, self.verdict = ids, head, joiner, verdict
        self.body = wording.shorten(body, wording.MAX_SENTENCE_WORDS - wording.word_count(head)) if body else ""

    @property
    def text(self) -> str:
        return sentence(self.head + (self.joiner + self.body if self.body else ""))

    def shorter(self) -> bool:
        """Cut the body one step (:func:`opnav.core.wording.shorter`); False when it cannot."""
        nxt = wording.shorter(self.body, min_words=4) if self.body else None
        if nxt is None:
            return False
        self.body = nxt
        return True


def _group_items(grp: list[Mapping], verdict: str) -> list[_Said]:
    """The sentences of one verdict's group: claims that share what the verdict names (up to a
    trailing scope) in one sentence that names it once (a claim whose verdict names nothing gives
    its cause instead); a claim not reproduced in its own sentence with its cause."""
    out = []
    if verdict == "not_reproduced":
        for r in grp:
            out.append(_Said([r["claim_id"]], f"{r['claim_id']} {_PREDICATE[verdict][1]}", claim_cause(r),
                             verdict=verdict))
        return out
    by_named: dict[str, list[Mapping]] = {}
    for r in grp:
        by_named.setdefault(_TRAILING_SCOPE.sub("", cell_text(r, "named")), []).append(r)
    for named, rows in by_named.items():
        ids = [r["claim_id"] for r in rows]
        head = f"{_ids(ids)} {_PREDICATE[verdict][len(ids) == 1]}"
        if verdict == "depends_on_choice":
            out.append(_Said(ids, head, named or "a choice the paper leaves open", " ", verdict))
        elif verdict == "reproduced":
            out.append(_Said(ids, head, verdict=verdict))
        else:
            out.append(_Said(ids, head, named or claim_cause(rows[0]), verdict=verdict))
    return out


def _take_items(grp: list[Mapping], said: set) -> list[_Said]:
    """What the group's claims would take, one sentence per distinct text not yet in ``said``
    (added to it): 'What it would take: ...' when one text serves the whole group, else
    'What it would take for A-C2: ...'."""
    by_take: dict[str, list[str]] = {}
    for r in grp:
        take = take_text(cell_text(r, "would_take"))
        if take:
            by_take.setdefault(take, []).append(r["claim_id"])
    whole = len(by_take) == 1 and len(next(iter(by_take.values()), [])) == len(grp)
    out = []
    for take, ids in by_take.items():
        if take in said:
            continue
        said.add(take)
        out.append(_Said(ids, "What it would take" + ("" if whole else f" for {_ids(ids)}"), take))
    return out


def group_sentences(grp: list[Mapping], verdict: str, said: set | None = None) -> str:
    """One group of claims with one verdict, each idea once: the claims that share what the
    verdict names (the addition, the choice, the bound) in one sentence that names it once;
    each claim not reproduced with its own cause; then what they would take, each text once
    unless ``said`` (the texts already written) holds it. No sentence is longer than
    :data:`opnav.core.wording.MAX_SENTENCE_WORDS` words."""
    said = set() if said is None else said
    items = _group_items(grp, verdict)
    if verdict != "reproduced":
        items += _take_items(grp, said)
    return " ".join(i.text for i in items)


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


#: verdicts page 1 must explain in every build: the choice of each claim that depends on one,
#: the cause of each claim not reproduced (issue 55 item 5), what differs, what is suspect
ABSTRACT_REQUIRED = ("depends_on_choice", "not_reproduced", "unstable", "suspect")
#: a snake_case key (a plan margin's or setting's name) a reader of page 1 does not know
_RAW_KEY = re.compile(r"\b[a-z]+_[a-z_]+\b")


def abstract_findings(df: pd.DataFrame, budget: int | None = None) -> str:
    """The findings of page 1 in plain sentences (plain text; :func:`prose_tex` makes it LaTeX),
    generated from the claims table, at most ``budget`` words (the abstract's limit less the
    framing sentence of ``main.tex``). Per paper: the verdict counts; then, always, the choice
    of every claim that depends on one and the cause of every claim not reproduced
    (:data:`ABSTRACT_REQUIRED`; their causes cut a step at a time, longest first, until they
    fit: parentheses, then clauses); then, while they fit, the other groups not reproduced as
    written (:data:`NOT_OK`'s order) and what they would take (only texts a reader can read:
    no plan key's raw name)."""
    rows = [dict(r) for _, r in df.iterrows()] if len(df) else []
    if not rows:
        return "No claim was evaluated in this build."
    budget = ABSTRACT_MAX_WORDS - ABSTRACT_FRAMING_WORDS if budget is None else budget
    papers = list(dict.fromkeys(r["paper"] for r in rows))
    # every candidate sentence: (paper, order, tier, item); tier 0 counts, 1 required, 2 other groups, 3 takes
    cands: list[tuple[str, int, int, _Said]] = []
    for p in papers:
        g = [r for r in rows if r["paper"] == p]
        cands.append((p, 0, 0, _Said([], verdict_counts_sentence(p, [r["verdict"] for r in g]).rstrip("."))))
        said: set = set()
        for k, v in enumerate(NOT_OK):
            grp = [r for r in g if r["verdict"] == v]
            if not grp:
                continue
            tier = 1 if v in ABSTRACT_REQUIRED else 2
            cands += [(p, 1 + 2 * k, tier, it) for it in _group_items(grp, v)]
            cands += [(p, 2 + 2 * k, 3, it) for it in _take_items(grp, said) if not _RAW_KEY.search(it.body)]

    def words(items) -> int:
        return sum(word_count(c[3].text) for c in items)

    chosen = [c for c in cands if c[2] <= 1]
    while words(chosen) > budget:  # the longest required sentence one step shorter
        cut = sorted((c for c in chosen if c[2] == 1), key=lambda c: -word_count(c[3].text))
        if not any(c[3].shorter() for c in cut[:1]) and not any(c[3].shorter() for c in cut[1:]):
            break
    if words(chosen) > budget:  # still too long: a claim not reproduced is said to fail, in fewer words
        for c in chosen:
            if c[3].verdict == "not_reproduced":
                c[3].head = f"{c[3].ids[0]} fails"
    if words(chosen) > budget:  # more required findings than page 1 holds: the causes go to Appendix A
        pointer = (papers[-1], 10 ** 6, 1, _Said([], "Appendix A gives each cause"))
        # what differs or is suspect is said by the verdict's own words; a choice and a cause last
        keep_last = ("not_reproduced", "depends_on_choice")
        for c in sorted((c for c in chosen if c[2] == 1 and c[3].body),
                        key=lambda c: (c[3].verdict in keep_last, -word_count(c[3].body))):
            if words(chosen) + word_count(pointer[3].text) <= budget:
                break
            c[3].body = ""
        chosen.append(pointer)
    for c in cands:
        if c[2] >= 2 and words(chosen) + word_count(c[3].text) <= budget:
            chosen.append(c)
    chosen.sort(key=lambda c: (papers.index(c[0]), c[1]))
    return " ".join(c[3].text for c in chosen)


def abstract_gaps(df: pd.DataFrame, abstract: str) -> list[str]:
    """What page 1 owes the reader and ``abstract`` (plain text or LaTeX) does not say: for each
    claim that depends on a choice, a sentence naming the claim and its choice (the first words
    of ``named``); for each claim not reproduced, a sentence naming the claim and quoting its
    cause (a number of the cause, or its first words when it has none). ``[]`` when every one is
    said (issue 55 item 5)."""
    from opnav.report.scorer import numbers_in

    text = " ".join(re.sub(r"\\[A-Za-z]+\{?\}?|[{}$]", " ", abstract).split())
    said = wording.sentences(text)
    out = []
    for r in (dict(r) for _, r in df.iterrows()):
        cid, v = r["claim_id"], r["verdict"]
        mine = [x for x in said if re.search(rf"\b{re.escape(cid)}\b(?!\d)", x)]
        if v == "depends_on_choice":
            key = " ".join(_TRAILING_SCOPE.sub("", cell_text(r, "named")).split()[:3])
            if not any(key in x for x in mine):
                out.append(f"{cid}: depends on a choice, which page 1 does not name ({key!r})")
        elif v == "not_reproduced":
            cause = claim_cause(r)
            nums = [n.lstrip("+") for n in numbers_in(cause)]
            bare = [re.sub(r"\b[A-Z]-C\d+\b", "", x) for x in mine]   # a claim id's digits are not a number
            ok = (any(re.search(rf"(?<![0-9.]){re.escape(n)}(?![0-9])", x) for n in nums for x in bare) if nums else
                  any(" ".join(cause.split()[:4]) in x for x in bare))
            if not ok:
                out.append(f"{cid}: not reproduced, and page 1 gives no cause ({cause[:60]!r})")
    return out


def page_one_abstract_tex(df: pd.DataFrame, sample_sentence: str = "") -> str:
    """The generated part of page 1's abstract as LaTeX: the findings and, for a quick-profile
    table, the sentence that its sample is too small for verdicts (first)."""
    text = abstract_findings(df, ABSTRACT_MAX_WORDS - ABSTRACT_FRAMING_WORDS - word_count(sample_sentence))
    return prose_tex(" ".join(t for t in (sample_sentence, text) if t)) + "\n"


def sample_sentence_of(df: pd.DataFrame) -> str:
    """The claims table's own sentence on its sample (quick profile: too small for verdicts);
    empty for a full build or a table without the ``sample`` column."""
    if "sample" not in df.columns:
        return ""
    from opnav.report.claims import sample_sentence

    return sample_sentence(df)
