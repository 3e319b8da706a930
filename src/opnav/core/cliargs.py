"""What every ``opnav`` subcommand shares: argument types, the one-line error parser, the
config of a run (defaults, ``--config`` overlays, ``--set`` keys, the subcommand's flags)
checked once, strict JSON output.

It sits in the core so the paper packages' subcommands (``opnav.approach.cli``,
``opnav.landing.cli``) import it, never the top-level :mod:`opnav.cli`. The checks of a
config need both papers' physics (:func:`opnav.preflight.problems`, above the papers): the
top-level command hands them to each subcommand as a :class:`RunConfig`, so nothing here
imports upward.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import re
import sys
from typing import Any, Callable

from opnav.core.errors import ConfigError

__all__ = ["EXIT_USER", "EXIT_NUMERICAL", "Parser", "finite_float", "integer", "print_json", "parse_set",
           "set_key", "RunConfig", "add_config_arguments"]

#: Exit code of every user error (argparse's own code for a bad flag).
EXIT_USER = 2
#: Exit code of a numerical failure on inputs that passed every check.
EXIT_NUMERICAL = 3


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) naming the flag: an
    extra value after a flag of fixed arity (``--bias 1 2 3 4``) is reported against that
    flag, not as an unrecognised argument; an unknown flag is named as one."""

    def parse_known_args(self, args=None, namespace=None):  # noqa: D102
        self._argv = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(args, namespace)

    def _arity(self) -> dict[str, int]:
        """``{option string: fixed number of values}`` of this parser and its subparsers."""
        out: dict[str, int] = {}
        stack = [self]
        while stack:
            p = stack.pop()
            for a in p._actions:
                if isinstance(a, argparse._SubParsersAction):
                    stack += list(a.choices.values())
                elif a.option_strings:
                    single = a.nargs is None and isinstance(a, (argparse._StoreAction, argparse._AppendAction))
                    n = a.nargs if isinstance(a.nargs, int) else (1 if single else None)
                    if n:
                        out.update(dict.fromkeys(a.option_strings, n))
        return out

    def error(self, message: str):  # noqa: D102
        m = re.match(r"unrecognized arguments: (\S+)", message)
        argv = getattr(self, "_argv", [])
        if m and m.group(1) in argv:
            word = m.group(1)
            i = argv.index(word)
            if _is_flag(word):                       # an unknown flag, whatever stands before it
                message = f"unrecognized flag {word.split('=')[0]}"
            else:                                    # an extra value: the flag before it takes fewer
                j = i - 1
                while j >= 0 and not _is_flag(argv[j]):
                    j -= 1
                arity = self._arity()
                if j >= 0 and argv[j] in arity:
                    end = next((k for k in range(i, len(argv)) if _is_flag(argv[k])), len(argv))
                    given = end - j - 1
                    message = (f"argument {argv[j]}: takes {arity[argv[j]]} value(s), got {given} "
                               f"({' '.join(argv[j + 1:j + 1 + given])})")
        self.exit(EXIT_USER, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _is_flag(word: str) -> bool:
    return word.startswith("-") and not _is_number(word)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def finite_float(text: str) -> float:
    """argparse type: a finite number (``nan``, ``inf`` refused)."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return x


def integer(text: str) -> int:
    """argparse type: an integer written as one (``3.0`` refused, as in the config)."""
    try:
        return int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None


def print_json(obj: Any, **kw) -> None:
    """Print ``obj`` as strict JSON (NaN and infinities written as ``null``)."""
    from opnav.core.tables import json_ready

    print(json.dumps(json_ready(obj), allow_nan=False, **kw))


def set_key(config: dict, dotted: str, value: Any) -> None:
    """``config[a][b][c] = value`` for ``dotted`` = ``a.b.c`` (maps made where missing)."""
    *parents, last = dotted.split(".")
    node = config
    for p in parents:
        node = node.setdefault(p, {})
    node[last] = value


def add_config_arguments(p: argparse.ArgumentParser) -> None:
    """``--config FILE`` (overlay) and ``--set KEY.PATH=VALUE`` on a subcommand."""
    g = p.add_argument_group("configuration (applied in this order, then validated once)")
    g.add_argument("--config", dest="overlays", action="append", default=[], metavar="FILE",
                   help="config overlay merged on the defaults (config/config.yaml), after the "
                        "top-level `opnav --config`; repeatable")
    g.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY.PATH=VALUE",
                   help="set one config key, the value parsed as YAML (e.g. --set landing.camera.fov_deg=75, "
                        "--set approach.camera.sigma3_px=[0.2,0.2,0.4]); repeatable; the subcommand's own "
                        "flags are applied after it. A map is set key by key: a map value must hold every "
                        "key the map has")


#: A --set key: dotted names, each as the schema's names are (scenario names hold "-").
_SET_KEY_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_-]*(\.[A-Za-z0-9_][A-Za-z0-9_-]*)*")


def parse_set(text: str) -> tuple[str, Any, str]:
    """``KEY.PATH=VALUE`` -> (dotted key, value, the value's text): the value read by the
    config files' strict reader (:func:`opnav.core.yamlfile.read_value`: YAML 1.1 traps,
    duplicate keys, control characters refused); an empty or null value, or one holding a
    null (``-`` is a YAML list of one null), is refused (a config key cannot be unset).
    Raises :class:`ConfigError` naming the flag and key."""
    from opnav.core.yamlfile import read_value

    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not _SET_KEY_RE.fullmatch(key):
        raise ConfigError(f"--set {text!r}: expected KEY.PATH=VALUE, e.g. --set landing.camera.fov_deg=75")
    value = read_value(raw, f"--set {key}")
    if _holds_null(value):
        raise ConfigError(f"--set {key}: the value {raw.strip()!r} reads as {json.dumps(value)}, which holds null "
                          "(in YAML '- ' starts a list item and '~' is null); give a value, quoted if it is text")
    return key, value, raw.strip()


def _holds_null(value: Any) -> bool:
    if isinstance(value, dict):
        return any(_holds_null(v) for v in value.values())
    if isinstance(value, list):
        return any(_holds_null(v) for v in value)
    return value is None


_KEY_RE = re.compile(r"config key '([^'\[]+)")


def _shown(value: Any) -> str:
    """A flag's value as the user typed it (lists space-separated, as nargs flags take them)."""
    if isinstance(value, (list, tuple)):
        return " ".join(_shown(v) for v in value)
    return "null" if value is None else str(value).lower() if isinstance(value, bool) else str(value)


class RunConfig:
    """The config of one subcommand run, checked by ``problems`` (the top-level command's
    :func:`opnav.preflight.problems`: schema, core checks, both papers' physics checks, and
    with ``workflow`` the studies): :meth:`load` reads it, :meth:`with_flags` sets flags."""

    def __init__(self, problems: Callable[..., list[str]]):
        self.problems = problems

    def check(self, config: dict, *, workflow: bool = False) -> dict:
        """``config`` validated in place (defaults filled), or :class:`ConfigError`."""
        lines = self.problems(config, workflow=workflow)
        if lines:
            raise ConfigError("\n".join(lines))
        return config

    def with_flags(self, config: dict, flags: dict[str, tuple], *, workflow: bool = False) -> dict:
        """Set config keys from command-line flags and validate the result.

        ``flags`` maps a dotted config key to ``(flag, value)`` or ``(flag, value, shown)``
        (``shown``: the user's value where the flag sets a derived one, e.g. ``--pixel-sigma``
        sets three 3-sigma values); ``None`` values are skipped. The whole config is checked
        again. Each error line about a flag's key (or a parent or child of it) is prefixed
        with the flag and the user's value; a line the flags caused that names another key
        (``--set landing.duration_s=1`` moving the B-F5 instant out of the descent) is prefixed
        with every flag given, so no line blames a key the user did not touch without naming
        the one they did. Raises :class:`~opnav.core.errors.ConfigError`.
        """
        given = {k: fv for k, fv in flags.items() if fv[1] is not None}
        before = copy.deepcopy(config) if given else None
        for key, (_, value, *_rest) in given.items():
            set_key(config, key, value)
        try:
            return self.check(config, workflow=workflow)
        except ConfigError as exc:
            old = set(self.problems(before, workflow=workflow)) if before is not None else set()
            lines, listed = [], set()
            for line in str(exc).splitlines():
                m = _KEY_RE.search(line)
                bad = m.group(1) if m else ""
                item = re.match(r"config key '([^'\[]+)\[\d+\]'", line[m.start():] if m else "")
                if item and item.group(1) in given:          # one flag, one list: its first bad item
                    if item.group(1) in listed:              # (--pixel-sigma 0 set three 3-sigmas)
                        continue
                    listed.add(item.group(1))
                # the flag of the key the line names (or a parent or child of it), else of a
                # key the line mentions (approach.table1_variants ... not in approach.variants)
                names = [key for key in given
                         if bad and (bad == key or key.startswith(bad + ".") or bad.startswith(key + "."))]
                names = names or [key for key in given if re.search(rf"(?<![\w.]){re.escape(key)}(?![\w])", line)]
                if not names and line not in old:
                    names = list(given)                # caused by the flags, about another key
                shown = [f"{given[k][0]} {_shown(given[k][2] if len(given[k]) > 2 else given[k][1])}"
                         if not given[k][0].startswith("--set ") else
                         f"{given[k][0]}={_shown(given[k][2] if len(given[k]) > 2 else given[k][1])}"
                         for k in names]
                lines.append(f"{', '.join(dict.fromkeys(shown))}: {line}" if shown else line)
            raise ConfigError("\n".join(lines)) from None

    def load(self, args, *, workflow: bool = False) -> dict:
        """The config of one subcommand run: the defaults (``config/config.yaml``), the top-level
        ``opnav --config`` overlay, the subcommand's ``--config`` overlays, then its ``--set``
        keys, checked once. A ``--set`` key must exist, or be a key the schema allows under an
        existing map (a camera scenario's ``fov_deg``); a map's value must hold every key the
        map has (an empty or partial map would drop the others for the schema's defaults: the
        quick profile's 300 samples became 2,200); its errors name the flag, the key and the
        value given."""
        from opnav.core.config import load_config

        overlays = [*([args.config] if getattr(args, "config", None) else []), *getattr(args, "overlays", [])]
        config = load_config(overlays=overlays, validate=False)
        flags, new = {}, {}
        for text in getattr(args, "sets", []):
            key, value, raw = parse_set(text)
            node, parts = config, key.split(".")
            for i, part in enumerate(parts):
                if isinstance(node, dict) and part not in node and i == len(parts) - 1:
                    new[key] = sorted(node)      # a new key of an existing map: the schema decides
                    break
                if not isinstance(node, dict) or part not in node:
                    where = ".".join(parts[:i]) or "the top level"
                    have = ", ".join(sorted(node)) if isinstance(node, dict) else "no sub-keys"
                    raise ConfigError(f"--set {key}: no config key '{key}' ({where} has: {have})")
                node = node[part]
            else:
                if isinstance(node, dict) and isinstance(value, dict):
                    missing = [k for k in node if k not in value]
                    if missing:
                        what = "an empty map" if not value else f"a map without {_few(missing)}"
                        raise ConfigError(
                            f"--set {key}={raw}: {what} would replace the whole map '{key}' (its other keys "
                            f"falling back to the schema's defaults); set its keys one by one, e.g. "
                            f"--set {key}.{missing[0]}=..., or give every key it has ({_few(list(node))})")
            flags[key] = (f"--set {key}", value, raw)
        try:
            return self.with_flags(config, flags, workflow=workflow)
        except ConfigError as exc:
            lines = str(exc).splitlines()
            for key, have in new.items():      # the schema's "'x' was unexpected", said as above
                parent, _, last = key.rpartition(".")
                unexpected = f"invalid config key '{parent}': Additional properties are not allowed ('{last}' was"
                if any(unexpected in ln for ln in lines):
                    raise ConfigError(f"--set {key}: no config key '{key}' ({parent} has: "
                                      f"{', '.join(have) or 'no keys'})") from None
            raise


def _few(names: list[str], n: int = 6) -> str:
    return ", ".join(names[:n]) + (f" and {len(names) - n} more" if len(names) > n else "")
