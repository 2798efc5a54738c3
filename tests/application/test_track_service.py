"""A continuous goal on the served kitchen: an answer per frame with the tracked target, ended by a cancel (reason
"cancelled") or by its target being lost (reason "target lost: ... not seen for X s"); the same over the socket."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from websockets.sync.client import connect

from annotators.readers.streams import KitchenCameraStream
from robokudo.application.service import AnsweringService
from robokudo.core.loop import Loop
from tests.application.server.conftest import Served, start_server

WAIT = 120.0


@pytest.fixture
def served(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[AnsweringService]:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    with AnsweringService.open(tmp_path / "beliefs.sqlite", hz=30, stream=KitchenCameraStream(rate_hz=30)) as service:
        service.run_in_background()
        yield service


def test_tracking_a_cup_answers_each_frame_with_its_track_until_cancelled(served: AnsweringService) -> None:
    handle = served.start("track the red cup")
    assert isinstance(handle.tree, Loop)
    answers = []
    for answer in handle.answers():
        answers.append(answer)
        if len(answers) == 4:
            break
    handle.cancel()
    assert len(answers) == 4, handle.reason
    assert handle.done and handle.reason == "cancelled"
    tracks = [a.track for a in answers]
    assert all(t is not None and t.seen and t.tracker == "ObjectTracker" and t.frame == "world" for t in tracks)
    assert {a.objects[0].id for a in answers} == {tracks[0].object_id}  # one cup, the belief the track follows
    first, last = tracks[0].position, tracks[-1].position
    assert max(abs(a - b) for a, b in zip(first, last, strict=True)) < 0.02  # it stands still
    cup = answers[-1].objects[0].pose.position
    assert max(abs(a - b) for a, b in zip(cup, last, strict=True)) < 0.05
    assert handle.runs >= 4 and not handle.timed_out
    assert served.task_tree is not None and served.task_tree.name == "idle"


def test_a_target_never_seen_is_lost_after_lost_after_with_the_reason(served: AnsweringService) -> None:
    handle = served.start("track { human: {}, lost_after: 0.5s }")  # the kitchen holds nobody
    assert handle.wait(WAIT), "the task did not end"
    assert handle.reason.startswith("target lost: the human not seen for "), handle.reason
    unseen = float(handle.reason.split("not seen for ")[1].split(" s")[0])
    assert unseen >= 0.5  # longer than 0.5 s, shown to 10 ms
    assert "lost after 0.5 s" in handle.reason and "DepthPeopleDetector" in handle.reason
    assert handle.runs >= 2


def test_the_service_default_applies_when_the_query_gives_no_lost_after(tmp_path: Path) -> None:
    stream = KitchenCameraStream(rate_hz=30)
    with AnsweringService.open(tmp_path / "b.sqlite", hz=30, stream=stream, lost_after=0.3) as service:
        handle = service.start("track the person")
        assert handle.wait(WAIT)
        assert "lost after 0.3 s" in handle.reason, handle.reason
    with pytest.raises(ValueError, match="lost_after"):
        AnsweringService.open(tmp_path / "c.sqlite", lost_after=-1.0)


def _goal(goal_id: str, query: str) -> str:
    return json.dumps({"op": "send_action_goal", "id": goal_id, "action": "/robokudo/query", "args": {"query": query}})


def _until_result(connection: object, goal_id: str) -> tuple[list[dict], dict]:
    feedback = []
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        message = json.loads(connection.recv(timeout=WAIT))  # type: ignore[attr-defined]
        if message.get("id") != goal_id:
            continue
        if message["op"] == "action_feedback":
            feedback.append(message["values"])
        elif message["op"] == "action_result":
            return feedback, message
    raise AssertionError(f"no result for {goal_id}")


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    served = start_server(tmp_path_factory.mktemp("track-served"), "--lost-after", "30")
    yield served
    served.stop()


def test_over_the_socket_a_lost_target_aborts_and_a_cancel_cancels(server: Served) -> None:
    with connect(server.url) as connection:
        connection.send(_goal("nobody", "track { human: {}, lost_after: 0.5s }"))
        _, result = _until_result(connection, "nobody")
        assert result["status"] == 6, result
        assert result["values"]["reason"].startswith("target lost: the human not seen for ")
        connection.send(_goal("cup", "track the red cup"))
        answers = []
        deadline = time.monotonic() + WAIT
        while len(answers) < 2 and time.monotonic() < deadline:
            message = json.loads(connection.recv(timeout=WAIT))
            if message["op"] == "action_feedback" and message["values"].get("phase") == "answer":
                answers.append(message["values"]["answer"])
        assert len(answers) == 2
        assert all(a["track"]["seen"] and a["track"]["object_id"] == a["objects"][0]["id"] for a in answers)
        connection.send(json.dumps({"op": "cancel_action_goal", "id": "cup", "action": "/robokudo/query"}))
        _, result = _until_result(connection, "cup")
        assert result["status"] == 5, result
