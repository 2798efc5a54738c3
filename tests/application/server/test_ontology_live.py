"""A running server sees an ontology edit at once: after ``robokudo ontology add-object OatMilk --is-a Milk`` in
another process, or an edit through its ``/robokudo/ontology`` service (called with roslibpy), the next goal naming
the new class is planned and answered without a restart; a rejected edit writes nothing; undo takes it back."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import roslibpy
from websockets.sync.client import connect

from tests.application.server.conftest import REPO, Served, start_server
from tests.application.server.test_protocol import WAIT, goal, receive

SUCCEEDED, ABORTED = 4, 6


def test_a_class_added_while_serving_is_queryable_by_the_next_goal(tmp_path: Path) -> None:
    served = start_server(tmp_path)
    try:
        with connect(served.url) as connection:
            connection.send(goal("before", "find oat milk in fridge"))
            before = receive(connection, "action_result", "before")
            assert before["status"] == ABORTED and "unknown object class 'oat_milk'" in before["values"]["reason"]
            environment = {
                **os.environ,
                "PYTHONPATH": str(REPO),
                "ROBOKUDO_USER_ONTOLOGY": str(tmp_path / "user.ttl"),
                "ROBOKUDO_BELIEF_STORE": str(tmp_path / "cli.sqlite"),
            }
            edit = [sys.executable, "-m", "robokudo", "ontology", "add-object", "OatMilk", "--is-a", "Milk"]
            added = subprocess.run(edit, cwd=REPO, env=environment, capture_output=True, text=True, timeout=120)
            assert added.returncode == 0, added.stderr
            connection.send(goal("after", "find oat milk in fridge"))
            after = receive(connection, "action_result", "after")
            assert after["status"] == SUCCEEDED, after["values"]
            assert "oat milk" in after["values"]["query"].lower()
    finally:
        assert served.stop() == 0


def call(ros: roslibpy.Ros, request: dict[str, Any]) -> tuple[bool, dict[str, Any]]:
    """Call ``/robokudo/ontology`` with roslibpy; (succeeded, values or the error)."""
    done = threading.Event()
    outcome: dict[str, Any] = {}

    def answered(values: Any) -> None:
        outcome.update(ok=True, values=dict(values))
        done.set()

    def failed(error: Any) -> None:
        outcome.update(ok=False, values=error if isinstance(error, dict) else {"error": str(error)})
        done.set()

    service = roslibpy.Service(ros, "/robokudo/ontology", "robokudo_msgs/srv/Ontology")
    service.call(roslibpy.ServiceRequest(request), answered, failed, timeout=WAIT)
    assert done.wait(WAIT), "no response"
    return outcome["ok"], outcome["values"]


def test_the_ontology_service_edits_the_user_layer_the_next_goal_uses(tmp_path: Path) -> None:
    served = start_server(tmp_path)
    ros = roslibpy.Ros(host=served.host, port=served.port)
    ros.run()
    try:
        ok, added = call(ros, {"action": "add", "name": "BarleyMilk", "is_a": ["Milk"], "synonyms": ["barley drink"]})
        assert ok and added["name"] == "BarleyMilk" and "Milk" in added["description"], added
        assert "BarleyMilk" in (tmp_path / "user.ttl").read_text()
        ok, shown = call(ros, {"action": "show", "name": "barley drink"})
        assert ok and "BarleyMilk" in shown["description"]
        with connect(served.url) as connection:
            connection.send(goal("barley", "find barley milk in fridge"))
            assert receive(connection, "action_result", "barley")["status"] == SUCCEEDED
        before = (tmp_path / "user.ttl").read_bytes()
        ok, refused = call(ros, {"action": "add", "name": "not a name", "is_a": ["Milk"]})
        assert not ok and "not a valid class name" in str(refused)
        assert (tmp_path / "user.ttl").read_bytes() == before  # a rejected edit writes nothing
        ok, log = call(ros, {"action": "log"})
        assert ok and [entry["name"] for entry in log["entries"]] == ["BarleyMilk"]
        ok, undone = call(ros, {"action": "undo"})
        assert ok and undone["undone"] == [1]
        with connect(served.url) as connection:
            connection.send(goal("gone", "find barley milk in fridge"))
            assert receive(connection, "action_result", "gone")["status"] == ABORTED
    finally:
        ros.close()
        assert served.stop() == 0


def test_an_ontology_call_without_an_action_gets_a_failed_response(kitchen_server: Served) -> None:
    with connect(kitchen_server.url) as connection:
        connection.send(json.dumps({"op": "call_service", "id": "o", "service": "/robokudo/ontology", "args": {}}))
        response = receive(connection, "service_response")
        assert response["id"] == "o" and response["result"] is False
        assert "needs the argument 'action'" in response["values"]["error"]
