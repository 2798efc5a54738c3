"""``robokudo beliefs [QUERY] [--json] [--clear] [--store PATH]``: answer from memory, without perception.

Without QUERY every known object is listed; with QUERY (any query form) the known objects matching it are
listed, using the knowledge base for class subsumption and regions. ``--clear`` forgets everything. The store
is ``--store``, else ``$ROBOKUDO_BELIEF_STORE``, else ``<user data dir>/robokudo/beliefs.sqlite``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from queries import QueryError, parse_query
from reasoning.beliefs.answer import Answer, answer_from_memory
from reasoning.beliefs.filters import belief_filter
from reasoning.beliefs.store import BeliefFilter, BeliefStore, BeliefStoreError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base

HELP = "answer from the belief store, without running perception"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the arguments of ``robokudo beliefs``."""
    parser.add_argument("query", nargs="?", help='a perception query, e.g. "milk in fridge" (default: everything)')
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--clear", action="store_true", help="forget every stored belief")
    parser.add_argument("--all", action="store_true", help="include objects marked gone")
    parser.add_argument("--store", type=Path, default=None, help="belief store file (default: see above)")


def run(args: argparse.Namespace) -> int:
    """Run ``robokudo beliefs``; 0 on success, 2 on a bad store or query."""
    path = args.store.expanduser() if args.store else BeliefStore.default_path()
    try:
        if args.clear:
            return _clear(path, args)
        if not path.exists():
            return _print(Answer(query=args.query or "", from_memory=True), args, f"no beliefs stored yet ({path})")
        kb = load_knowledge_base() if args.query else None
        query_filter = _filter(args.query, args.all, kb)
        options = {"label_of": kb.label} if kb is not None else {}
        with BeliefStore(path) as store:
            answer = answer_from_memory(store, query_filter, args.query or "", **options)
        return _print(answer, args, None)
    except (BeliefStoreError, _QueryProblemError) as error:
        print(f"robokudo beliefs: {error}", file=sys.stderr)
        return 2


class _QueryProblemError(Exception):
    """The query text could not be parsed."""


def _clear(path: Path, args: argparse.Namespace) -> int:
    count = 0
    if path.exists():
        with BeliefStore(path) as store:
            count = store.clear()
    if args.json:
        print(json.dumps({"cleared": count, "store": str(path)}))
    else:
        print(f"forgot {count} object(s) in {path}")
    return 0


def _filter(text: str | None, include_gone: bool, kb: KnowledgeBase | None) -> BeliefFilter:
    if not text:
        return BeliefFilter(include_gone=include_gone)
    try:
        query = parse_query(text)
    except QueryError as error:
        try:  # a memory question may name just the object: "milk in fridge" means "find milk in fridge"
            query = parse_query(f"find {text}")
        except QueryError:
            raise _QueryProblemError(str(error)) from error
    return belief_filter(query, kb, include_gone=include_gone)


def _print(answer: Answer, args: argparse.Namespace, note: str | None) -> int:
    if args.json:
        print(answer.to_json())
    else:
        if note:
            print(note, file=sys.stderr)
        print(answer.summary())
    return 0
