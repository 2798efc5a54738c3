"""A continuous goal served on a real looping recording, as a robot's program sees it: a track of a target nobody
in view ends ``target lost`` after its ``lost_after`` (the grabber sequence's three time-stamped frames restart their
stamps on every loop), with a reason about the target, not about frames the loop waited for."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from websockets.sync.client import connect

from tests.annotators.conftest import SHARED_DATA, require_folder
from tests.application.server.conftest import start_server
from tests.application.server.test_protocol import goal

pytestmark = pytest.mark.real_data

ABORTED = 6
GIVE_UP = 90.0
"""Seconds after which the goal is taken to never end (its lost_after is 1 s of frames): a hang guard."""


def test_a_track_of_nobody_on_a_looping_recording_ends_target_lost(tmp_path: Path) -> None:
    grabber = require_folder(SHARED_DATA / "pcl_grabber_sequences")
    served = start_server(tmp_path, "--input", str(grabber))
    try:
        with connect(served.url) as connection:
            connection.send(goal("follow", "track { human: {}, lost_after: 1s }"))
            result, deadline = None, time.monotonic() + GIVE_UP
            while result is None:
                assert time.monotonic() < deadline, "the goal never ended"
                message = json.loads(connection.recv(timeout=GIVE_UP))
                if message["op"] == "action_result" and message["id"] == "follow":
                    result = message
        reason = result["values"]["reason"]
        assert result["status"] == ABORTED, reason
        assert reason.startswith("target lost: the human not seen for "), reason
        assert "no frame was perceived" not in reason
    finally:
        assert served.stop() == 0
