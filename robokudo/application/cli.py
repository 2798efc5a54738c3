"""The ``robokudo`` command line: one subcommand per module of :mod:`robokudo.application.commands`.

Each command module provides ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from types import ModuleType

from robokudo.application.commands import beliefs, ontology, parse, plan, query, run, tree

COMMANDS: dict[str, ModuleType] = {
    "tree": tree,
    "run": run,
    "parse": parse,
    "plan": plan,
    "query": query,
    "beliefs": beliefs,
    "ontology": ontology,
}
"""Subcommand name -> the module implementing it."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``robokudo`` command."""
    parser = argparse.ArgumentParser(prog="robokudo", description="Knowledge-enabled robot perception.")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        sub = commands.add_parser(name, help=module.HELP, description=module.HELP)
        module.add_arguments(sub)
        sub.set_defaults(handler=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script."""
    args = build_parser().parse_args(list(sys.argv[1:] if argv is None else argv))
    try:
        return int(args.handler(args))
    except (KeyError, ValueError) as error:
        print(f"robokudo: {error.args[0] if error.args else error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
