"""The ``robokudo parse QUERY [--json]`` subcommand."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from queries.dispatch import parse_query
from queries.errors import QueryError
from queries.json_form import query_to_json
from queries.printer import format_query

EXIT_BAD_QUERY = 2
"""Exit code for a query that does not parse or validate."""


HELP = "parse a perception query and print its canonical form"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``parse`` subcommand's arguments to ``parser``."""
    parser.add_argument(
        "query",
        nargs="+",
        metavar="QUERY",
        help="the query: nested form, JSON or a phrase (words are joined; '-' reads stdin)",
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="print the model as tagged JSON instead of the canonical nested form",
    )


def run(args: argparse.Namespace) -> int:
    """Parse ``args.query``, print the result and return the exit code."""
    words: list[str] = list(args.query)
    text = sys.stdin.read() if words == ["-"] else " ".join(words)
    try:
        query = parse_query(text)
    except QueryError as error:
        print(error, file=sys.stderr)
        return EXIT_BAD_QUERY
    if args.json:
        print(json.dumps(query_to_json(query), indent=2, ensure_ascii=False))
    else:
        print(format_query(query))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``parse`` as a stand-alone command (``python -m robokudo.application.commands.parse``)."""
    parser = argparse.ArgumentParser(prog="robokudo parse", description="Parse a perception query and print it.")
    add_arguments(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    raise SystemExit(main())
