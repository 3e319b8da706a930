"""One strict reading of a user's config file (YAML or JSON), shared by ``opnav --config``
and the workflow (the Snakefile re-reads every ``--configfile`` Snakemake was given).

Why not a plain ``yaml.safe_load``
----------------------------------
Snakemake reads a config file with PyYAML (``yte.process_yaml``: JSON first, then YAML
1.1 with PyYAML's resolver), and the workflow validates *that* reading. A YAML 1.1
reader turns ``020200704`` into the octal 4260292, ``1:30`` into 90, ``on`` / ``no`` into
booleans (also as keys), ``1e-6`` into the *string* '1e-6' and ``2020-07-04`` into a date,
keeps the last of two equal keys silently, expands ``<<`` merge keys and aliases, and runs
embedded Python when the file says ``__use_yte__: true``. A YAML 1.2 reader (and a human)
reads most of these differently. So the rule here: **a file is accepted only where every
reading agrees**; everything else is refused in one line naming the file, the line and
the dotted key, with the spelling to use instead:

* a plain scalar that PyYAML (YAML 1.1) and the YAML 1.2 core schema resolve to different
  types or values (yes/no/on/off, leading-zero and underscore numbers, sexagesimal
  ``1:30``, ``0o`` / ``0b`` forms, exponents without a dot or sign such as ``1e-6``, dates,
  PyYAML's ``=`` value key);
* a key given twice in one mapping; a key that is not a string (``1:``, ``on:``, ``null:``,
  a list or mapping as key);
* anchors, aliases and ``<<`` merge keys (write the values out: a config is read by people);
* explicit tags other than ``!!str`` (``!!python/...``, ``!custom``);
* a ``__use_yte__`` key (Snakemake would evaluate the file as a template);
* a string holding an unexpanded environment variable (``$HOME``, ``${USER}``: neither
  reader expands it, so a folder literally named ``$HOME`` would be made) or a control
  character (newline, tab, escape, NUL, DEL, C1) or a Unicode format character (bidi
  overrides, zero-width);
* more than one document, an empty document, a top level that is not a mapping, nesting
  deeper than :data:`MAX_DEPTH`, a file over :data:`MAX_BYTES`, bytes that are not UTF-8.

The reader walks PyYAML's *event* stream (libyaml's parser where installed): it sees
anchors, tags and scalar styles, which a constructed document has lost, and needs no
recursion. Values it accepts are constructed exactly as PyYAML's safe constructor does
(the workflow's reading), so both paths see the same numbers.

Why not a YAML library's strict mode
------------------------------------
Measured for issue 56/57 (ruamel.yaml 0.19.1 in its YAML 1.2 mode, duplicate keys refused
by default; strictyaml 1.7.3): neither does this module's job, which is to refuse where
*two* readings differ (Snakemake's YAML 1.1, which the workflow validates, and YAML 1.2):

* ruamel.yaml gives the 1.2 reading only: ``020200704`` is 20200704 there and 4260292 in
  Snakemake's, ``1e-3`` a number there and a string in Snakemake's, ``yes`` a string there
  and a boolean in Snakemake's, each accepted silently; it accepts ``1:`` as an int key,
  anchors, aliases and ``<<`` merges, its round-trip mode drops an unknown ``!!python``
  tag's meaning silently, 5,000-deep nesting ends in RecursionError, and it read
  config/config.yaml in 146 ms (pure safe loader; 333 ms round-trip) against 35 ms here;
* strictyaml refuses flow style (``landing: {mc: {n_runs: 10}}``, which every config of the
  project and its docs use), and without a second schema beside the JSON schema returns
  every scalar as a string (``1: 2`` read as ``{'1': '2'}``).

Duplicate keys are the one rule either would take over; the comparison of the two
readings, the event-level refusals (anchors, tags, depth) and the messages stay here.

Use: :func:`read_config_text` (a file's text) and :func:`read_value` (one ``--set`` value).
Errors are :class:`opnav.core.errors.ConfigError`, one line each.
"""

from __future__ import annotations

import json
import re
import unicodedata
from pathlib import Path
from typing import Any

import yaml

from opnav.core.errors import ConfigError

