"""``robokudo plan QUERY``: synthesize the Perception Pipeline Tree for a query and print it."""

from __future__ import annotations

import argparse
import json
import sys

from annotators.catalog import AnnotatorCatalog
from queries import QueryError, format_query, parse_query
from reasoning.errors import OntologyError
from reasoning.planning.planner import PlanningError
from reasoning.planning.query_planner import QueryPlan, QueryPlanner
from robokudo.application.commands.input_options import (
    add_input_arguments,
    frame_number,
    input_problem,
    intrinsics_of,
)
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.planning import plan_for_input
from robokudo.core.render import tree_to_dict, unicode_tree
from trees.synthesis import SynthesisError, build_task_tree

HELP = "synthesize the perception tree for a query and print it"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo plan``."""
    parser.add_argument("query", nargs="+", help="the query: nested, a phrase, or JSON")
    parser.add_argument("--json", action="store_true", help="print a machine-readable tree")
    parser.add_argument("--explain", action="store_true", help="print why each node is there")
    add_input_arguments(parser, "input the tree will read")


def task_summary(query_plan: QueryPlan) -> dict[str, object]:
    """The interpretation of the query, as plain data."""
    task = query_plan.interpretation.task
    return {
        "kind": task.kind,
        "object_class": task.object_class,
        "region": task.region,
        "constraints": [{"key": c.key, "type": c.annotation_type, "value": c.value} for c in task.constraints],
        "inferences": list(task.inferences),
    }


def run(args: argparse.Namespace) -> int:
    """Plan and print; exit 2 with the reason when the query cannot be parsed or planned."""
    text = " ".join(args.query)
    problem = input_problem(args)
    if problem is not None:
        print(f"robokudo plan: {problem}", file=sys.stderr)
        return 2
    try:
        catalog = AnnotatorCatalog.discover()
        planner = QueryPlanner(load_knowledge_base(catalog=catalog))
        query_plan = plan_for_input(
            planner, parse_query(text), args.input, frame_number(args), intrinsics=intrinsics_of(args)
        )
        tree = build_task_tree(query_plan.plan, catalog=catalog)
    except QueryError as error:
        print(error, file=sys.stderr)
        return 2
    except (PlanningError, SynthesisError, OntologyError) as error:
        print(f"robokudo plan: {error}", file=sys.stderr)
        return 2
    if args.json:
        document = {
            "query": format_query(parse_query(text)),
            "task": task_summary(query_plan),
            "tree": tree_to_dict(tree),
        }
        print(json.dumps(document, indent=2))
        return 0
    print(unicode_tree(tree, show_reasons=args.explain))
    if args.explain:
        for inference in query_plan.interpretation.task.inferences:
            print(f"inferred: {inference}")
    return 0
