"""The ``opnav`` command.

Subcommands are contributed by the subpackages: a module ``opnav.<part>.cli``
that defines ``register(subparsers)`` adds its own (``opnav approach``,
``opnav landing``). Each prints a JSON summary to stdout (:func:`print_json`:
valid JSON, a non-finite number written as ``null``). ``opnav study NAME`` runs
one parameter study of the config (``studies``) through the checkout's Snakemake
workflow (its target ``study_NAME``) and prints where its outputs are.

Errors are one line each on stderr, no traceback. Exit codes: 0 success;
:data:`EXIT_USER` (2) for every user error (a bad flag or config value, an
unreadable or invalid YAML file, a missing file); :data:`EXIT_NUMERICAL` (3)
when a computation fails on inputs that passed every check. Every flag that
sets a config value goes through the same schema and physics checks as the
config (:func:`with_flags`), so the errors name the flag and the limit.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import re
import sys
from typing import Any

from opnav import __version__
from opnav.core.errors import ConfigError

#: Exit code of every user error (argparse's own code for a bad flag).
EXIT_USER = 2
#: Exit code of a numerical failure on inputs that passed every check.
EXIT_NUMERICAL = 3


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) naming the flag: an
    extra value after a flag of fixed arity (``--bias 1 2 3 4``) is reported against that
    flag, not as an unrecognised argument."""

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
            i = argv.index(m.group(1))
            j = i - 1
            while j >= 0 and not (argv[j].startswith("-") and not _is_number(argv[j])):
                j -= 1
            arity = self._arity()
            if j >= 0 and argv[j] in arity:
                end = next((k for k in range(i, len(argv)) if argv[k].startswith("-") and not _is_number(argv[k])),
                           len(argv))
                given = end - j - 1
                message = (f"argument {argv[j]}: takes {arity[argv[j]]} value(s), got {given} "
                           f"({' '.join(argv[j + 1:j + 1 + given])})")
        self.exit(EXIT_USER, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


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


def _set(config: dict, dotted: str, value: Any) -> None:
    *parents, last = dotted.split(".")
    node = config
    for p in parents:
        node = node.setdefault(p, {})
    node[last] = value


_KEY_RE = re.compile(r"config key '([^'\[]+)")


def _shown(value: Any) -> str:
    """A flag's value as the user typed it (lists space-separated, as nargs flags take them)."""
    if isinstance(value, (list, tuple)):
        return " ".join(_shown(v) for v in value)
    return "null" if value is None else str(value).lower() if isinstance(value, bool) else str(value)


def with_flags(config: dict, flags: dict[str, tuple], *, workflow: bool = False) -> dict:
    """Set config keys from command-line flags and validate the result.

    ``flags`` maps a dotted config key to ``(flag, value)`` or ``(flag, value, shown)``
    (``shown``: the user's value where the flag sets a derived one, e.g. ``--pixel-sigma``
    sets three 3-sigma values); ``None`` values are skipped. The whole config is checked
    again (:func:`opnav.preflight.check_config`: schema, core checks, the papers' physics
    checks). Each error line about a flag's key (or a parent or child of it) is prefixed
    with the flag and the user's value; a line the flags caused that names another key
    (``--set landing.duration_s=1`` moving the B-F5 instant out of the descent) is prefixed
    with every flag given, so no line blames a key the user did not touch without naming
    the one they did. Raises :class:`~opnav.core.errors.ConfigError`.
    """
    import copy

    from opnav.preflight import check_config, problems

    given = {k: fv for k, fv in flags.items() if fv[1] is not None}
    before = copy.deepcopy(config) if given else None
    for key, (_, value, *_rest) in given.items():
        _set(config, key, value)
    try:
        return check_config(config, workflow=workflow)
    except ConfigError as exc:
        old = set(problems(before, workflow=workflow)) if before is not None else set()
        lines = []
        for line in str(exc).splitlines():
            m = _KEY_RE.search(line)
            bad = m.group(1) if m else ""
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


def print_json(obj: Any, **kw) -> None:
    """Print ``obj`` as strict JSON (NaN and infinities written as ``null``)."""
    from opnav.core.tables import json_ready

    print(json.dumps(json_ready(obj), allow_nan=False, **kw))

#: Subpackages that may contribute a subcommand, in help order.
PARTS = ("approach", "landing")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="opnav",
        description=(
            "Reproducible Mars optical navigation: EM-EKF camera-misalignment "
            "estimation on approach (paper A) and depth-error landmark selection "
            "for powered descent (paper B). The full pipeline runs with "
            "`snakemake --cores 2`; these subcommands run single cases."
        ),
        epilog=f"Exit codes: 0 ok, {EXIT_USER} bad input (flag, config value or file), "
               f"{EXIT_NUMERICAL} numerical failure.",
    )
    parser.add_argument("--version", action="version", version=f"opnav {__version__}")
    parser.add_argument("--config", default=None,
                        help="config overlay on config/config.yaml of the checkout (e.g. config/quick.yaml)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for part in PARTS:
        try:
            mod = importlib.import_module(f"opnav.{part}.cli")
        except ModuleNotFoundError as exc:
            if exc.name != f"opnav.{part}.cli":
                raise
            continue
        mod.register(sub)
    _register_study(sub)
    for p in sub.choices.values():
        add_config_arguments(p)
    return parser


def add_config_arguments(p: argparse.ArgumentParser) -> None:
    """``--config FILE`` (overlay) and ``--set KEY.PATH=VALUE`` on a subcommand."""
    g = p.add_argument_group("configuration (applied in this order, then validated once)")
    g.add_argument("--config", dest="overlays", action="append", default=[], metavar="FILE",
                   help="config overlay merged on the defaults (config/config.yaml), after the "
                        "top-level `opnav --config`; repeatable")
    g.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY.PATH=VALUE",
                   help="set one config key, the value parsed as YAML (e.g. --set landing.camera.fov_deg=75, "
                        "--set approach.camera.sigma3_px=[0.2,0.2,0.4]); repeatable; the subcommand's own "
                        "flags are applied after it")


