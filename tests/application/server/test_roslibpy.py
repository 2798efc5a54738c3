"""An independent client, roslibpy, uses the served kitchen: the query action, cancel, preemption, the plan
service and the tree status topic."""

from __future__ import annotations

import threading
import time
from typing import Any

import roslibpy

from tests.application.server.conftest import TOKEN, Served

ACTION = "/robokudo/query"
ACTION_TYPE = "robokudo_msgs/action/Query"
WAIT = 60.0


class GoalRecord:
    """What roslibpy reported for one goal."""

    def __init__(self) -> None:
        self.feedback: list[dict[str, Any]] = []
        self.result: dict[str, Any] | None = None
        self.error: Any = None
        self.running = threading.Event()
        self.ended = threading.Event()

    def on_feedback(self, feedback: Any) -> None:
        self.feedback.append(dict(feedback))
        if feedback.get("phase") == "running":
            self.running.set()

    def on_result(self, result: Any) -> None:
        self.result = dict(result)
        self.ended.set()

    def on_error(self, error: Any) -> None:
        self.error = error
        self.ended.set()


def send(action: roslibpy.ActionClient, query: str) -> tuple[str, GoalRecord]:
    record = GoalRecord()
    goal_id = action.send_goal(roslibpy.Goal({"query": query}), record.on_result, record.on_feedback, record.on_error)
    return goal_id, record


def ended(record: GoalRecord) -> dict[str, Any]:
    assert record.ended.wait(WAIT), "no result"
    assert record.error is None, record.error
    assert record.result is not None
    return record.result


def test_find_milk_in_fridge_gives_feedback_then_the_milk(ros: roslibpy.Ros) -> None:
    action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
    _, record = send(action, "find milk in fridge")
    result = ended(record)
    assert result["status"] is roslibpy.GoalStatus.SUCCEEDED
    assert [f["phase"] for f in record.feedback][:2] == ["planning", "running"]
    objects = result["values"]["objects"]
    assert objects and all(o["region"] == "fridge" for o in objects)
    assert any("milk" in o["class"]["label"].lower() for o in objects)


def test_a_cancelled_goal_ends_canceled_and_the_server_still_answers(ros: roslibpy.Ros) -> None:
    action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
    goal_id, record = send(action, "find milk in fridge")
    assert record.running.wait(WAIT)
    action.cancel_goal(goal_id)
    result = ended(record)
    assert result["status"] is roslibpy.GoalStatus.CANCELED
    assert "cancel" in result["values"]["reason"]
    _, again = send(action, "find milk in fridge")
    assert ended(again)["status"] is roslibpy.GoalStatus.SUCCEEDED


def test_a_second_goal_preempts_the_running_one(ros: roslibpy.Ros) -> None:
    action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
    _, first = send(action, "find milk in fridge")
    assert first.running.wait(WAIT)
    second_id, second = send(action, "find milk in fridge")
    preempted = ended(first)
    assert preempted["status"] is roslibpy.GoalStatus.CANCELED
    assert preempted["values"]["reason"] == f"preempted by goal {second_id}"
    assert ended(second)["status"] is roslibpy.GoalStatus.SUCCEEDED


def test_an_unplannable_goal_is_aborted_with_the_located_error(ros: roslibpy.Ros) -> None:
    action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
    _, record = send(action, "detect {obj: {type: Milk")
    result = ended(record)
    assert result["status"] is roslibpy.GoalStatus.ABORTED
    assert "line 1, column" in result["values"]["reason"]


def test_the_plan_service_returns_the_tree_and_its_explanation(ros: roslibpy.Ros) -> None:
    service = roslibpy.Service(ros, "/robokudo/plan", "robokudo_msgs/srv/Plan")
    response = service.call(roslibpy.ServiceRequest({"query": "find milk in fridge"}), timeout=WAIT)
    assert response["task"]["region"] == "fridge"
    names = str(response["tree"])
    assert "TextReader" in names and "TextReader" in response["explanation"]


def test_the_tree_status_topic_publishes_ticks(ros: roslibpy.Ros) -> None:
    statuses: list[dict[str, Any]] = []
    seen = threading.Event()

    def on_status(message: dict[str, Any]) -> None:
        statuses.append(message)
        if len(statuses) >= 3:
            seen.set()

    topic = roslibpy.Topic(ros, "/robokudo/tree_status", "std_msgs/String")
    topic.subscribe(on_status)
    try:
        action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
        _, record = send(action, "find milk in fridge")
        assert seen.wait(WAIT)
        ended(record)
        wanted = len(statuses) + 3
        deadline = time.monotonic() + WAIT
        while len(statuses) < wanted and time.monotonic() < deadline:  # a few ticks after the result
            time.sleep(0.02)
    finally:
        topic.unsubscribe()
    ticks = [s["tick"] for s in statuses]
    assert ticks == sorted(ticks) and len(set(ticks)) == len(ticks)
    assert statuses[0]["tree"]["name"] == "robot"
    in_slot = [next(c for c in s["tree"]["children"] if c["name"] == "task")["children"][0] for s in statuses]
    assert any(task["status"] == "SUCCESS" and task["name"] != "idle" for task in in_slot)  # the finished task
    assert in_slot[-1]["name"] == "idle"  # then the slot idles again


def test_the_beliefs_topic_publishes_what_a_goal_changed_in_the_store(ros: roslibpy.Ros) -> None:
    changes: list[dict[str, Any]] = []
    arrived = threading.Event()

    def on_changes(message: dict[str, Any]) -> None:
        changes.append(message)
        arrived.set()

    topic = roslibpy.Topic(ros, "/robokudo/beliefs", "std_msgs/String")
    topic.subscribe(on_changes)
    try:
        action = roslibpy.ActionClient(ros, ACTION, ACTION_TYPE)
        _, record = send(action, "find milk in fridge")
        result = ended(record)
        assert arrived.wait(WAIT)
    finally:
        topic.unsubscribe()
    milk = result["values"]["objects"][0]
    changed = {belief["id"]: belief for message in changes for belief in message["changed"]}
    assert milk["id"] in changed  # the milk the goal saw was published as a changed belief
    assert changed[milk["id"]]["region"] == "fridge"
    # the same class; the goal's answer also says how likely the milk answers to what was asked ("answers"), which
    # a change in the store, asked by nobody, does not
    published = changed[milk["id"]]["class"]
    assert (published["iri"], published["label"]) == (milk["class"]["iri"], milk["class"]["label"])
    assert "answers" not in published and 0.5 < milk["class"]["answers"] <= 1.0


def test_roslibpy_authenticates_with_the_token_on_a_guarded_server(guarded_server: Served) -> None:
    client = roslibpy.Ros(host=guarded_server.host, port=guarded_server.port)
    client.run()
    # Sent as the first message once connected; roslibpy's authenticate() sends on its "ready" event, which can come
    # after a request made right after run() returns, and the server refuses any op before auth.
    client.send_on_ready(
        roslibpy.Message(
            {"op": "auth", "mac": TOKEN, "client": "", "dest": "", "rand": "", "t": 0, "level": "", "end": 0}
        )
    )
    try:
        service = roslibpy.Service(client, "/robokudo/plan", "robokudo_msgs/srv/Plan")
        response = service.call(roslibpy.ServiceRequest({"query": "find milk in fridge"}), timeout=WAIT)
        assert response["task"]["region"] == "fridge"
    finally:
        client.close()
