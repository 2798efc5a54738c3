"""``robokudo run TREE``: run a hand-authored tree with the engine and print what it found."""

from __future__ import annotations

import argparse
import sys

from py_trees.behaviour import Behaviour
from py_trees.common import Status

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
from robokudo.application.report import describe_hypotheses
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import pipelines
from robokudo.core.remote import PlacementError, place_remote
from robokudo.core.render import stats_table, unicode_tree
from trees import load_tree

HELP = "run a tree with the engine"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo run``."""
    parser.add_argument("name")
    add_input_arguments(parser, "input path")
    parser.add_argument("--ticks", type=int, default=None, help="tick this many times (default: until it finishes)")
    parser.add_argument("--hz", type=float, default=30.0, help="tick frequency")
    parser.add_argument("--annotated-image", metavar="PATH", help="write the frame with what was found drawn")
    add_rerun_arguments(parser)
    add_remote_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Run the tree (once, or ``--ticks`` times); 0 when it succeeded, 2 for bad options (``--rerun`` without the
    Rerun SDK, ``--remote`` without Ray or naming no annotator of the tree, ...)."""
    problem = input_problem(args)
    if problem is not None:
        print(f"robokudo run: {problem}", file=sys.stderr)
        return 2
    root = load_tree(args.name).create(input_path=args.input, frame=frame_number(args), intrinsics=intrinsics_of(args))
    annotators = [node for node in root.iterate() if isinstance(node, Annotator)]
    try:
        hints = check_remote_options(args, (type(node) for node in annotators))
        unknown = unknown_names(args.remote, [n for node in annotators for n in (node.name, type(node).__name__)])
        if unknown:
            names = ", ".join(sorted({node.name for node in annotators}))
            raise RemoteOptionError(f"--remote {unknown[0]}: no annotator of that name in the tree ({names})")
        with remote_cluster(args, (type(node) for node in annotators)):
            placed = place_remote(root, args.remote, hints)
            status = _run(args, root)
            for node in placed:
                print(f"remote {node.name}: {node.where.describe()}, calls through {node.call_path}")
            return status
    except (RemoteOptionError, PlacementError, ClusterError) as error:
        print(f"robokudo run: {error}", file=sys.stderr)
        return 2


def _run(args: argparse.Namespace, root: Behaviour) -> int:
    engine = Engine(root, hz=args.hz)
    try:
        rerun_log = open_rerun_log(args)
    except RerunOptionError as error:
        print(f"robokudo run: {error}", file=sys.stderr)
        return 2
    until_finished = (lambda s: s is not Status.RUNNING) if args.ticks is None else None
    if rerun_log is None:
        status = engine.run(ticks=args.ticks, until=until_finished)
    else:
        from robokudo.application.rerun_log import TickRecorder

        recorder = TickRecorder(rerun_log, task_of=lambda tree: tree, tick_of=lambda: engine.tick_count)
        engine.tree.add_post_tick_handler(recorder.after_tick)
        try:
            status = engine.run(ticks=args.ticks, until=until_finished)
        finally:
            recorder.close()
    print(unicode_tree(root, show_status=True, show_reasons=False))
    print()
    print(stats_table(root))
    cas = next(pipelines(root)).cas
    print()
    print(describe_hypotheses(cas))
    if args.annotated_image:
        print(f"annotated image: {write_annotated_image(cas, args.annotated_image)}")
    return 0 if status is Status.SUCCESS else 1
