"""``robokudo query QUERY``: plan, run on an input, fuse into the belief store and print the answer.

Exit status: 0 with an answer (also when the query's ``timeout`` passed first: the answer then holds the stored
beliefs matching the query, ``"timed_out": true`` in the JSON and a note on stderr), 1 when perception failed,
2 for a bad query, plan, option, input, belief store or an object id the store does not hold (``no object 3``), and
for ``--rerun`` / ``--rerun-connect`` without the Rerun SDK or a viewer to reach, and for ``--remote`` without Ray
or naming no annotator class.
The query is parsed first, then the belief store is checked, before anything else is loaded.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from typing import TYPE_CHECKING

from annotators.catalog import AnnotatorCatalog
from queries import Query, QueryError, parse_query
from reasoning.beliefs.store import BeliefStoreError
from reasoning.errors import OntologyError
from reasoning.planning.planner import PlanningError
from robokudo.application.annotated_image import write_annotated_image
from robokudo.application.cluster import ClusterError
from robokudo.application.commands.input_options import (
    add_input_arguments,
    frame_number,
    input_problem,
    intrinsics_of,
)
from robokudo.application.commands.remote_options import (
    RemoteOptionError,
    add_remote_arguments,
    check_remote_options,
    remote_cluster,
    unknown_names,
)
from robokudo.application.commands.rerun_options import RerunOptionError, add_rerun_arguments, open_rerun_log
from robokudo.application.service import AnsweringService, Outcome, PerceptionFailedError, UnknownObjectError
from robokudo.core.remote import PlacementError
from robokudo.core.render import unicode_tree
from robokudo.core.types import ColorImage
from trees.synthesis import SynthesisError

if TYPE_CHECKING:
    from robokudo.application.rerun_log import RerunLog

HELP = "plan and run a query on an input and print the answer"

TIMED_OUT_NOTE = "the query's timeout passed before perception finished; the answer holds the stored beliefs that match"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo query``."""
    parser.add_argument("query", nargs="+", help="the query: nested, a phrase, or JSON")
    add_input_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--explain", action="store_true", help="print the synthesized tree with its reasons")
    parser.add_argument("--store", help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)")
    parser.add_argument(
        "--annotated-image",
        metavar="PATH",
        help="write the analysed frame with the answer's objects boxed and labelled",
    )
    parser.add_argument(
        "--person",
        metavar="SPEC",
        help="put a person into the built-in kitchen: stand, wave or point:<object or region>, optionally @x,y "
        "(where it stands, metres), e.g. point:red_cup@0.2,0.7",
    )
    add_rerun_arguments(parser)
    add_remote_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Answer the query; exit 2 on a bad query or plan, 1 when perception failed."""
    text = " ".join(args.query)
    problem = input_problem(args)
    if problem is not None:
        print(f"robokudo query: {problem}", file=sys.stderr)
        return 2
    try:
        query = parse_query(text)  # the cheapest check first: a bad query touches nothing
        catalog = None
        hints = check_remote_options(args)
        if args.remote:  # names to check against the catalog (else it loads after the store is checked)
            catalog = AnnotatorCatalog.discover()
            unknown = unknown_names(args.remote, catalog)
            if unknown:
                raise RemoteOptionError(f"--remote {unknown[0]}: no annotator class of that name")
        with (
            open_rerun_log(args) or contextlib.nullcontext() as rerun_log,
            remote_cluster(args),
            AnsweringService.open(
                args.store,
                input_path=args.input,
                frame=frame_number(args),
                intrinsics=intrinsics_of(args),
                catalog=catalog,
                remote=args.remote,
                remote_hints=hints,
                person=args.person,
            ) as service,
        ):
            outcome = answer(service, query, rerun_log)
            regions = service.kb.regions()  # to outline a pointed region in the picture
    except QueryError as error:
        print(error, file=sys.stderr)
        return 2
    except (PlanningError, SynthesisError, OntologyError, BeliefStoreError, UnknownObjectError, ValueError) as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 2
    except (RerunOptionError, RemoteOptionError, PlacementError, ClusterError) as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 2
    except PerceptionFailedError as error:
        print(f"robokudo query: {error}", file=sys.stderr)
        return 1
    if args.explain:
        print(unicode_tree(outcome.tree, show_status=True, show_reasons=True))
        print()
    if args.annotated_image and outcome.tree.cas.view(ColorImage) is not None:
        path = write_annotated_image(outcome.tree.cas, args.annotated_image, regions=regions)
        print(f"annotated image: {path}", file=sys.stderr)
    if outcome.answer.timed_out:
        print(f"robokudo query: {TIMED_OUT_NOTE}", file=sys.stderr)
    print(outcome.answer.to_json() if args.json else outcome.answer.summary())
    return 0


def answer(service: AnsweringService, query: Query, rerun_log: RerunLog | None) -> Outcome:
    """The service's answer to ``query``, recorded into ``rerun_log`` when there is one."""
    if rerun_log is None:
        return service.answer(query)
    from robokudo.application.rerun_log import service_recorder

    recorder = service_recorder(rerun_log, service)
    service.engine.tree.add_post_tick_handler(recorder.after_tick)
    service.add_belief_listener(recorder.beliefs_changed)
    try:
        return service.answer(query)
    finally:
        recorder.close()
