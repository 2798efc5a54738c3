"""``robokudo serve``: keep one answering service running and serve it over the rosbridge v2 protocol.

The engine ticks at ``--rate`` for the server's lifetime on a live source (``--input``): the built-in kitchen as a
simulated camera (default; pointed at each task's region), or a recording that ``--input`` reads elsewhere, or a
ROS 1 / ROS 2 bag (``--topic`` names its topics, else they are picked by type), played at its recorded rate (or
``--sensor-rate``), looped unless ``--once``. When a recording played once ends, the running goal and every later
one are aborted with that reason.

Clients (roslibpy, roslibjs, ``robokudo ask``) send goals to the action ``/robokudo/query``, call the services
``/robokudo/plan`` and ``/robokudo/beliefs`` and subscribe to ``/robokudo/tree_status``
(:mod:`robokudo.application.server`). Binding anything but a loopback address needs a token (``--token`` or
``$ROBOKUDO_TOKEN``) that clients send in the ``auth`` op. ``--write-behind N`` lets the belief store commit up to
N frames behind in a writer process (many cameras on a machine with a free core). ``--rerun FILE.rrd`` /
``--rerun-connect`` record every analysed frame, the belief changes and the tree's status changes with Rerun.
SIGINT or SIGTERM aborts the running goals with the reason, closes the belief store (committing every frame
fused, and finishing the Rerun file) and exits 0. Exit status 2 for a bad option or belief store.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from annotators.catalog import AnnotatorCatalog
from annotators.readers.bag_io import ANY_TOPICS, BagTopics, is_bag, named_topics
from annotators.readers.frame_io import FrameError
from annotators.readers.streams import FrameStream, KitchenCameraStream, stream_for
from reasoning.beliefs.frame_writer import MAX_WRITE_BEHIND
from reasoning.beliefs.store import BeliefStoreError
from reasoning.errors import OntologyError
from robokudo.application.cluster import ClusterError
from robokudo.application.commands.remote_options import (
    RemoteOptionError,
    add_remote_arguments,
    check_remote_options,
    remote_cluster,
    unknown_names,
)
from robokudo.application.commands.rerun_options import RerunOptionError, add_rerun_arguments, open_rerun_log
from robokudo.application.server.runner import ServerConfig, is_loopback, serve
from robokudo.application.service import DEFAULT_LOST_AFTER, AnsweringService
from robokudo.core.placement import Placement

if TYPE_CHECKING:
    from robokudo.application.rerun_log import RerunLog

HELP = "serve queries to robots over the rosbridge v2 protocol (WebSocket) until SIGINT/SIGTERM"

TOKEN_VARIABLE = "ROBOKUDO_TOKEN"
DEFAULT_RATE = 30.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo serve``."""
    parser.add_argument(
        "--input",
        help="live source: a recording any command's --input reads, or a ROS 1/2 bag (default: the kitchen camera)",
    )
    parser.add_argument(
        "--sensor-rate",
        type=float,
        help="frames per second of the source (default: the kitchen camera's 30, a recording's recorded rate)",
    )
    parser.add_argument("--once", action="store_true", help="play a recording once (default: loop it)")
    parser.add_argument(
        "--topic", action="append", default=[], help="a bag topic to read (repeat for colour, depth, camera info)"
    )
    parser.add_argument("--rate", type=float, default=DEFAULT_RATE, help=f"engine ticks per second ({DEFAULT_RATE:g})")
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=9090, help="port to listen on (default 9090)")
    parser.add_argument("--token", help=f"token clients must send in the 'auth' op (default: ${TOKEN_VARIABLE})")
    parser.add_argument("--db", help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)")
    parser.add_argument(
        "--lost-after",
        type=float,
        default=DEFAULT_LOST_AFTER,
        help="seconds a continuous goal's target may go unseen before the goal ends, when the query gives no "
        f"lost_after (default {DEFAULT_LOST_AFTER:g})",
    )
    parser.add_argument(
        "--write-behind",
        type=int,
        default=0,
        metavar="N",
        help="let the belief store commit up to N frames behind, in a writer process on another core (faster "
        "updates with a free core; a crash of both processes or a power failure loses up to N frames more; "
        "default 0: every frame is committed before the next)",
    )
    add_rerun_arguments(parser)
    add_remote_arguments(parser)


