"""``robokudo tree list|show``: the hand-authored trees."""

from __future__ import annotations

import argparse
import sys

from robokudo.core.render import dot_tree, svg_tree, unicode_tree
from trees import available_trees, load_tree

HELP = "list or show the hand-authored trees"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo tree``."""
    actions = parser.add_subparsers(dest="tree_command", required=True, metavar="ACTION")
    actions.add_parser("list", help="list the trees").set_defaults(tree_action=_list)
    show = actions.add_parser("show", help="print one tree")
    show.add_argument("name")
    show.add_argument("--format", choices=("text", "dot", "svg"), default="text")
    show.set_defaults(tree_action=_show)


def run(args: argparse.Namespace) -> int:
    """List the trees or print one."""
    return int(args.tree_action(args))


def _list(_: argparse.Namespace) -> int:
    for name, spec in sorted(available_trees().items()):
        print(f"{name:24s} {spec.summary}")
    return 0


def _show(args: argparse.Namespace) -> int:
    root = load_tree(args.name).create()
    if args.format == "dot":
        sys.stdout.write(dot_tree(root))
    elif args.format == "svg":
        sys.stdout.write(svg_tree(root))
    else:
        print(unicode_tree(root, show_ports=True))
    return 0
