"""``robokudo beliefs [QUERY] [--json] [--all] [--clear [--yes]] [--store PATH]``: answer from memory.

Without QUERY every known object is listed; with QUERY (any query form) the known objects matching it are
listed, using the knowledge base for class subsumption and regions. A class, value or region word the knowledge
base does not know is an error (exit 2), as it is for ``robokudo query``; ``inspect object 3`` lists belief 3,
or says ``no object 3`` (exit 2) when the store holds no such belief.

``QUERY --clear`` forgets exactly the objects the same command without ``--clear`` lists (with their history)
and prints how many. ``--clear`` without QUERY forgets every belief, gone ones and history included, and needs
``--yes`` to confirm; ``--clear --yes QUERY`` is refused as ambiguous. A refused or failed command forgets
nothing. The store is ``--store``, else ``$ROBOKUDO_BELIEF_STORE``, else ``<user data dir>/robokudo/beliefs.sqlite``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from queries import Block, Field, ListValue, Query, QueryError, String, Symbol, parse_query
from queries.errors import located_error
from reasoning.beliefs.answer import Answer, answer_from_memory
from reasoning.beliefs.filters import belief_filter
from reasoning.beliefs.store import BeliefFilter, BeliefStore, BeliefStoreError
from reasoning.errors import TermError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base

HELP = "answer from the belief store, without running perception"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the arguments of ``robokudo beliefs``."""
    parser.add_argument(
        "query", nargs="*", help='a perception query, e.g. "milk in fridge" (words are joined; default: everything)'
    )
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument(
        "--clear",
        action="store_true",
        help="forget the objects QUERY matches (what the command lists without --clear); "
        "without QUERY, forget every belief (needs --yes)",
    )
    parser.add_argument(
        "--yes", action="store_true", help="confirm --clear without QUERY: forget every belief and its history"
    )
    parser.add_argument("--all", action="store_true", help="include objects marked gone")
    parser.add_argument(
        "--store",
        type=Path,
        default=None,
        help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)",
    )


class _RefusedError(Exception):
    """The command cannot be carried out as given; nothing was changed."""


def run(args: argparse.Namespace) -> int:
    """Run ``robokudo beliefs``; 0 on success, 2 on a bad store, query, option combination or object id."""
    path = args.store.expanduser() if args.store else BeliefStore.default_path()
    words = args.query if isinstance(args.query, list) else [args.query or ""]
    args.query = " ".join(words).strip()
    try:
        _check_options(args)
        if args.clear and not args.query:
            return _clear_everything(path, args)
        kb = load_knowledge_base() if args.query else None
        query_filter, counted = _filter(args.query, args.all, kb)
        if not path.exists():  # reading never creates the store
            _check_ids(query_filter, None)
            if args.clear:
                return _print_cleared(0, (), path, args)
            return _print(Answer(query=args.query or "", from_memory=True), args, f"no beliefs stored yet ({path})")
        with BeliefStore(path) as store:
            _check_ids(query_filter, store)
            if args.clear:
                ids = tuple(b.id for b in store.query(query_filter))
                return _print_cleared(store.forget(ids), ids, path, args)
            options = {"label_of": kb.label} if kb is not None else {}
            answer = answer_from_memory(store, query_filter, args.query or "", counted=counted, **options)
        return _print(answer, args, None)
    except (BeliefStoreError, _RefusedError) as error:
        print(f"robokudo beliefs: {error}", file=sys.stderr)
        return 2


def _check_options(args: argparse.Namespace) -> None:
    if args.yes and not args.clear:
        raise _RefusedError("--yes only confirms --clear; nothing was forgotten")
    if args.clear and args.yes and args.query:
        raise _RefusedError(
            "--clear with both a QUERY and --yes is ambiguous: give QUERY to forget what it matches, or --yes "
            "(without QUERY) to forget every belief; nothing was forgotten"
        )
    if args.clear and not args.query and not args.yes:
        raise _RefusedError(
            "--clear without a QUERY would forget every belief; add --yes to confirm, or give a QUERY to forget "
            "only what it matches; nothing was forgotten"
        )


def _clear_everything(path: Path, args: argparse.Namespace) -> int:
    count = 0
    if path.exists():
        with BeliefStore(path) as store:
            count = store.clear()
    return _print_cleared(count, None, path, args)


def _print_cleared(count: int, ids: tuple[int, ...] | None, path: Path, args: argparse.Namespace) -> int:
    if args.json:
        document: dict[str, object] = {"cleared": count, "store": str(path)}
        if ids is not None:
            document["ids"] = sorted(ids)
        print(json.dumps(document))
    elif ids is None:
        print(f"forgot {count} object(s) in {path} (every belief, with its history)")
    else:
        print(f"forgot {count} object(s) matching {args.query!r} in {path}")
    return 0


def _check_ids(query_filter: BeliefFilter, store: BeliefStore | None) -> None:
    """Refuse a query naming an object id the store does not hold."""
    for object_id in query_filter.ids or ():
        if store is None or store.get(object_id) is None:
            raise _RefusedError(f"no object {object_id}")


def _filter(text: str | None, include_gone: bool, kb: KnowledgeBase | None) -> tuple[BeliefFilter, bool]:
    """The belief filter of a memory question and whether it asks how many."""
    if not text:
        return BeliefFilter(include_gone=include_gone), False
    added = ""
    try:
        query = parse_query(text)
    except QueryError as error:
        added = "find "  # a memory question may name just the object: "milk in fridge" means "find milk in fridge"
        try:
            query = parse_query(added + text)
        except QueryError:
            raise _RefusedError(str(error)) from error
    try:
        return belief_filter(query, kb, include_gone=include_gone, strict=True), query.counted
    except TermError as error:
        raise _RefusedError(_located(text, query, error, len(added))) from error


def _located(text: str, query: Query, error: TermError, added: int) -> str:
    """The message of ``error`` told where ``text`` said the unknown word (line, column and excerpt), as
    ``robokudo query`` tells it; ``added`` characters were put before ``text`` to parse it."""
    word = getattr(error, "word", None)
    said = _field_saying(query.body, word.lower()) if isinstance(word, str) else None
    if said is None or said.span.line <= 0:
        return str(error)
    column = said.span.column - (added if said.span.line == 1 else 0)
    return str(located_error(text, str(error), said.span.line, max(1, column)))


def _field_saying(block: Block, word: str) -> Field | None:
    """The innermost field of ``block`` whose value (or one of its values) is ``word``."""
    for item in block.fields:
        values = item.value.items if isinstance(item.value, ListValue) else (item.value,)
        for value in values:
            if isinstance(value, Block):
                inner = _field_saying(value, word)
                if inner is not None:
                    return inner
            elif (isinstance(value, Symbol) and value.name.lower() == word) or (
                isinstance(value, String) and value.text.lower() == word
            ):
                return item
    return None


def _print(answer: Answer, args: argparse.Namespace, note: str | None) -> int:
    if args.json:
        print(answer.to_json())
    else:
        if note:
            print(note, file=sys.stderr)
        print(answer.summary())
    return 0
