"""A running server sees an ontology edit at once: after ``robokudo ontology add-object OatMilk --is-a Milk`` in
another process, the next goal naming oat milk is planned and answered without a restart."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from websockets.sync.client import connect

from tests.application.server.conftest import REPO, start_server
from tests.application.server.test_protocol import goal, receive

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