__all__ = ["read_config_file", "read_config_text", "read_value", "MAX_BYTES", "MAX_DEPTH"]

#: Largest config file read (bytes): every config of the project is under 20 kB.
MAX_BYTES = 1_000_000
#: Deepest nesting of mappings and lists (the project's configs nest 5 deep).
MAX_DEPTH = 32

_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_RESOLVER = yaml.resolver.Resolver()
_CONSTRUCTOR = yaml.constructor.SafeConstructor()

_T = "tag:yaml.org,2002:"
# YAML 1.2 core schema (https://yaml.org/spec/1.2.2/#1032-tag-resolution)
_CORE = [
    ("null", re.compile(r"(?:null|Null|NULL|~|)\Z")),
    ("bool", re.compile(r"(?:true|True|TRUE|false|False|FALSE)\Z")),
    ("int", re.compile(r"[-+]?[0-9]+\Z")),
    ("int8", re.compile(r"0o[0-7]+\Z")),
    ("int16", re.compile(r"0x[0-9a-fA-F]+\Z")),
    ("float", re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?\Z")),
    ("inf", re.compile(r"[-+]?\.(?:inf|Inf|INF)\Z")),
    ("nan", re.compile(r"\.(?:nan|NaN|NAN)\Z")),
]
_ENV = re.compile(r"\$(?:\{[^}]*\}|[A-Za-z_][A-Za-z0-9_]*)")


def _core_value(text: str):
    """The YAML 1.2 core schema's value of a plain scalar (a str where none matches)."""
    for kind, rx in _CORE:
        if rx.match(text):
            if kind == "null":
                return None
            if kind == "bool":
                return text.lower() == "true"
            if kind == "int":
                return int(text, 10)
            if kind == "int8":
                return int(text[2:], 8)
            if kind == "int16":
                return int(text[2:], 16)
            return float(text.replace("Inf", "inf").replace("INF", "inf").replace("NaN", "nan")
                         .replace("NAN", "nan").replace(".inf", "inf").replace(".nan", "nan"))
    return text


def _pyyaml_value(text: str):
    """PyYAML's (YAML 1.1, the workflow's) value of a plain scalar, and its tag."""
    tag = _RESOLVER.resolve(yaml.ScalarNode, text, (True, False))
    if tag in (_T + "merge", _T + "value"):
        return tag, None
    return tag, _CONSTRUCTOR.construct_object(yaml.ScalarNode(tag, text))


def _same(a, b) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, float) and a != a:
        return b != b
    return a == b


def _hint(text: str, tag: str, v11, v12) -> str:
    """Why a plain scalar is ambiguous and what to write instead."""
    low = text.lower()
    if tag == _T + "bool":
        return (f"{text!r} is the boolean {v11} in YAML 1.1 (Snakemake's reader) but the string {text!r} in "
                f"YAML 1.2; write {str(v11).lower()} for the boolean or quote it ('{text}') for the word")
    if tag == _T + "timestamp":
        return f"{text!r} reads as a date in YAML 1.1; quote it ('{text}') if it is text"
    if ":" in text and tag in (_T + "int", _T + "float"):
        return (f"{text} is the base-60 number {v11} in YAML 1.1 but the string {text!r} in YAML 1.2; "
                f"write {v11} or quote it")
    if "_" in text:
        return f"{text} is {v11!r} in YAML 1.1 but the string {text!r} in YAML 1.2; write it without '_'"
    if re.match(r"[-+]?0[0-9]", text) and isinstance(v12, int):
        return (f"{text} has a leading zero: YAML 1.1 reads {v11!r}"
                f"{' (octal)' if isinstance(v11, int) else ''}, YAML 1.2 reads {v12}; write {v12}, "
                f"or quote it ('{text}') if it is text")
    if low.startswith(("0b", "+0b", "-0b", "0o")):
        return f"{text} is {v11!r} in YAML 1.1 and {v12!r} in YAML 1.2; write it in decimal"
    if isinstance(v12, float) and isinstance(v11, str):
        m, _, e = re.split(r"([eE])", text, maxsplit=1) if re.search("[eE]", text) else (text, "", "")
        m = m if "." in m else m + ".0"
        e = e if not e or e[0] in "+-" else "+" + e
        fixed = f"{m}e{e}" if e else m
        return (f"{text} is the string {text!r} in YAML 1.1 (Snakemake's reader: an exponent needs a dot and "
                f"a sign) but the number {v12!r} in YAML 1.2; write {fixed}")
    return f"{text!r} reads as {v11!r} in YAML 1.1 but {v12!r} in YAML 1.2; quote it or write it plainly"