#: A --set key: dotted names, each as the schema's names are (scenario names hold "-").
_SET_KEY_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_-]*(\.[A-Za-z0-9_][A-Za-z0-9_-]*)*")


def parse_set(text: str) -> tuple[str, Any, str]:
    """``KEY.PATH=VALUE`` -> (dotted key, value, the value's text): the value read by the
    config files' strict reader (:func:`opnav.core.yamlfile.read_value`: YAML 1.1 traps,
    duplicate keys, control characters refused); an empty or null value is refused (a
    config key cannot be unset). Raises :class:`ConfigError` naming the flag and key."""
    from opnav.core.yamlfile import read_value

    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not _SET_KEY_RE.fullmatch(key):
        raise ConfigError(f"--set {text!r}: expected KEY.PATH=VALUE, e.g. --set landing.camera.fov_deg=75")
    return key, read_value(raw, f"--set {key}"), raw.strip()


def load_cli_config(args, *, workflow: bool = False) -> dict:
    """The config of one subcommand run: the defaults (``config/config.yaml``), the top-level
    ``opnav --config`` overlay, the subcommand's ``--config`` overlays, then its ``--set``
    keys, checked once by the workflow's own pre-flight (:func:`opnav.preflight.check_config`:
    schema, core checks, the papers' physics checks; with ``workflow``, also the studies,
    growing windows and job bounds). A ``--set`` key must exist, or be a key the schema
    allows under an existing map (a camera scenario's ``fov_deg``); its errors name the flag,
    the key and the value given."""
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
        flags[key] = (f"--set {key}", value, raw)
    try:
        return with_flags(config, flags, workflow=workflow)
    except ConfigError as exc:
        lines = str(exc).splitlines()
        for key, have in new.items():      # the schema's "'x' was unexpected", said as above
            parent, _, last = key.rpartition(".")
            unexpected = f"invalid config key '{parent}': Additional properties are not allowed ('{last}' was"
            if any(unexpected in ln for ln in lines):
                raise ConfigError(f"--set {key}: no config key '{key}' ({parent} has: "
                                  f"{', '.join(have) or 'no keys'})") from None
        raise


def _register_study(sub) -> None:
    p = sub.add_parser("study", help="run one parameter study (config `studies`) with Snakemake",
                       description="Run the parameter study NAME of the config (the defaults plus the "
                                   "--config overlays, e.g. one holding a new `studies` block) through "
                                   "the checkout's workflow: `snakemake --cores N --configfile FILE ... "
                                   "-- study_NAME`. Only that study's jobs run.")
    p.add_argument("name", metavar="NAME", help="the study's name (a key of `studies`)")
    p.add_argument("--cores", type=integer, default=2, help="Snakemake cores (default 2)")
    p.add_argument("-n", "--dry-run", action="store_true", help="list the jobs, run nothing")
    p.set_defaults(func=run_study)


def study_command(name: str, overlays, cores: int = 2, dry_run: bool = False) -> list[str]:
    """The Snakemake command line that runs study ``name`` with the config ``overlays``
    (files; the target after ``--``, since ``--configfile`` takes every word after it)."""
    cmd = [sys.executable, "-m", "snakemake", "--cores", str(cores)]
    if dry_run:
        cmd.append("--dry-run")
    if overlays:
        cmd += ["--configfile", *map(str, overlays)]
    return cmd + ["--", f"study_{name}"]


