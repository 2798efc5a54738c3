"""A robot cancels a goal that has just ended (its result crossed the cancel on the wire): nothing to report, so no
``status`` error (roslibpy has no handler for one and prints a traceback); a cancel of a goal id the client never
sent still gets one."""

from __future__ import annotations

import json

from websockets.sync.client import connect

from tests.application.server.conftest import Served
from tests.application.server.test_protocol import beliefs_call, goal, receive, replies_until_the_service_response

ACTION = "/robokudo/query"


def cancel(goal_id: str) -> str:
    return json.dumps({"op": "cancel_action_goal", "id": goal_id, "action": ACTION})


def test_cancelling_a_goal_that_just_ended_is_no_error(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(goal("done", "find milk in fridge"))
        assert receive(connection, "action_result", "done")["status"] == 4
        connection.send(cancel("done"))
        connection.send(beliefs_call("after"))
        replies = replies_until_the_service_response(connection, "after")
    assert [m["op"] for m in replies] == ["service_response"], replies


def test_cancelling_a_goal_never_sent_is_an_error_naming_it(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(cancel("never-sent"))
        connection.send(beliefs_call("after"))
        replies = replies_until_the_service_response(connection, "after")
    errors = [m for m in replies if m["op"] == "status"]
    assert len(errors) == 1 and "never-sent" in str(errors[0]["msg"]), replies
