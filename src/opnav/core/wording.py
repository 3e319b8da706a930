"""Numbers, counts and sentences in generated prose: one home (issue 55 item 4).

Every generator of reader-facing text says a number, a count or a change through these helpers,
so no text reads "1 maps", "-0 % lower" or "a ratio of 1" for 0.9999:

* :func:`num`: a number at ``nd`` significant digits; a ratio that would round onto 1 and is
  not (0.9999) keeps the digits that show the difference; never "-0".
* :func:`count`: "1 map", "3 maps", "no map" on request; the noun agrees with the number.
* :func:`change`: a relative change in words: "12 % lower", "3 % higher", "unchanged" for a
  change that rounds to zero.
* :func:`sentences`, :func:`word_count`: how the manuscript's checks cut text into sentences
  and count their words (:data:`MAX_SENTENCE_WORDS`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from typing import Any

#: the longest sentence generated text may hold, in words (issue 55 item 4)
MAX_SENTENCE_WORDS = 40

#: nouns whose plural is not noun + "s"
_PLURALS = {"run": "runs", "case": "cases", "seed": "seeds", "star": "stars", "map": "maps",
            "image": "images", "call": "calls", "landmark": "landmarks", "sample": "samples",
            "study": "studies", "bootstrap": "bootstraps", "choice": "choices", "claim": "claims",
            "ratio": "ratios", "variant": "variants", "iteration": "iterations", "axis": "axes",
            "camera": "cameras", "replay": "replays", "job": "jobs", "row": "rows"}


def _missing(x: Any) -> bool:
    if x is None:
        return True
    try:
        return not math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def num(x: Any, nd: int = 3, missing: str = "n/a") -> str:
    """``x`` at ``nd`` significant digits (integers of more digits in full); a value that would
    print as 1 or -1 and is not (a ratio of 0.9999 at 3 digits) gets the digits that tell it
    from 1 (up to 6: "0.9999"); "-0" prints as "0".
    Missing or non-finite values print as ``missing``; a non-number prints as it is."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return missing if x is None else str(x)
    if not math.isfinite(v):
        return missing
    if v == 0:
        return "0"

    def fmt(d: int) -> str:
        s = f"{v:.{d}g}" if abs(v) < 10 ** d else f"{v:.0f}"
        if "e" in s and abs(v) >= 1:  # 1.23e+04 at 3 digits: the integer
            s = f"{v:.0f}"
        return s

    s = fmt(nd)
    d = nd
    while d < 6 and "e" not in s and float(s) != v and abs(float(s)) == 1.0:
        d += 1
        s = fmt(d)
    if re.fullmatch(r"-0(\.0*)?", s):
        s = "0"
    return s


def plural(n: float, noun: str, plural_form: str | None = None) -> str:
    """``noun`` in the number ``n`` asks for (singular for exactly 1)."""
    if n == 1:
        return noun
    return plural_form or _PLURALS.get(noun) or (noun + "es" if noun.endswith(("s", "x", "ch", "sh")) else noun + "s")


def count(n: Any, noun: str, plural_form: str | None = None, zero: str | None = None) -> str:
    """'1 map', '3 maps', '2.5 maps'; ``zero`` (e.g. 'no map') for 0 where given; a missing
    count reads 'n/a maps'."""
    if _missing(n):
        return f"n/a {plural(2, noun, plural_form)}"
    v = float(n)
    if v == 0 and zero is not None:
        return zero
    text = f"{int(v):,}" if v == int(v) else num(v)
    return f"{text} {plural(v, noun, plural_form)}"


def change(pct: float, lower: str = "lower", higher: str = "higher", nd: int = 0,
           unchanged: str = "unchanged") -> str:
    """A relative change in percent as words: ``pct`` > 0 is a fall ('12 % lower'), < 0 a
    rise ('3 % higher'); one that rounds to zero at ``nd`` decimals is ``unchanged``."""
    if _missing(pct):
        return "n/a"
    r = round(float(pct), nd)
    if r == 0:
        return unchanged
    return f"{abs(r):.{nd}f} % {lower if r > 0 else higher}"


def join(items: Iterable[str], none: str = "none") -> str:
    """'a', 'a and b', 'a, b and c'."""
    items = [i for i in items if i]
    if not items:
        return none
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


# ------------------------------------------------------------ sentences
#: abbreviations a full stop does not end a sentence after
_ABBREV = re.compile(r"(?:\b(?:e\.g|i\.e|vs|cf|Fig|Figs|Eq|Eqs|eq|eqs|Sec|sec|Secs|Ref|No|Tab|approx|al|etc|resp)"
                     r"|\b[A-Z])\.$")


