"""``robokudo query QUERY``: plan, run on an input, fuse into the belief store and print the answer."""

from __future__ import annotations

import argparse
import sys

import py_trees
from py_trees.common import Status

from queries import QueryError, parse_query
from reasoning.beliefs.answer import Answer
from reasoning.beliefs.filters import belief_filter, kb_class_test
from reasoning.beliefs.store import BeliefStore, BeliefStoreError
from reasoning.errors import OntologyError
from reasoning.fusion.tracking import BeliefTracker
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.planner import PlanningError
from robokudo.application.commands.plan import synthesize
from robokudo.application.knowledge import load_knowledge_base
from robokudo.core.engine import Engine
from robokudo.core.render import unicode_tree
from robokudo.core.slot import TaskSlot
from trees.answer_step import AnswerStep
from trees.synthesis import SynthesisError, build_tree

TASK_SLOT = "task"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo query``."""
    parser.add_argument("query", nargs="+", help="the query: nested, a phrase, or JSON")
    parser.add_argument("--input", help="input to perceive (default: the built-in kitchen scene)")
    parser.add_argument("--frame", type=int, default=0, help="frame number in a sequence input")
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--explain", action="store_true", help="print the synthesized tree with its reasons")
    parser.add_argument("--store", help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)")


def answer_query(
    text: str, kb: KnowledgeBase, input_path: str | None = None, frame: int = 0, store: BeliefStore | None = None
) -> tuple[Answer, py_trees.behaviour.Behaviour]:
    """Plan ``text``, run the tree once in the engine's task slot and return the answer and the tree."""
    query = parse_query(text)
    query_plan = synthesize(text, kb, input_path, frame)
    step = AnswerStep(
        store if store is not None else BeliefStore.default_path(),
        tracker=BeliefTracker(class_test=kb_class_test(kb), regions=kb.regions()),
        filter_for=lambda q: belief_filter(q, kb),
        label_of=kb.label,
    )
    step.reason = "fuses the hypotheses into the belief store and answers with the objects matching the query"
    pipeline = build_tree(query_plan.plan, final_steps=[step], query=query)
    root = py_trees.composites.Sequence("robot", memory=True, children=[TaskSlot(TASK_SLOT)])
    engine = Engine(root, hz=100.0)
    engine.tasks.insert(TASK_SLOT, pipeline)
    try:
        engine.run(until=lambda status: status is not Status.RUNNING)
    finally:
        step.shutdown()
    if step.answer is None:
        failed = [n for n in pipeline.iterate() if n.status is Status.FAILURE and n.feedback_message]
        reason = "; ".join(f"{n.name}: {n.feedback_message}" for n in failed) or "the tree did not finish"
        raise PlanningError(f"perception failed: {reason}")
    return step.answer, pipeline


def run(args: argparse.Namespace) -> int:
    """Answer the query; exit 2 on a bad query or plan, 1 when perception failed."""
    text = " ".join(args.query)
    try:
        kb = load_knowledge_base()
        store = BeliefStore(args.store) if args.store else None
        answer, tree = answer_query(text, kb, args.input, args.frame, store)
    except QueryError as error:
        print(error, file=sys.stderr)
        return 2
    except (SynthesisError, OntologyError, BeliefStoreError) as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 2
    except PlanningError as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 1 if str(error).startswith("perception failed") else 2
    if args.explain:
        print(unicode_tree(tree, show_status=True, show_reasons=True))
        print()
    print(answer.to_json() if args.json else answer.summary())
    return 0
