"""The protocol's edge cases over raw WebSocket JSON: bad messages get a status error and the connection keeps
working, authentication on a non-loopback bind, a client vanishing mid-goal, SIGTERM with a goal running."""

from __future__ import annotations

import json
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from robokudo.application.server.session import MAX_SUBSCRIPTIONS
from tests.application.server.conftest import TOKEN, Served, start_server

ACTION = "/robokudo/query"
WAIT = 60.0
QUIET = 2.0
"""Seconds without a message after which the server is taken to be idle."""
CLIENTS = 8
GOALS_PER_CLIENT = 50


def receive(connection: ClientConnection, op: str, goal_id: str | None = None) -> dict[str, Any]:
    """The next message with ``op`` (and ``id``), skipping feedback, ticks and others."""
    while True:
        message = json.loads(connection.recv(timeout=WAIT))
        if message["op"] == op and (goal_id is None or message.get("id") == goal_id):
            return message


def replies_until_the_service_response(connection: ClientConnection, call_id: str) -> list[dict[str, object]]:
    """The messages up to the response to ``call_id`` (feedback and publications left out)."""
    replies = []
    while True:
        message = json.loads(connection.recv(timeout=WAIT))
        if message["op"] in ("action_feedback", "publish"):
            continue
        replies.append(message)
        if message["op"] == "service_response" and message.get("id") == call_id:
            return replies


def task_in_slot(tree: dict[str, Any]) -> str:
    """The name of what the task slot holds, in a ``/robokudo/tree_status`` tree."""
    slot = next(child for child in tree["children"] if child["name"] == "task")
    return str(slot["children"][0]["name"])


def went_idle(connection: ClientConnection) -> bool:
    """True once a tree status shows the idle subtree in the task slot while the engine still ticks (within
    :data:`WAIT`); the connection must be subscribed to ``/robokudo/tree_status``."""
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        status = receive(connection, "publish")["msg"]
        if task_in_slot(status["tree"]) == "idle":
            later = receive(connection, "publish")["msg"]
            return bool(later["tick"] > status["tick"])
    return False


def goal(goal_id: str, query: str = "find milk in fridge") -> str:
    return json.dumps({"op": "send_action_goal", "id": goal_id, "action": ACTION, "args": {"query": query}})


def beliefs_call(call_id: str) -> str:
    request = {"op": "call_service", "id": call_id, "service": "/robokudo/beliefs", "args": {"query": "find milk"}}
    return json.dumps(request)


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
        connection.send(beliefs_call("after"))
        response = receive(connection, "service_response")
        assert response["id"] == "after" and response["result"] is True


