"""The protocol's edge cases over raw WebSocket JSON: bad messages get a status error and the connection keeps
working, authentication on a non-loopback bind, a client vanishing mid-goal, SIGTERM with a goal running."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from tests.application.server.conftest import Served, start_server

ACTION = "/robokudo/query"
WAIT = 60.0


def receive(connection: ClientConnection, op: str, goal_id: str | None = None) -> dict[str, Any]:
    """The next message with ``op`` (and ``id``), skipping feedback, ticks and others."""
    while True:
        message = json.loads(connection.recv(timeout=WAIT))
        if message["op"] == op and (goal_id is None or message.get("id") == goal_id):
            return message


def goal(goal_id: str, query: str = "find milk in fridge") -> str:
    return json.dumps({"op": "send_action_goal", "id": goal_id, "action": ACTION, "args": {"query": query}})


def plan_call(call_id: str) -> str:
    return json.dumps({"op": "call_service", "id": call_id, "service": "/robokudo/beliefs", "args": {"query": "find milk"}})


@pytest.mark.parametrize(
    ("message", "problem"),
    [
        ("{not json", "malformed JSON"),
        (json.dumps({"op": "teleport", "id": "x"}), "unknown op 'teleport'"),
        (json.dumps({"op": "subscribe", "topic": 42}), "field 'topic' of op 'subscribe' must be a string"),
        (json.dumps({"op": "send_action_goal", "id": "g", "action": ACTION, "args": "milk"}), "'args'"),
        (json.dumps([1, 2]), "must be a JSON object"),
        (json.dumps({"op": "call_service", "data": "x" * (1 << 20)}), "exceeds the limit"),
    ],
    ids=["malformed", "unknown-op", "wrong-type", "args-not-object", "not-object", "oversize"],
)
def test_a_bad_message_gets_a_status_error_and_the_connection_keeps_working(
    kitchen_server: Served, message: str, problem: str
) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(message)
        error = receive(connection, "status")
        assert error["level"] == "error" and problem in error["msg"]
        connection.send(plan_call("after"))
        response = receive(connection, "service_response")
        assert response["id"] == "after" and response["result"] is True


def test_a_goal_without_query_text_is_refused(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(json.dumps({"op": "send_action_goal", "id": "g", "action": ACTION, "args": {}}))
        result = receive(connection, "action_result", "g")
        assert result["result"] is False and "'query'" in result["values"]["error"]


def test_a_client_vanishing_mid_goal_has_its_goal_canceled_and_others_are_served(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as watcher, connect(kitchen_server.url) as leaving:
        leaving.send(goal("vanishing"))
        assert receive(leaving, "action_feedback", "vanishing")["values"]["phase"] == "planning"
        leaving.close()
        watcher.send(goal("next"))
        result = receive(watcher, "action_result", "next")
        assert result["status"] == 4 and result["values"]["objects"]


def test_the_beliefs_service_answers_from_memory(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(goal("fill"))
        assert receive(connection, "action_result", "fill")["status"] == 4
        connection.send(plan_call("memory"))
        response = receive(connection, "service_response")
        assert response["values"]["from_memory"] is True
        assert any(o["region"] == "fridge" for o in response["values"]["objects"])


@pytest.fixture(scope="module")
def guarded(tmp_path_factory: pytest.TempPathFactory) -> Any:
    served = start_server(tmp_path_factory.mktemp("guarded"), host="127.0.0.2", env={"ROBOKUDO_TOKEN": "s3cret"})
    yield served
    served.stop()


def test_a_client_without_the_token_is_refused_on_a_non_loopback_bind(guarded: Served) -> None:
    with connect(guarded.url) as connection:
        connection.send(plan_call("early"))
        error = receive(connection, "status")
        assert "authenticate first" in error["msg"]
        with pytest.raises(ConnectionClosed):
            receive(connection, "service_response")
    with connect(guarded.url) as connection:
        connection.send(json.dumps({"op": "auth", "mac": "wrong"}))
        assert "wrong token" in receive(connection, "status")["msg"]
        with pytest.raises(ConnectionClosed):
            connection.recv(timeout=WAIT)


def test_a_client_with_the_token_is_served(guarded: Served) -> None:
    with connect(guarded.url) as connection:
        connection.send(json.dumps({"op": "auth", "mac": "s3cret"}))
        connection.send(plan_call("late"))
        assert receive(connection, "service_response")["result"] is True


def test_binding_a_non_loopback_address_without_a_token_is_refused(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError, match="needs a token"):
        start_server(tmp_path, host="0.0.0.0", env={"ROBOKUDO_TOKEN": ""})


def test_sigterm_aborts_the_running_goal_with_the_reason_and_exits_0(tmp_path: Path) -> None:
    served = start_server(tmp_path)
    try:
        with connect(served.url) as connection:
            connection.send(goal("doomed"))
            feedback = receive(connection, "action_feedback", "doomed")
            while feedback["values"]["phase"] != "running":
                feedback = receive(connection, "action_feedback", "doomed")
            served.process.terminate()
            result = receive(connection, "action_result", "doomed")
        assert result["status"] == 6 and "SIGTERM" in result["values"]["reason"]
    finally:
        status = served.stop()
    assert status == 0
    assert (tmp_path / "beliefs.sqlite").exists()
