"""A ROS 2 bag written here with rosbags' own writer from shared real frames plays through ``robokudo serve``: a goal
is answered on it, and when a bag played once ends, the running goal and later ones are aborted with that reason."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from websockets.sync.client import ClientConnection, connect

from annotators.readers.frame_io import read_color_depth_pair
from tests.annotators.bag_writing import COLOR_TOPIC, DEPTH_TOPIC, INFO_TOPIC, write_bag
from tests.annotators.conftest import SHARED_DATA, require_folder
from tests.application.server.conftest import start_server
from tests.application.server.test_protocol import WAIT, goal, receive

pytestmark = pytest.mark.real_data

SUCCEEDED, ABORTED = 4, 6


def receive_any(connection: ClientConnection, goal_id: str) -> dict[str, Any]:
    """The next feedback or result of the goal ``goal_id``."""
    while True:
        message = json.loads(connection.recv(timeout=WAIT))
        if message["op"] in ("action_feedback", "action_result") and message.get("id") == goal_id:
            return message


@pytest.fixture(scope="module")
def uoc_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    uoc_folder = require_folder(SHARED_DATA / "uoc_tabletop_realsense")
    frames = [read_color_depth_pair(uoc_folder, index % 3) for index in range(6)]
    return write_bag(tmp_path_factory.mktemp("bag") / "frames", frames, ros1=False)


def test_a_goal_is_answered_on_a_looping_bag_with_named_topics(uoc_bag: Path, tmp_path: Path) -> None:
    topics = ["--topic", COLOR_TOPIC, "--topic", DEPTH_TOPIC, "--topic", INFO_TOPIC]
    served = start_server(tmp_path, "--input", str(uoc_bag), *topics)
    try:
        with connect(served.url) as connection:
            # uoc frames 0-2 hold the blue mug and no cup (a can once answered "cup" there)
            connection.send(goal("mugs", "detect { obj: { type: Mug } }"))
            result = receive(connection, "action_result", "mugs")
        assert result["status"] == SUCCEEDED, result["values"]
        assert result["values"]["objects"] and {o["class"]["label"] for o in result["values"]["objects"]} == {"mug"}
    finally:
        assert served.stop() == 0


def test_a_bag_played_once_aborts_the_running_goal_and_later_ones_when_it_ends(uoc_bag: Path, tmp_path: Path) -> None:
    served = start_server(tmp_path, "--input", str(uoc_bag), "--once", "--sensor-rate", "1")
    try:
        with connect(served.url) as connection:
            connection.send(goal("tracking", "track the cup"))
            answers = 0
            while (message := receive_any(connection, "tracking"))["op"] == "action_feedback":
                answers += message["values"]["phase"] == "answer"
            ended = message
            assert answers >= 1  # the cup was tracked on the bag's frames before it ended
            assert ended["status"] == ABORTED
            assert "source ended" in ended["values"]["reason"] and "all 6 frames played" in ended["values"]["reason"]
            connection.send(goal("late", "find the cup"))
            late = receive(connection, "action_result", "late")
            assert late["status"] == ABORTED and "all 6 frames played" in late["values"]["reason"]
            connection.send(
                json.dumps(
                    {
                        "op": "call_service",
                        "id": "b",
                        "service": "/robokudo/beliefs",
                        "args": {"query": "find objects"},
                    }
                )
            )
            memory = receive(connection, "service_response")
            assert memory["result"] and memory["values"]["objects"]  # what was seen before the end is remembered
    finally:
        assert served.stop() == 0
