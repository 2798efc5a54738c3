"""The ``--remote NAME`` options shared by the commands that perceive (run, query, serve): run experts on Ray
actors (:mod:`robokudo.core.remote`), on a local cluster or on the one at ``--address``.

Ray is an optional extra (``pip install 'robokudo[ray]'``); without it these options are refused with that hint
(exit 2), and nothing else needs it.
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterable
from typing import Any

from robokudo.application.cluster import ClusterError, ray_cluster, ray_module
from robokudo.core.annotator import Annotator
from robokudo.core.placement import Placement


class RemoteOptionError(Exception):
    """``--remote`` / ``--address`` cannot be used as given; the message says why (exit status 2)."""


def add_remote_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare ``--remote``, ``--remote-cpus``, ``--remote-gpus`` and ``--address``."""
    parser.add_argument(
        "--remote",
        metavar="NAME",
        action="append",
        default=[],
        help="run this annotator (node or class name) on a Ray actor; repeatable (needs robokudo[ray])",
    )
    parser.add_argument("--remote-cpus", type=float, metavar="N", help="CPUs each --remote actor reserves (1)")
    parser.add_argument("--remote-gpus", type=float, metavar="N", help="GPUs each --remote actor reserves (0)")
    parser.add_argument(
        "--address",
        metavar="ADDRESS",
        help="Ray cluster for remote experts: ray://HOST:10001 or HOST:6379 (default: a local cluster)",
    )


def remote_hints(args: argparse.Namespace) -> Placement | None:
    """The resource hints ``--remote-cpus`` / ``--remote-gpus`` give (None: the classes' own)."""
    if args.remote_cpus is None and args.remote_gpus is None:
        return None
    try:
        return Placement(
            remote=True,
            num_cpus=1.0 if args.remote_cpus is None else args.remote_cpus,
            num_gpus=0.0 if args.remote_gpus is None else args.remote_gpus,
        )
    except ValueError as error:
        raise RemoteOptionError(str(error).replace("Placement.num_", "--remote-")) from None


def check_remote_options(args: argparse.Namespace, classes: Iterable[type[Annotator]] = ()) -> Placement | None:
    """The hints, after checking the options: Ray is there when anything is to run remotely (``--remote``, or
    one of ``classes`` declares remote placement), and resource hints or an address come with ``--remote`` or
    such a class. RemoteOptionError naming the problem."""
    hints = remote_hints(args)
    declared = any(cls.placement.remote for cls in classes)
    if not args.remote and not declared:
        if hints is not None or args.address is not None:
            raise RemoteOptionError("--remote-cpus, --remote-gpus and --address go with --remote NAME")
        return None
    try:
        ray_module("--remote")
    except ClusterError as error:
        raise RemoteOptionError(str(error)) from None
    return hints


def remote_cluster(
    args: argparse.Namespace, classes: Iterable[type[Annotator]] = ()
) -> contextlib.AbstractContextManager[Any]:
    """The cluster the options ask for, connected for the block (nothing when no annotator runs remotely)."""
    if not args.remote and not any(cls.placement.remote for cls in classes):
        return contextlib.nullcontext()
    return ray_cluster(args.address, purpose="--remote")


def unknown_names(names: Iterable[str], known: Iterable[str]) -> list[str]:
    """The ``--remote`` names that are not among ``known`` (node or class names)."""
    known = set(known)
    return [name for name in names if name not in known]
