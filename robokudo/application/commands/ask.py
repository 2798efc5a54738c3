"""``robokudo ask QUERY``: send a goal to a running ``robokudo serve`` and print its feedback and result.

Speaks the rosbridge v2 protocol with the ``websockets`` client: ``auth`` (when a token is given or
``$ROBOKUDO_TOKEN`` is set), then ``send_action_goal`` on ``/robokudo/query``. Feedback is printed as it arrives
(one line each, on stderr), the result on stdout (the answer's summary, or its JSON with ``--json``). Ctrl-C sends
``cancel_action_goal`` and waits for the goal to end. Exit status: 0 succeeded, 1 aborted or canceled, 2 when the
server cannot be reached or refused the goal, 130 when interrupted.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Any

from websockets.exceptions import ConnectionClosed, InvalidURI
from websockets.sync.client import ClientConnection, connect

from robokudo.application.server.protocol import GOAL_QUERY_FIELD, QUERY_ACTION, QUERY_ACTION_TYPE, GoalStatus

HELP = "send a query to a running 'robokudo serve' and print the feedback and the answer"

TOKEN_VARIABLE = "ROBOKUDO_TOKEN"
GOAL_ID = "robokudo-ask"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo ask``."""
    parser.add_argument("query", nargs="+", help="the query: nested, a phrase, or JSON")
    parser.add_argument("--server", default="ws://127.0.0.1:9090", help="the server (default ws://127.0.0.1:9090)")
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--token", help=f"the server's token (default: ${TOKEN_VARIABLE})")


def run(args: argparse.Namespace) -> int:
    """Send the goal and wait for its result (see the module for the exit status)."""
    token = args.token or os.environ.get(TOKEN_VARIABLE) or None
    try:
        with connect(args.server, open_timeout=10) as connection:
            if token is not None:
                connection.send(json.dumps({"op": "auth", "mac": token}))
            goal = {
                "op": "send_action_goal",
                "id": GOAL_ID,
                "action": QUERY_ACTION,
                "action_type": QUERY_ACTION_TYPE,
                "args": {GOAL_QUERY_FIELD: " ".join(args.query)},
                "feedback": True,
            }
            connection.send(json.dumps(goal))
            try:
                result = _wait(connection)
            except KeyboardInterrupt:
                connection.send(json.dumps({"op": "cancel_action_goal", "id": GOAL_ID, "action": QUERY_ACTION}))
                _report(_wait(connection), args.json)
                raise
    except (OSError, InvalidURI, ConnectionClosed) as error:
        print(f"robokudo ask: cannot talk to {args.server}: {error}", file=sys.stderr)
        return 2
    return _report(result, args.json)


def _wait(connection: ClientConnection) -> dict[str, Any]:
    """Print feedback until the goal's result (or a server error about it) arrives; returns that message.
    The server sends feedback every tick; a line is printed only when it says something new."""
    last_line = None
    for raw in connection:
        message = json.loads(raw)
        op = message.get("op")
        if op == "action_feedback" and message.get("id") == GOAL_ID:
            line = _feedback_line(message.get("values", {}))
            if line != last_line:
                print(line, file=sys.stderr, flush=True)
                last_line = line
            continue
        ours = op == "action_result" and message.get("id") == GOAL_ID
        if ours or (op == "status" and message.get("level") == "error"):
            return message
    raise ConnectionClosed(None, None)


def _feedback_line(values: dict[str, Any]) -> str:
    phase = values.get("phase", "?")
    running = values.get("running") or []
    if "answer" in values:
        return f"{phase}: {len(values['answer'].get('objects', []))} object(s)"
    return f"{phase}: {', '.join(running)}" if running else str(phase)


def _report(message: dict[str, Any], as_json: bool) -> int:
    if message.get("op") == "status":
        print(f"robokudo ask: the server refused: {message.get('msg')}", file=sys.stderr)
        return 2
    values = message.get("values", {})
    if message.get("result") is False:
        print(f"robokudo ask: the server refused the goal: {values.get('error', values)}", file=sys.stderr)
        return 2
    if message.get("status") != GoalStatus.SUCCEEDED:
        name = {GoalStatus.CANCELED: "canceled", GoalStatus.ABORTED: "aborted"}.get(message.get("status"), "failed")
        print(f"robokudo ask: goal {name}: {values.get('reason', '')}", file=sys.stderr)
        return 1
    print(json.dumps(values, indent=2) if as_json else summary(values))
    return 0


def summary(answer: dict[str, Any]) -> str:
    """One line per object of a served answer: id, class, region, position and existence confidence (after the
    number of them when the question asked how many)."""
    objects = answer.get("objects", [])
    lines = [f"count: {answer['count']}"] if "count" in answer else []
    if not objects:
        return "\n".join([*lines, "no matching object"])
    for o in objects:
        position = ", ".join(f"{v:.2f}" for v in o["pose"]["position"])
        where = f" in {o['region']}" if o.get("region") else ""
        lines.append(f"#{o['id']} {o['class']['label']}{where} at ({position}) exists {o['confidence']:.2f}")
    return "\n".join(lines)
