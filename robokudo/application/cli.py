"""The ``robokudo`` command line."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from py_trees.common import Status

# Subcommands implemented in other packages: name -> (module, help). Each module provides
# ``add_arguments(parser)`` and ``run(args) -> int``; they are imported only when used.
_EXTERNAL_COMMANDS: dict[str, tuple[str, str]] = {
    "parse": ("robokudo.application.commands.parse", "parse a perception query and print its canonical form"),
    "plan": ("robokudo.application.commands.plan", "synthesize the perception tree for a query and print it"),
    "ontology": ("robokudo.application.commands.ontology", "show, check and edit the ontology"),
    "query": ("robokudo.application.commands.query", "plan and run a query on an input and print the answer"),
    "beliefs": ("robokudo.application.commands.beliefs", "answer from the belief store, without running perception"),
}


def _tree_list(_: argparse.Namespace) -> int:
    from trees import available_trees

    for name, spec in sorted(available_trees().items()):
        print(f"{name:24s} {spec.summary}")
    return 0


def _tree_show(args: argparse.Namespace) -> int:
    from robokudo.core.render import dot_tree, svg_tree, unicode_tree
    from trees import load_tree

    root = load_tree(args.name).create()
    if args.format == "dot":
        sys.stdout.write(dot_tree(root))
    elif args.format == "svg":
        sys.stdout.write(svg_tree(root))
    else:
        print(unicode_tree(root, show_ports=True))
    return 0


def _run(args: argparse.Namespace) -> int:
    from robokudo.application.report import describe_hypotheses, write_annotated_image
    from robokudo.core.engine import Engine
    from robokudo.core.pipeline import pipelines
    from robokudo.core.render import stats_table, unicode_tree
    from trees import load_tree

    root = load_tree(args.name).create(input_path=args.input, frame=args.frame)
    engine = Engine(root, hz=args.hz)
    status = engine.run(ticks=args.ticks, until=(lambda s: s is not Status.RUNNING) if args.once else None)
    print(unicode_tree(root, show_status=True, show_reasons=False))
    print()
    print(stats_table(root))
    cas = next(pipelines(root)).cas
    print()
    print(describe_hypotheses(cas))
    if args.annotated_image:
        print(f"annotated image: {write_annotated_image(cas, args.annotated_image)}")
    return 0 if status is Status.SUCCESS else 1


def build_parser(selected: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``robokudo`` command.

    Subcommands from other packages are imported only when ``selected`` names them, so ``robokudo parse``
    does not load the ontology and ``robokudo --help`` stays fast.
    """
    parser = argparse.ArgumentParser(prog="robokudo", description="Knowledge-enabled robot perception.")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    tree = commands.add_parser("tree", help="list or show the hand-authored trees")
    tree_commands = tree.add_subparsers(dest="tree_command", required=True, metavar="ACTION")
    tree_commands.add_parser("list", help="list the trees").set_defaults(handler=_tree_list)
    show = tree_commands.add_parser("show", help="print one tree")
    show.add_argument("name")
    show.add_argument("--format", choices=("text", "dot", "svg"), default="text")
    show.set_defaults(handler=_tree_show)

    run = commands.add_parser("run", help="run a tree with the engine")
    run.add_argument("name")
    run.add_argument("--input", help="input path (default: the built-in kitchen scene)")
    run.add_argument("--frame", type=int, default=0, help="frame number in a sequence input")
    run.add_argument("--ticks", type=int, default=None, help="tick this many times (default: until it finishes)")
    run.add_argument("--hz", type=float, default=30.0, help="tick frequency")
    run.add_argument("--annotated-image", metavar="PATH", help="write the colour image with the hypotheses drawn")
    run.set_defaults(handler=_run)

    for name, (module_name, help_text) in _EXTERNAL_COMMANDS.items():
        sub = commands.add_parser(name, help=help_text, description=help_text)
        if name == selected:
            _add_external_arguments(sub, module_name)
    return parser


def _add_external_arguments(parser: argparse.ArgumentParser, module_name: str) -> None:
    module = importlib.import_module(module_name)
    module.add_arguments(parser)
    parser.set_defaults(handler=module.run)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script."""
    arguments = list(sys.argv[1:] if argv is None else argv)
    selected = next((a for a in arguments if not a.startswith("-")), None)
    args = build_parser(selected).parse_args(arguments)
    if args.command == "run":
        args.once = args.ticks is None
    try:
        return int(args.handler(args))
    except (KeyError, ValueError) as error:
        print(f"robokudo: {error.args[0] if error.args else error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