def test_a_goal_without_query_text_is_refused(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(json.dumps({"op": "send_action_goal", "id": "g", "action": ACTION, "args": {}}))
        result = receive(connection, "action_result", "g")
        assert result["result"] is False and "'query' (the query text) or 'obj'" in result["values"]["error"]


@pytest.mark.parametrize(
    ("action", "args", "problem"),
    [(ACTION, {"query": "  "}, "'query' (the query text)"), ("/robokudo/qery", {"query": "find milk"}, "no action")],
    ids=["blank-query", "unknown-action"],
)
def test_a_refused_goal_gets_its_failed_result_and_no_status_error_besides(
    kitchen_server: Served, action: str, args: dict[str, Any], problem: str
) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(json.dumps({"op": "send_action_goal", "id": "r", "action": action, "args": args}))
        connection.send(beliefs_call("after"))
        replies = replies_until_the_service_response(connection, "after")
    assert [m["op"] for m in replies] == ["action_result", "service_response"], replies
    assert replies[0]["result"] is False and problem in replies[0]["values"]["error"]


def test_a_structured_designator_goal_finds_the_milk_in_the_fridge(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        args = {"type": "detect", "obj": {"type": "Milk", "location": ["fridge"], "pose": []}}
        connection.send(json.dumps({"op": "send_action_goal", "id": "d", "action": ACTION, "args": args}))
        result = receive(connection, "action_result", "d")
    assert result["status"] == 4
    objects = result["values"]["objects"]
    assert objects and all(o["region"] == "fridge" for o in objects)
    assert any("milk" in o["class"]["label"].lower() for o in objects)


@pytest.mark.parametrize(
    ("designator", "found"),
    [
        ({"color": ["red", "blue"], "location": "table"}, {"red", "blue"}),  # the table's yellow object is left out
        ({"type": "Milk", "attribute": ["oat", "lactose free"]}, {"lactose free"}),  # the milk reads "lactose free"
        ({"type": "Milk", "attribute": ["oat", "soy"]}, set()),
    ],
    ids=["colors", "texts", "no-text-read"],
)
def test_a_designator_with_several_values_answers_the_objects_with_any_of_them(
    kitchen_server: Served, designator: dict[str, Any], found: set[str]
) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(
            json.dumps({"op": "send_action_goal", "id": "any", "action": ACTION, "args": {"obj": designator}})
        )
        result = receive(connection, "action_result", "any")
    assert result["status"] == 4
    objects = result["values"]["objects"]
    if "color" in designator:
        assert sorted(o["attributes"]["color"]["value"] for o in objects) == sorted(found)
    else:  # one milk whose text reads one of the alternatives, or none when no alternative is read
        read = [o["attributes"]["text"]["value"].lower() for o in objects]
        assert len(read) == len(found) and all(any(text in r for text in found) for r in read)


@pytest.mark.parametrize(
    ("designator", "problem"),
    [
        ({"type": "lactose free"}, "expected an identifier"),
        ({"type": "Milk", "pose": [{"header": {"frame_id": "map"}, "pose": {"position": {"x": 1.5}}}]}, "'pose'"),
        ({"type": ["Milk", "Cup"]}, "'type' has 2 values"),
        ({"weight": "1kg"}, "unknown designator field 'weight'"),
    ],
    ids=["not-a-name", "pose", "several-classes", "unknown-field"],
)
def test_a_designator_that_makes_no_query_is_aborted_with_the_reason(
    kitchen_server: Served, designator: dict[str, Any], problem: str
) -> None:
    with connect(kitchen_server.url) as connection:
        args = {"obj": designator}
        connection.send(json.dumps({"op": "send_action_goal", "id": "bad", "action": ACTION, "args": args}))
        result = receive(connection, "action_result", "bad")
    assert result["status"] == 6 and problem in result["values"]["reason"]


def test_a_client_vanishing_mid_goal_has_its_goal_canceled_and_others_are_served(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as watcher, connect(kitchen_server.url) as leaving:
        leaving.send(goal("vanishing", "track milk in fridge"))  # runs until cancelled
        feedback = receive(leaving, "action_feedback", "vanishing")
        while feedback["values"]["phase"] != "answer":
            feedback = receive(leaving, "action_feedback", "vanishing")
        watcher.send(json.dumps({"op": "subscribe", "topic": "/robokudo/tree_status"}))
        receive(watcher, "publish")
        leaving.close()
        assert went_idle(watcher), "the vanished client's task kept running"  # its task was taken out
        watcher.send(json.dumps({"op": "unsubscribe", "topic": "/robokudo/tree_status"}))
        watcher.send(goal("next"))
        result = receive(watcher, "action_result", "next")
        assert result["status"] == 4 and result["values"]["objects"]


def test_a_stop_goal_ends_the_running_track_goal_and_succeeds(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(goal("tracking", "track milk in fridge"))
        feedback = receive(connection, "action_feedback", "tracking")
        while feedback["values"]["phase"] != "answer":
            feedback = receive(connection, "action_feedback", "tracking")
        connection.send(goal("stopper", "stop all"))
        tracking = receive(connection, "action_result", "tracking")
        stopper = receive(connection, "action_result", "stopper")
    assert tracking["status"] == 5 and tracking["values"]["reason"] == "preempted by goal stopper"
    assert stopper["status"] == 4


def test_the_beliefs_service_answers_from_memory(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(goal("fill"))
        assert receive(connection, "action_result", "fill")["status"] == 4
        connection.send(beliefs_call("memory"))
        response = receive(connection, "service_response")
        assert response["values"]["from_memory"] is True
        assert any(o["region"] == "fridge" for o in response["values"]["objects"])


def test_a_client_without_the_token_is_refused_on_a_non_loopback_bind(guarded_server: Served) -> None:
    with connect(guarded_server.url) as connection:
        connection.send(beliefs_call("early"))
        error = receive(connection, "status")
        assert "authenticate first" in error["msg"]
        with pytest.raises(ConnectionClosed):
            receive(connection, "service_response")
    with connect(guarded_server.url) as connection:
        connection.send(json.dumps({"op": "auth", "mac": "wrong"}))
        assert "wrong token" in receive(connection, "status")["msg"]
        with pytest.raises(ConnectionClosed):
            connection.recv(timeout=WAIT)


def test_a_client_with_the_token_is_served(guarded_server: Served) -> None:
    with connect(guarded_server.url) as connection:
        connection.send(json.dumps({"op": "auth", "mac": TOKEN}))
        connection.send(beliefs_call("late"))
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


def test_eight_clients_sending_fifty_goals_each_get_exactly_one_result_per_goal(kitchen_server: Served) -> None:
    def client(number: int) -> list[dict[str, Any]]:
        ids = [f"c{number}-g{i}" for i in range(GOALS_PER_CLIENT)]
        with connect(kitchen_server.url) as connection:
            for goal_id in ids:
                connection.send(goal(goal_id))
            results: list[dict[str, Any]] = []
            while len(results) < len(ids):
                results.append(receive(connection, "action_result"))
            while True:
                try:
                    message = json.loads(connection.recv(timeout=QUIET))
                except TimeoutError:
                    break
                if message["op"] == "action_result":
                    results.append(message)
        return results

    with ThreadPoolExecutor(CLIENTS) as pool:
        per_client = list(pool.map(client, range(CLIENTS)))
    results = [r for rs in per_client for r in rs]
    ids = [r["id"] for r in results]
    assert len(ids) == CLIENTS * GOALS_PER_CLIENT and len(set(ids)) == len(ids)
    assert {r["status"] for r in results} <= {4, 5}
    assert sum(r["status"] == 4 for r in results) >= 1


def subscribe(subscription_id: str, op: str = "subscribe") -> str:
    return json.dumps({"op": op, "id": subscription_id, "topic": "/robokudo/tree_status"})


def next_reply(connection: ClientConnection) -> dict[str, Any]:
    """The next status error or service response (publications and goal messages skipped)."""
    while True:
        message = json.loads(connection.recv(timeout=WAIT))
        if message["op"] in ("status", "service_response"):
            return message


def test_subscriptions_beyond_the_cap_get_a_status_error_and_an_unsubscribe_frees_a_place(
    kitchen_server: Served,
) -> None:
    with connect(kitchen_server.url) as connection:
        for number in range(MAX_SUBSCRIPTIONS):
            connection.send(subscribe(f"s{number}"))
        connection.send(subscribe("s0"))  # the same subscription again takes no second place
        connection.send(beliefs_call("within"))
        assert next_reply(connection)["op"] == "service_response"

        connection.send(subscribe("over"))
        error = next_reply(connection)
        assert error["op"] == "status" and error["level"] == "error" and error.get("id") == "over"
        assert f"at most {MAX_SUBSCRIPTIONS}" in error["msg"]

        connection.send(goal("ticking"))  # the connection keeps working, its subscriptions publish each tick once
        publications = []
        while (message := json.loads(connection.recv(timeout=WAIT)))["op"] != "action_result":
            if message["op"] == "publish":
                publications.append(message["msg"])
        assert message["status"] == 4 and publications
        ticks = [p["tick"] for p in publications]
        assert len(set(ticks)) == len(ticks)
        nodes, timed = [publications[-1]["tree"]], []
        while nodes:
            node = nodes.pop()
            nodes.extend(node.get("children", []))
            if "timing" in node:
                timed.append(node["timing"])
        assert timed and any(t["runs"] > 0 and t["last_ms"] > 0 for t in timed)  # the annotators' run times

        connection.send(subscribe("s1", "unsubscribe"))
        connection.send(subscribe("over"))
        connection.send(beliefs_call("freed"))
        assert next_reply(connection)["op"] == "service_response"
        connection.send(subscribe("one-more"))
        assert f"at most {MAX_SUBSCRIPTIONS}" in next_reply(connection)["msg"]
