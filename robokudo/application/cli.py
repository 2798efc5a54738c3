"""The ``robokudo`` command line: one subcommand per module of :mod:`robokudo.application.commands`.

Each command module provides ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``. Exit status: 0 on
success, 1 when the work itself failed (e.g. perception), 2 for bad input (query, option, path, store), and
130 when interrupted (SIGINT or SIGTERM: the command prints one line ``interrupted`` on stderr after stopping
the engine and closing the belief store, and ends the process; :mod:`robokudo.application.interrupts`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from types import MappingProxyType, ModuleType

from robokudo.application.commands import ask, beliefs, ontology, parse, plan, query, run, scenario, serve, tree
from robokudo.application.commands import eval as evaluation
from robokudo.application.interrupts import InterruptHandling

COMMANDS: Mapping[str, ModuleType] = MappingProxyType(
    {
        "tree": tree,
        "run": run,
        "parse": parse,
        "plan": plan,
        "query": query,
        "beliefs": beliefs,
        "ontology": ontology,
        "serve": serve,
        "ask": ask,
        "eval": evaluation,
        "scenario": scenario,
    }
)
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
    """Entry point of the console script; an interrupted command ends the process (exit status 130)."""
    with InterruptHandling() as interrupts:
        try:
            status = _run(argv)
        except SystemExit:
            raise
        except BaseException:
            if interrupts.received is None:
                raise
        # The interrupt may arrive wrapped (a C extension turns it into ImportError, an expert's failure, ...):
        # once one was received, the command was interrupted whatever it returned.
        if interrupts.received is not None:
            interrupts.exit()
    return status


def _run(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args, unknown = parser.parse_known_args(list(sys.argv[1:] if argv is None else argv))
    if unknown:  # told by the (sub)command given, with its usage, not by the top-level parser
        _given_command(parser, args).error(f"unrecognized arguments: {' '.join(unknown)}")
    try:
        return int(args.handler(args))
    except (KeyError, ValueError) as error:
        print(f"robokudo: {error.args[0] if error.args else error}", file=sys.stderr)
        return 2


def _given_command(parser: argparse.ArgumentParser, args: argparse.Namespace) -> argparse.ArgumentParser:
    """The innermost sub-command parser ``args`` were parsed by (``robokudo ontology show``)."""
    while True:
        chosen = next(
            (
                action.choices.get(getattr(args, action.dest, None) or "")
                for action in parser._actions
                if isinstance(action, argparse._SubParsersAction)
            ),
            None,
        )
        if chosen is None:
            return parser
        parser = chosen


if __name__ == "__main__":
    sys.exit(main())
