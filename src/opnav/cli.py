"""The ``opnav`` command.

Subcommands are contributed by the subpackages: a module ``opnav.<part>.cli``
that defines ``register(subparsers)`` adds its own (``opnav approach``,
``opnav landing``). Each prints a JSON summary to stdout.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from opnav import __version__
from opnav.config import ConfigError

#: Subpackages that may contribute a subcommand, in help order.
PARTS = ("approach", "landing")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="opnav",
        description=(
            "Reproducible Mars optical navigation: EM-EKF camera-misalignment "
            "estimation on approach (paper A) and depth-error landmark selection "
            "for powered descent (paper B). The full pipeline runs with "
            "`snakemake --cores 2`; these subcommands run single cases."
        ),
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
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except ConfigError as exc:
        print(f"opnav: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