def _string_problem(s: str, is_key: bool) -> str | None:
    """A control or format character, or an unexpanded environment variable, in ``s``."""
    for i, ch in enumerate(s):
        cat = unicodedata.category(ch)
        if cat == "Cc" or cat == "Cf" or cat in ("Zl", "Zp"):
            name = {"\n": "a newline", "\t": "a tab", "\r": "a carriage return", "\0": "a NUL byte",
                    "\x1b": "an escape"}.get(ch, f"the control character U+{ord(ch):04X}")
            if cat == "Cf":
                name = f"the invisible format character U+{ord(ch):04X} ({unicodedata.name(ch, '?')})"
            return f"{'key' if is_key else 'value'} {s[:40]!r} holds {name} (at character {i + 1})"
    m = _ENV.search(s)
    if m and not is_key:
        return (f"{s[:60]!r} holds {m.group(0)}, which no reader expands (a folder literally named "
                f"{m.group(0)!r} would be made); write the value itself")
    return None


def dotted(path) -> str:
    """A key path as the user writes it: ``("a", "b", 0)`` -> ``a.b[0]``."""
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


class _Where:
    def __init__(self, source: str):
        self.source = source

    def fail(self, mark, path, msg: str):
        line = f", line {mark.line + 1}" if mark is not None else ""
        key = f": key '{dotted(path)}'" if path else ""
        raise ConfigError(f"{self.source}{line}{key}: {msg}")


def _walk_events(events, where: _Where, *, top_mapping: bool = True):
    """The one document of the YAML event stream, constructed under the rules above."""
    ev = next(events)                                    # StreamStart
    ev = next(events)
    if isinstance(ev, yaml.StreamEndEvent):
        return _EMPTY
    doc_mark = ev.start_mark                             # DocumentStart
    root = _node(events, where, (), 0)
    end = next(events)                                   # DocumentEnd
    nxt = next(events)
    if not isinstance(nxt, yaml.StreamEndEvent):
        where.fail(nxt.start_mark, (), "more than one YAML document ('---'); give one mapping")
    del doc_mark, end
    return root


_EMPTY = object()


def _node(events, where: _Where, path: tuple, depth: int):
    ev = next(events)
    return _value(ev, events, where, path, depth)


def _value(ev, events, where: _Where, path: tuple, depth: int):
    if depth > MAX_DEPTH:
        where.fail(ev.start_mark, path, f"nested more than {MAX_DEPTH} levels deep")
    if isinstance(ev, yaml.AliasEvent):
        where.fail(ev.start_mark, path, f"an alias (*{ev.anchor}): write the value out (anchors, aliases "
                                        "and '<<' merge keys are refused)")
    if getattr(ev, "anchor", None):
        where.fail(ev.start_mark, path, f"an anchor (&{ev.anchor}): write the values out (anchors, aliases "
                                        "and '<<' merge keys are refused)")
    tag = getattr(ev, "tag", None)
    if tag not in (None, "!", _T + "str", _T + "map", _T + "seq"):
        where.fail(ev.start_mark, path, f"the tag {tag!r} is refused (plain values only)")
    if isinstance(ev, yaml.ScalarEvent):
        return _scalar(ev, where, path, is_key=False)
    if isinstance(ev, yaml.SequenceStartEvent):
        out = []
        while True:
            nxt = next(events)
            if isinstance(nxt, yaml.SequenceEndEvent):
                return out
            out.append(_value(nxt, events, where, (*path, len(out)), depth + 1))
    if isinstance(ev, yaml.MappingStartEvent):
        out: dict = {}
        lines: dict = {}
        while True:
            kev = next(events)
            if isinstance(kev, yaml.MappingEndEvent):
                return out
            if not isinstance(kev, yaml.ScalarEvent):
                what = "an alias" if isinstance(kev, yaml.AliasEvent) else "a list or mapping"
                where.fail(kev.start_mark, path, f"{what} used as a key; keys are names")
            if getattr(kev, "anchor", None):
                where.fail(kev.start_mark, path, f"an anchor (&{kev.anchor}) on a key; write the values out")
            key = _key(kev, where, path)
            if key in out:
                where.fail(kev.start_mark, (*path, key), f"given twice (first on line {lines[key] + 1}); "
                                                         "YAML would keep the last silently")
            lines[key] = kev.start_mark.line
            out[key] = _node(events, where, (*path, key), depth + 1)
    where.fail(ev.start_mark, path, f"unexpected YAML event {type(ev).__name__}")  # pragma: no cover


