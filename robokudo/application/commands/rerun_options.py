"""The ``--rerun FILE.rrd`` and ``--rerun-connect [URL]`` options shared by the commands that perceive (run, query,
serve): record what the engine does with Rerun (:mod:`robokudo.application.rerun_log`).

The Rerun SDK is an optional extra (``pip install 'robokudo[rerun]'``); without it these options are refused with
that hint (exit 2), and nothing else needs it.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robokudo.application.rerun_log import RerunLog

INSTALL_HINT = "recording with Rerun needs the rerun-sdk package: pip install 'robokudo[rerun]' (or rerun-sdk)"
DEFAULT_VIEWER = "default"
"""What ``--rerun-connect`` without a URL stands for: the Rerun SDK's default viewer address."""


class RerunOptionError(Exception):
    """``--rerun`` / ``--rerun-connect`` cannot be used as given; the message says why (exit status 2)."""


def add_rerun_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare ``--rerun`` and ``--rerun-connect``."""
    parser.add_argument(
        "--rerun",
        metavar="FILE.rrd",
        help="record frames, clouds, boxes, beliefs and the tree status to a Rerun file (an existing one is continued)",
    )
    parser.add_argument(
        "--rerun-connect",
        metavar="URL",
        nargs="?",
        const=DEFAULT_VIEWER,
        help="stream the same to a running Rerun viewer: its URL or port (default rerun+http://127.0.0.1:9876/proxy)",
    )


def wants_rerun(args: argparse.Namespace) -> bool:
    """True when ``--rerun`` or ``--rerun-connect`` was given."""
    return args.rerun is not None or args.rerun_connect is not None


def open_rerun_log(args: argparse.Namespace) -> RerunLog | None:
    """The Rerun log the options ask for (None when they ask for none); RerunOptionError without the SDK, for a
    file that is not a Rerun recording, or when no viewer listens at the URL."""
    if not wants_rerun(args):
        return None
    if args.rerun is not None and not args.rerun.endswith(".rrd"):
        raise RerunOptionError(f"--rerun writes a Rerun recording: give a file name ending in .rrd, not {args.rerun!r}")
    try:
        from robokudo.application.rerun_log import DEFAULT_VIEWER_URL, RerunLog, RerunTargetError
    except ImportError as error:
        if (error.name or "").split(".")[0] in ("rerun", "rerun_bindings", "pyarrow"):
            raise RerunOptionError(INSTALL_HINT) from None
        raise
    url = args.rerun_connect
    if url == DEFAULT_VIEWER:
        url = DEFAULT_VIEWER_URL
    elif url is not None and url.isdigit():  # a port, as the rerun command takes it
        url = f"rerun+http://127.0.0.1:{url}/proxy"
    try:
        return RerunLog(args.rerun, url)
    except RerunTargetError as error:
        raise RerunOptionError(str(error)) from None
