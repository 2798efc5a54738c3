"""``robokudo query QUERY``: plan, run on an input, fuse into the belief store and print the answer."""

from __future__ import annotations

import argparse
import sys

from queries import QueryError
from reasoning.beliefs.store import BeliefStoreError
from reasoning.errors import OntologyError
from reasoning.planning.planner import PlanningError
from robokudo.application.service import AnsweringService, PerceptionFailedError
from robokudo.core.render import unicode_tree
from trees.synthesis import SynthesisError

HELP = "plan and run a query on an input and print the answer"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo query``."""
    parser.add_argument("query", nargs="+", help="the query: nested, a phrase, or JSON")
    parser.add_argument("--input", help="input to perceive (default: the built-in kitchen scene)")
    parser.add_argument("--frame", type=int, default=0, help="frame number in a sequence input")
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--explain", action="store_true", help="print the synthesized tree with its reasons")
    parser.add_argument("--store", help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)")


def run(args: argparse.Namespace) -> int:
    """Answer the query; exit 2 on a bad query or plan, 1 when perception failed."""
    text = " ".join(args.query)
    try:
        with AnsweringService.open(args.store, input_path=args.input, frame=args.frame) as service:
            outcome = service.answer(text)
    except QueryError as error:
        print(error, file=sys.stderr)
        return 2
    except (PlanningError, SynthesisError, OntologyError, BeliefStoreError, ValueError) as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 2
    except PerceptionFailedError as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 1
    if args.explain:
        print(unicode_tree(outcome.tree, show_status=True, show_reasons=True))
        print()
    print(outcome.answer.to_json() if args.json else outcome.answer.summary())
    return 0