def _key(ev, where: _Where, path: tuple) -> str:
    text = ev.value
    if ev.tag not in (None, "!", _T + "str"):
        where.fail(ev.start_mark, path, f"key {text!r} with the tag {ev.tag!r} is refused")
    if not ev.style and ev.tag is None:                  # plain: resolved
        if text == "<<":
            where.fail(ev.start_mark, path, "a '<<' merge key: write the keys out (anchors, aliases and merge "
                                            "keys are refused)")
        tag, v11 = _pyyaml_value(text)
        if not isinstance(v11, str):
            shown = "null" if v11 is None else f"the {type(v11).__name__} {v11!r}"
            where.fail(ev.start_mark, (*path, text), f"not a name: YAML reads this key as {shown}; "
                                                     f"quote it ('{text}') if it is meant")
    if text == "__use_yte__":
        where.fail(ev.start_mark, (*path, text), "YTE templates are refused (Snakemake would run the file's "
                                                 "embedded Python); write plain values")
    bad = _string_problem(text, is_key=True)
    if bad:
        where.fail(ev.start_mark, path, bad)
    if not text:
        where.fail(ev.start_mark, path, "an empty key")
    return text


def _scalar(ev, where: _Where, path: tuple, *, is_key: bool):
    text = ev.value
    if ev.style or ev.tag is not None:                   # quoted, block or !!str: a string
        value = text
    else:
        tag, v11 = _pyyaml_value(text)
        if tag in (_T + "merge", _T + "value"):
            where.fail(ev.start_mark, path, f"{text!r} is a YAML 1.1 special key; quote it")
        v12 = _core_value(text)
        if not _same(v11, v12):
            where.fail(ev.start_mark, path, _hint(text, tag, v11, v12))
        value = v11
    if isinstance(value, str):
        bad = _string_problem(value, is_key)
        if bad:
            where.fail(ev.start_mark, path, bad)
    return value


def _json_walk(value, where: _Where, path: tuple = (), depth: int = 0):
    if depth > MAX_DEPTH:
        where.fail(None, path, f"nested more than {MAX_DEPTH} levels deep")
    if isinstance(value, dict):
        for k, v in value.items():
            if k == "__use_yte__":
                where.fail(None, (*path, k), "YTE templates are refused; write plain values")
            bad = _string_problem(k, True) or (None if k else "an empty key")
            if bad:
                where.fail(None, path, bad)
            _json_walk(v, where, (*path, k), depth + 1)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _json_walk(v, where, (*path, i), depth + 1)
    elif isinstance(value, str):
        bad = _string_problem(value, False)
        if bad:
            where.fail(None, path, bad)


def _json_pairs(where: _Where):
    def hook(pairs):
        out = {}
        for k, v in pairs:
            if k in out:
                where.fail(None, (k,), "given twice in one JSON object (the last would be kept silently)")
            out[k] = v
        return out
    return hook


