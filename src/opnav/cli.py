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
import re
import sys

from opnav import __version__
from opnav.core.cliargs import (EXIT_NUMERICAL, EXIT_USER, Parser, RunConfig, add_config_arguments,  # noqa: F401
                                finite_float, integer, parse_set, print_json, set_key)
from opnav.core.errors import ConfigError


def run_config() -> RunConfig:
    """The checks every subcommand's config goes through (:func:`opnav.preflight.problems`)."""
    from opnav.preflight import problems

    return RunConfig(problems)


def with_flags(config: dict, flags: dict[str, tuple], *, workflow: bool = False) -> dict:
    """:meth:`opnav.core.cliargs.RunConfig.with_flags` with the workflow's checks."""
    return run_config().with_flags(config, flags, workflow=workflow)


def load_cli_config(args, *, workflow: bool = False) -> dict:
    """:meth:`opnav.core.cliargs.RunConfig.load` with the workflow's checks: the defaults, the
    ``--config`` overlays and the ``--set`` keys, checked once."""
    return run_config().load(args, workflow=workflow)


def build_parser() -> argparse.ArgumentParser:
    from opnav.approach import cli as approach_cli
    from opnav.landing import cli as landing_cli

    parser = Parser(
        prog="opnav",
        description=(
            "Reproducible Mars optical navigation: EM-EKF camera-misalignment "
            "estimation on approach (paper A) and depth-error landmark selection "
            "for powered descent (paper B). The full pipeline runs with "
            "`snakemake --cores 2`; these subcommands run single cases. Check a new "
            "config file with `opnav check FILE` before `snakemake --configfile FILE`."
        ),
        epilog=f"Exit codes: 0 ok, {EXIT_USER} bad input (flag, config value or file), "
               f"{EXIT_NUMERICAL} numerical failure.",
    )
    parser.add_argument("--version", action="version", version=f"opnav {__version__}")
    parser.add_argument("--config", default=None,
                        help="config overlay on config/config.yaml of the checkout (e.g. config/quick.yaml)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for part in (approach_cli, landing_cli):    # the papers' subcommands, in help order
        part.register(sub)
    _register_study(sub)
    for p in sub.choices.values():
        add_config_arguments(p)
    _register_check(sub)                        # files only: no overlays, no --set
    return parser


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


def _register_check(sub) -> None:
    p = sub.add_parser("check", help="check config files before `snakemake --configfile FILE ...`",
                       description="Read each config FILE as the workflow will (size, file type, encoding, "
                                   "YAML 1.2 rules, no YTE template), merge them on config/config.yaml in "
                                   "order as `snakemake --configfile FILE ...` does, and run every check the "
                                   "workflow runs before any job. One line per problem naming the file and "
                                   "the key, exit 2; a JSON summary and exit 0 when every file passes. It "
                                   "never hangs: a FIFO or device is not opened, and the check runs under a "
                                   "time and a memory limit.")
    p.add_argument("files", nargs="+", metavar="CONFIG", help="config files, in the order given to --configfile")
    p.add_argument("--timeout", type=integer, default=60, help="seconds before the check is stopped (default 60)")
    p.set_defaults(func=run_check)
    p.epilog = ("Snakemake reads a --configfile itself before any of the project's code runs: a FIFO, "
                "/dev/zero or a 10 MB file given to it hangs or fills memory, a UTF-16 file or deep "
                "nesting ends in a traceback. Run this first on a new config.")


def run_check(args, rc=None) -> int:
    """``opnav check``: print each problem line (``opnav: error: ...``) and exit 2, or a
    JSON summary and exit 0. Runs :func:`check_files` under a time and memory limit."""
    import time

    if args.timeout < 1:
        raise ConfigError("--timeout: must be at least 1 (seconds)")
    t0 = time.perf_counter()
    lines = _limited(args.files, args.timeout)
    if lines:
        for line in lines:
            print(f"opnav: error: {line}", file=sys.stderr)
        return EXIT_USER
    print_json({"ok": True, "files": list(args.files), "merged_on": "config/config.yaml",
                "seconds": round(time.perf_counter() - t0, 2)})
    return 0


def _limited(files: list[str], timeout: float) -> list[str]:
    """:func:`check_files` in a forked child with a memory limit, stopped after ``timeout`` s."""
    import json
    import os
    import select
    import signal
    import time

    from opnav.preflight import check_files

    if not hasattr(os, "fork"):
        return check_files(files)
    import opnav.approach.preflight  # noqa: F401  (imported before the limit: the child only checks)
    import opnav.landing.preflight  # noqa: F401
    import opnav.studies.planning  # noqa: F401

    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:                                      # the child: limited, reports through the pipe
        os.close(r)
        code = 0
        try:
            _limit_memory(CHECK_MEMORY_MB)
            out = check_files(files)
        except MemoryError:
            out = [f"config files {', '.join(files)}: the check ran out of memory ({CHECK_MEMORY_MB} MB)"]
        except BaseException as exc:                  # noqa: BLE001 - one line, never a traceback
            out = [f"config files {', '.join(files)}: the check failed ({type(exc).__name__}: "
                   f"{' '.join(str(exc).split())[:200]})"]
            code = 1
        try:
            os.write(w, json.dumps(out).encode())
        finally:
            os._exit(code)
    os.close(w)
    data, deadline = b"", time.monotonic() + timeout
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                return [f"config files {', '.join(files)}: the check did not finish in {timeout:g} s (stopped)"]
            ready, _, _ = select.select([r], [], [], left)
            if ready:
                chunk = os.read(r, 1 << 16)
                if not chunk:
                    break
                data += chunk
    finally:
        os.close(r)
    _, status = os.waitpid(pid, 0)
    if not data:
        sig = -os.waitstatus_to_exitcode(status)
        why = "ran out of memory" if sig == signal.SIGKILL else f"ended by signal {sig}" if sig > 0 else "failed"
        return [f"config files {', '.join(files)}: the check {why}"]
    return json.loads(data)


def _limit_memory(mb: int) -> None:
    """RLIMIT_AS: what the process maps now plus ``mb`` (where the platform has it)."""
    import os

    try:
        import resource
    except ImportError:                               # pragma: no cover - not POSIX
        return
    try:
        with open("/proc/self/statm") as f:
            now = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        now = 0
    limit = now + mb * 1024 * 1024
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


#: Memory ``opnav check`` may take beyond what the process maps when it starts (MB).
CHECK_MEMORY_MB = 1024


def study_command(name: str, overlays, cores: int = 2, dry_run: bool = False) -> list[str]:
    """The Snakemake command line that runs study ``name`` with the config ``overlays``
    (files; the target after ``--``, since ``--configfile`` takes every word after it)."""
    cmd = [sys.executable, "-m", "snakemake", "--cores", str(cores)]
    if dry_run:
        cmd.append("--dry-run")
    if overlays:
        cmd += ["--configfile", *map(str, overlays)]
    return cmd + ["--", f"study_{name}"]


def run_study(args, rc: RunConfig) -> int:
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
    config = rc.load(args, workflow=True)  # every overlay and --set, every study: errors name the key
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
                set_key(sets, key, value)
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
        return int(args.func(args, run_config()) or 0)
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