def source_stream(args: argparse.Namespace) -> FrameStream:
    """The live source the options name (ValueError / FrameError naming the problem)."""
    topics: BagTopics = ANY_TOPICS
    if args.topic:
        if args.input is None or not is_bag(Path(args.input).expanduser()):
            raise ValueError("--topic names topics of a bag: give the bag with --input")
        topics = named_topics(Path(args.input).expanduser(), args.topic)
    if args.once and args.input is None:
        raise ValueError("--once plays a recording once: give one with --input (the kitchen camera never ends)")
    stream = stream_for(args.input, args.sensor_rate, loop=not args.once, topics=topics)
    if isinstance(stream, KitchenCameraStream):
        stream.prepare()  # render every view now, not while a goal waits
    return stream


def run(args: argparse.Namespace) -> int:
    """Serve until interrupted; exit 0 then, 2 for a bad option, source or belief store."""
    token = args.token or os.environ.get(TOKEN_VARIABLE) or None
    problem = None
    if args.rate <= 0:
        problem = f"--rate must be positive, got {args.rate:g}"
    elif args.sensor_rate is not None and args.sensor_rate <= 0:
        problem = f"--sensor-rate must be positive, got {args.sensor_rate:g}"
    elif not args.lost_after >= 0 or args.lost_after == float("inf"):
        problem = f"--lost-after must be a number of seconds >= 0, got {args.lost_after:g}"
    elif not 0 <= args.write_behind <= MAX_WRITE_BEHIND:
        limit = MAX_WRITE_BEHIND
        problem = f"--write-behind must be 0 (off) or a number of frames up to {limit}, got {args.write_behind}"
    elif token is None and not is_loopback(args.host):
        problem = f"binding {args.host} (not a loopback address) needs a token: --token or ${TOKEN_VARIABLE}"
    if problem is not None:
        print(f"robokudo serve: {problem}", file=sys.stderr)
        return 2
    try:
        hints = check_remote_options(args)
        if args.remote:
            catalog = AnnotatorCatalog.discover()
            unknown = unknown_names(args.remote, catalog)
            if unknown:
                raise RemoteOptionError(f"--remote {unknown[0]}: no annotator class of that name")
        rerun_log = open_rerun_log(args)
    except (RerunOptionError, RemoteOptionError) as error:
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    try:
        with rerun_log or contextlib.nullcontext(), remote_cluster(args):
            return _serve(args, token, rerun_log, hints)
    except ClusterError as error:
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2


def _serve(args: argparse.Namespace, token: str | None, rerun_log: RerunLog | None, hints: Placement | None) -> int:
    try:
        stream = source_stream(args)
    except (ValueError, FrameError) as error:
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    try:
        service = AnsweringService.open(
            args.db,
            input_path=args.input,
            hz=args.rate,
            stream=stream,
            remote=args.remote,
            remote_hints=hints,
            lost_after=args.lost_after,
            write_behind=args.write_behind,
        )
    except (BeliefStoreError, OntologyError) as error:
        stream.close()
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    recorder = None
    if rerun_log is not None:
        from robokudo.application.rerun_log import service_recorder

        recorder = service_recorder(rerun_log, service, background=True)
    config = ServerConfig(host=args.host, port=args.port, token=token)

    def ready(address: str) -> None:
        page = address.replace("ws://", "http://", 1) + "/" + ("?token=TOKEN" if token is not None else "")
        print(f"serving on {address}", flush=True)
        print(f"live view: {page}", flush=True)

    try:
        reason = asyncio.run(serve(service, config, on_ready=ready, recorder=recorder))
    except OSError as error:  # the address is in use or cannot be bound
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    except BaseException:  # interrupted before the server took over the signals: still close the store
        service.close()
        raise
    finally:
        if recorder is not None:  # the engine has stopped: write what is queued and finish the file
            recorder.close()
    print(f"robokudo serve: stopped: {reason}", file=sys.stderr, flush=True)
    return 0
