"""``robokudo serve``: keep one answering service running and serve it over the rosbridge v2 protocol.

Clients (roslibpy, roslibjs, ``robokudo ask``) send goals to the action ``/robokudo/query``, call the services
``/robokudo/plan`` and ``/robokudo/beliefs`` and subscribe to ``/robokudo/tree_status``
(:mod:`robokudo.application.server`). Binding anything but a loopback address needs a token (``--token`` or
``$ROBOKUDO_TOKEN``) that clients send in the ``auth`` op. SIGINT or SIGTERM aborts the running goals with the
reason, closes the belief store and exits 0. Exit status 2 for a bad option or belief store.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import sys

from reasoning.beliefs.store import BeliefStoreError
from reasoning.errors import OntologyError
from robokudo.application.commands.input_options import (
    add_input_arguments,
    frame_number,
    input_problem,
    intrinsics_of,
)
from robokudo.application.server.runner import ServerConfig, is_loopback, serve
from robokudo.application.service import AnsweringService

HELP = "serve queries to robots over the rosbridge v2 protocol (WebSocket) until SIGINT/SIGTERM"

TOKEN_VARIABLE = "ROBOKUDO_TOKEN"
DEFAULT_RATE = 30.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo serve``."""
    add_input_arguments(parser)
    parser.add_argument("--rate", type=float, default=DEFAULT_RATE, help=f"engine ticks per second ({DEFAULT_RATE:g})")
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=9090, help="port to listen on (default 9090)")
    parser.add_argument("--token", help=f"token clients must send in the 'auth' op (default: ${TOKEN_VARIABLE})")
    parser.add_argument("--db", help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)")


def run(args: argparse.Namespace) -> int:
    """Serve until interrupted; exit 0 then, 2 for a bad option or belief store."""
    problem = input_problem(args)
    token = args.token or os.environ.get(TOKEN_VARIABLE) or None
    if problem is None and args.rate <= 0:
        problem = f"--rate must be positive, got {args.rate:g}"
    if problem is None and token is None and not is_loopback(args.host):
        problem = f"binding {args.host} (not a loopback address) needs a token: --token or ${TOKEN_VARIABLE}"
    if problem is not None:
        print(f"robokudo serve: {problem}", file=sys.stderr)
        return 2
    try:
        service = AnsweringService.open(
            args.db, input_path=args.input, frame=frame_number(args), hz=args.rate, intrinsics=intrinsics_of(args)
        )
    except (BeliefStoreError, OntologyError) as error:
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    config = ServerConfig(host=args.host, port=args.port, token=token)

    def ready(address: str) -> None:
        print(f"serving on {address}", flush=True)

    try:
        reason = asyncio.run(serve(service, config, on_ready=ready))
    except OSError as error:  # the address is in use or cannot be bound
        print(f"robokudo serve: {error}", file=sys.stderr)
        return 2
    except BaseException:  # interrupted before the server took over the signals: still close the store
        service.close()
        raise
    print(f"robokudo serve: stopped: {reason}", file=sys.stderr, flush=True)
    return 0