def run_study(args) -> int:
    """``opnav study NAME``: validate the merged config and every study (the checks the
    Snakefile runs, before any job), then run the study's Snakemake target in the
    checkout. Snakemake's output goes to stderr (stdout holds the JSON summary only); if
    it fails, its error lines follow as ``opnav: error:`` lines: exit 2 for a config
    problem it found, 3 for a failed job."""
    import os
    import subprocess
    import tempfile
    from pathlib import Path

    import yaml

    from opnav.core.config import repo_root

    if args.cores < 1:
        raise ConfigError("--cores: must be at least 1")
    config = load_cli_config(args, workflow=True)  # every overlay and --set, every study: errors name the key
    studies = config.get("studies") or {}
    if args.name not in studies:
        raise ConfigError(f"no study '{args.name}' in the config (studies: {', '.join(sorted(studies)) or 'none'}); "
                          "declare it in an overlay given with --config")
    root = repo_root()
    overlays = [Path(f).resolve() for f in [*([args.config] if getattr(args, "config", None) else []),
                                            *args.overlays]]
    with tempfile.TemporaryDirectory() as tmp:
        if args.sets:  # --set keys reach Snakemake as one more overlay
            sets = {}
            for text in args.sets:
                key, value, _ = parse_set(text)
                _set(sets, key, value)
            extra = Path(tmp, "set.yaml")
            extra.write_text(yaml.safe_dump(sets))
            overlays.append(extra)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            p for p in (str(root / "src"), os.environ.get("PYTHONPATH", "")) if p))
        proc = subprocess.Popen(study_command(args.name, overlays, args.cores, args.dry_run), cwd=root, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
        tail: list[str] = []
        for line in proc.stdout:            # streamed: a study runs for minutes
            sys.stderr.write(line)
            tail = (tail + [line.rstrip("\n")])[-200:]
        rc = proc.wait()
    if rc:
        lines, code = snakemake_error(tail)
        for line in lines:
            print(f"opnav: error: {line}", file=sys.stderr)
        print(f"opnav: error: snakemake failed for study '{args.name}' (exit {rc})", file=sys.stderr)
        return code
    out = Path(config["results_dir"]) / "studies" / args.name
    print_json({"study": args.name, "dry_run": bool(args.dry_run),
                "outputs": str(out if out.is_absolute() else root / out)})
    return 0


def snakemake_error(output: list[str]) -> tuple[list[str], int]:
    """The error lines of a failed Snakemake run's ``output`` and the exit code they mean:
    the config problems after the Snakefile's ``ConfigError (no job was run):`` (a user
    error, :data:`EXIT_USER`), else Snakemake's own error line (``WorkflowError``, ``Error in
    rule ...``, a missing input; :data:`EXIT_NUMERICAL` for a failed job)."""
    for i, line in enumerate(output):
        if line.startswith("ConfigError (no job was run):"):
            rest = [ln for ln in output[i + 1:] if ln.startswith(("invalid config", "config file"))]
            return rest or [line], EXIT_USER
    for i, line in enumerate(output):
        if line.startswith(("WorkflowError", "MissingInputException", "SyntaxError")):
            detail = next((ln.strip() for ln in output[i + 1:] if ln.strip()), "")
            return [f"{line.strip()} {detail}".strip()], EXIT_USER
    rules = [ln.strip().rstrip(":") for ln in output if ln.startswith("Error in rule")]
    return (rules[:3] or ["see the Snakemake output above"]), EXIT_NUMERICAL


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    import numpy as np

    try:
        return int(args.func(args) or 0)
    except ConfigError as exc:
        for line in str(exc).splitlines():
            print(f"opnav: error: {line}", file=sys.stderr)
        return EXIT_USER
    except BrokenPipeError:                      # e.g. `opnav landing | head`
        return 0
    except OSError as exc:
        print(f"opnav: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), file=sys.stderr)
        return EXIT_USER
    except KeyboardInterrupt:
        print("opnav: interrupted", file=sys.stderr)
        return 130
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        msg = " ".join(str(exc).split()) or type(exc).__name__
        if isinstance(exc, ValueError) and _NAMES_A_KEY.search(msg):
            # a check inside the package that names the user's key: a user error
            print(f"opnav: error: {msg}", file=sys.stderr)
            return EXIT_USER
        print(f"opnav: numerical failure ({type(exc).__name__}): {msg}", file=sys.stderr)
        return EXIT_NUMERICAL


#: A dotted config key in an error message (a ValueError raised by a check inside the
#: package about the user's value, e.g. opnav.approach.stars on approach.stars.every_K).
_NAMES_A_KEY = re.compile(r"\b(?:approach|landing)\.[a-z_]+[a-z0-9_.]*\b")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