def sentences(text: str) -> list[str]:
    """``text`` cut into sentences: at a full stop, question or exclamation mark followed by
    white space and a capital letter, digit-free opening or bracket, not after an abbreviation
    (e.g., vs., Fig., a single capital); paragraph breaks (blank lines) end a sentence too."""
    out: list[str] = []
    for para in re.split(r"\n\s*\n", text):
        para = " ".join(para.split())
        if not para:
            continue
        buf = ""
        for part in re.split(r"(?<=[.!?])\s+(?=[A-Z(\[\"'*])", para):
            buf = f"{buf} {part}".strip()
            if _ABBREV.search(buf):
                continue
            out.append(buf)
            buf = ""
        if buf:
            out.append(buf)
    return out


def word_count(text: str) -> int:
    """Words of a plain text: white-space separated tokens holding a letter or a digit."""
    return sum(1 for w in text.split() if re.search(r"[A-Za-z0-9]", w))


def long_sentences(text: str, max_words: int = MAX_SENTENCE_WORDS) -> list[str]:
    """The sentences of ``text`` longer than ``max_words``."""
    return [s for s in sentences(text) if word_count(s) > max_words]


_PARENS = re.compile(r" \((?:[^()]|\([^()]*\))*\)")


def _top_level(text: str, sep: str) -> list[int]:
    """Where ``sep`` occurs in ``text`` outside brackets."""
    out, depth = [], 0
    for i, c in enumerate(text):
        if c in "([":
            depth += 1
        elif c in ")]":
            depth = max(0, depth - 1)
        elif depth == 0 and text.startswith(sep, i):
            out.append(i)
    return out


def shorter(text: str, min_words: int = 6) -> str | None:
    """``text`` one step shorter the way a reader loses least, or ``None`` when no step is left.
    The evidence's numbers go last: first the last parenthesis without a number (an identifier's
    digits aside: '(T1-13)', '(interior)'); then a tail without a number, after the first '; ' or
    the last ', '; then the last parenthesis; then any tail. Separators inside brackets do not
    count, and a clause is cut only while ``min_words`` words remain."""
    text = " ".join(text.split())

    def numberless(t: str) -> bool:
        return not re.search(r"\d", re.sub(r"\b[A-Z]+\d*-\d+\b", "", t))

    parens = list(_PARENS.finditer(text))
    plain = [m for m in parens if numberless(m.group(0))]
    if plain:
        return text[:plain[-1].start()] + text[plain[-1].end():]
    tails = [i for i in _top_level(text, "; ")[:1] + _top_level(text, ", ")[-1:] if word_count(text[:i]) >= min_words]
    for i in tails:
        if numberless(text[i:]):
            return text[:i]
        last = parens[-1] if parens else None
        if last is not None and last.end() == len(text) and last.start() > i and numberless(text[i:last.start()]):
            return text[:i] + last.group(0)   # the clause goes, its closing numbers stay
    if parens:
        return text[:parens[-1].start()] + text[parens[-1].end():]
    return text[:tails[0]] if tails else None


def shorten(text: str, max_words: int) -> str:
    """``text`` cut to at most ``max_words`` words by :func:`shorter`'s steps, then, if still
    too long, to its first ``max_words`` words."""
    text = " ".join(text.split())
    while word_count(text) > max_words:
        nxt = shorter(text)
        if nxt is None:
            return " ".join(text.split()[:max_words])
        text = nxt
    return text


# ------------------------------------------------------------ a plan key in words
#: unit suffixes of the plan's margin and setting names (target_arcsec, threshold_m)
_KEY_UNITS = {"arcsec": "arcsec", "samples": "samples", "km": "km", "m": "m", "s": "s", "pct": "%", "deg": "deg",
              "us": "us", "px": "px", "mps": "m/s"}
_KEY_WORDS = {"rel": "relative", "tol": "tolerance", "max": "maximum", "min": "minimum", "diff": "difference"}


def key_words(name: str) -> tuple[str, str]:
    """A plan key (a margin's or setting's snake_case name) as words and its unit:
    'target_arcsec' -> ('target', 'arcsec'), 'margin_rel' -> ('relative margin', ''),
    'rel_tol' -> ('relative tolerance', ''), 'min_difference_s' -> ('minimum difference', 's')."""
    parts = [p for p in str(name).split("_") if p]
    unit = ""
    if len(parts) > 2 and parts[-1] == "s" and parts[-2] in ("deg", "m", "km", "rad"):  # a rate: deg_s -> deg/s
        unit, parts = f"{parts[-2]}/s", parts[:-2]
    elif len(parts) > 1 and parts[-1] in _KEY_UNITS:
        unit, parts = _KEY_UNITS[parts[-1]], parts[:-1]
    rel = "rel" in parts
    words = [_KEY_WORDS.get(p, p) for p in parts if p != "rel"]
    return " ".join((["relative"] if rel else []) + words), unit


def key_value(name: str, value: str) -> str:
    """'a target of 20.6 arcsec', 'a relative margin of 1.38' (``value`` already formatted)."""
    words, unit = key_words(name)
    art = "an" if words[:1].lower() in "aeio" and words else "a"
    return f"{art} {words} of {value}" + (f" {unit}" if unit else "")