def read_config_text(text: str, source: str) -> dict:
    """The config mapping in ``text`` (a file's contents), read as Snakemake reads it (JSON
    if it parses as JSON, else YAML) under the rules of this module; ``source`` names it in
    errors (e.g. ``config file quick.yaml``)."""
    where = _Where(source)
    if "\0" in text:
        line = text[:text.index("\0")].count("\n") + 1
        raise ConfigError(f"{source}, line {line}: a NUL byte (binary data); a YAML config is expected")
    stripped = text.lstrip()
    if stripped.startswith("{"):
        try:
            data = json.loads(text, object_pairs_hook=_json_pairs(where))
        except ValueError:
            data = _EMPTY          # not JSON, or a key twice: read as YAML below (which names the line)
        if data is not _EMPTY:
            _json_walk(data, where)
            return _top(data, where, None)
    events = yaml.parse(text, Loader=_LOADER)
    try:
        data = _walk_events(iter(events), where)
        mark = None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        at = f", line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        what = " ".join(filter(None, [getattr(exc, "context", None), getattr(exc, "problem", None)])) \
            or str(exc).splitlines()[0]
        lines = text.splitlines()
        if mark and mark.line < len(lines) and "\t" in lines[mark.line][:mark.column + 1]:
            what += " (a tab: YAML indents with spaces)"
        raise ConfigError(f"{source}{at}: not valid YAML: {what}") from None
    return _top(data, where, mark)


def _top(data, where: _Where, mark) -> dict:
    if data is _EMPTY or data is None:
        raise ConfigError(f"{where.source}: empty (no config keys); give a mapping such as "
                          "'landing: {mc: {n_runs: 10}}'")
    if not isinstance(data, dict):
        kind = "a list" if isinstance(data, list) else f"the scalar {str(data)[:40]!r}"
        raise ConfigError(f"{where.source}, line 1: the top level must be a mapping of config keys "
                          f"(approach, landing, ...), not {kind}")
    return data


def read_config_file(path: str | Path) -> dict:
    """The config mapping in the user's file ``path`` (:func:`read_config_text`), or
    :class:`ConfigError` naming the file: missing, not a regular file (a FIFO or a device is
    never opened: reading one would wait, or never end), unreadable, over :data:`MAX_BYTES`
    (checked before reading, and at most that many bytes are read), not UTF-8 text, or any
    refusal of this module."""
    import stat

    f = Path(path)
    source = f"config file {f}"
    try:
        st = f.stat()
    except FileNotFoundError:
        raise ConfigError(f"{source}: not found") from None
    except OSError as exc:
        raise ConfigError(f"{source}: cannot be read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode)
                else "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
                else "a socket" if stat.S_ISSOCK(st.st_mode) else "not a file")
        raise ConfigError(f"{source}: {kind}, not a regular file; give a YAML file")
    if st.st_size > MAX_BYTES:
        raise ConfigError(f"{source}: {st.st_size} bytes, over the {MAX_BYTES} a config may have")
    try:
        with open(f, "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{source}: cannot be read ({exc.strerror or exc})") from None
    if len(raw) > MAX_BYTES:                        # grew after the size check
        raise ConfigError(f"{source}: over the {MAX_BYTES} bytes a config may have")
    for bom, name in ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                      (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16")):
        if raw.startswith(bom):
            raise ConfigError(f"{source}, line 1: {name} text (byte-order mark); save it as UTF-8")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ConfigError(f"{source}, line {line}: not UTF-8 text (byte 0x{raw[exc.start]:02x}); save it as "
                          "UTF-8 (a YAML config is expected)") from None
    return read_config_text(text, source)


def read_value(text: str, source: str) -> Any:
    """One value given on the command line (``--set KEY=VALUE``), under the same rules;
    ``source`` names it (``--set landing.mc.n_runs``). Empty text and null are refused."""
    if not text.strip():
        raise ConfigError(f"{source}: no value after '=' (give one, e.g. {source.split()[-1]}=10)")
    where = _Where(source)
    try:
        value = _walk_events(iter(yaml.parse(text, Loader=_LOADER)), where)
    except yaml.YAMLError as exc:
        what = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{source}: the value {text!r} is not valid YAML: {what}") from None
    except ConfigError as exc:                          # no line numbers for a one-line value
        raise ConfigError(re.sub(r", line 1(?=: )", "", str(exc))) from None
    if value is None or value is _EMPTY:
        raise ConfigError(f"{source}: the value {text!r} is null; give a value (a config key cannot be unset)")
    return value
