"""The served shape (the paper's Fig. 4): a perceive pipeline reads the live stream, then the task slot; the engine
ticks idle between tasks, each task starts on a freshly perceived frame from the camera pointed at its region, and
a source that ends aborts the running task and refuses later ones with the reason."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from annotators.readers.frame_io import Frame
from annotators.readers.streams import KitchenCameraStream, PerceivedFrameReader, PlaybackStream
from annotators.simulation.kitchen_scene import render_kitchen
from robokudo.application.service import TASK_SLOT, AnsweringService, PerceptionFailedError, SourceEndedError
from robokudo.core.types import CameraInfo


@pytest.fixture
def served(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[AnsweringService]:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    camera = KitchenCameraStream(rate_hz=30)
    with AnsweringService.open(tmp_path / "beliefs.sqlite", hz=30, stream=camera) as service:
        service.run_in_background()
        yield service


def wait_for_ticks(service: AnsweringService, count: int) -> None:
    target = service.engine.tick_count + count
    deadline = time.monotonic() + 30
    while service.engine.tick_count < target and time.monotonic() < deadline:
        time.sleep(0.01)
    assert service.engine.tick_count >= target, "the engine stopped ticking"


def test_the_root_perceives_then_holds_the_task_and_ticks_idle_without_one(served: AnsweringService) -> None:
    root = served.engine.root
    assert [child.name for child in root.children] == ["perception", TASK_SLOT]
    assert served.engine.tasks.slot(TASK_SLOT).subtree.name == "idle"
    assert served.stream is not None
    delivered = served.stream.delivered
    wait_for_ticks(served, 10)
    assert served.stream.delivered > delivered  # idle ticks keep reading the camera


def test_a_task_starts_on_a_frame_from_the_camera_pointed_at_its_region(served: AnsweringService) -> None:
    outcome = served.answer("find milk in fridge")
    assert [(o.class_label, o.region) for o in outcome.answer.objects][:1] == [("lactose free milk", "fridge")]
    assert set(outcome.timing) == {"plan_ms", "wait_ms", "run_ms"} and min(outcome.timing.values()) >= 0
    first_step = outcome.tree.children[0]
    assert isinstance(first_step, PerceivedFrameReader)
    camera = outcome.tree.cas.view(CameraInfo)
    assert camera is not None and camera.frame_id == "kitchen/fridge"
    wait_for_ticks(served, 2)
    assert served.engine.tasks.slot(TASK_SLOT).subtree.name == "idle"  # the finished task was taken out
    cup = served.answer("find the red cup")
    assert cup.tree.cas.view(CameraInfo).frame_id == "kitchen/table"
    assert [o.class_label for o in cup.answer.objects] == ["cup"]


def test_a_continuous_task_sees_a_new_frame_on_every_run(served: AnsweringService) -> None:
    handle = served.start("track the red cup")
    stamps = []
    for answer in handle.answers():
        assert [o.class_label for o in answer.objects] == ["cup"]
        stamps.append(answer.objects[0].last_seen)  # the stamp of the frame the run saw it in
        if len(stamps) == 3:
            break
    handle.cancel()
    assert len(stamps) == 3, handle.reason
    assert len(set(stamps)) == 3  # every run perceived its own frame


def kitchen_recording(frames: int) -> Iterator[tuple[Frame, str]]:
    scene = render_kitchen("table")
    for index in range(frames):
        yield Frame(scene.color, scene.depth, scene.intrinsics, source="table", timestamp=float(index)), "kitchen"


def test_the_source_ending_aborts_the_running_task_and_refuses_later_ones(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    recording = PlaybackStream(lambda: kitchen_recording(4), name="four frames", rate_hz=4, loop=False)
    with AnsweringService.open(tmp_path / "beliefs.sqlite", hz=30, stream=recording) as service:
        handle = service.start("track the red cup")
        answers = list(handle.answers())
        assert handle.done and "source ended: four frames: all 4 frames played" in handle.reason
        assert 1 <= len(answers) <= 4
        assert service.source_ended is not None
        with pytest.raises(SourceEndedError, match="all 4 frames played"):
            service.answer("find the red cup")
        wait_for_ticks(service, 3)  # the engine keeps ticking; perception fails with the reason


def test_a_one_shot_task_on_an_ended_source_fails_with_the_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    recording = PlaybackStream(lambda: kitchen_recording(1), name="one frame", rate_hz=30, loop=False)
    with AnsweringService.open(tmp_path / "beliefs.sqlite", hz=30, stream=recording) as service:
        service.run_in_background()
        wait_for_ticks(service, 5)  # the single frame was read and the source ended meanwhile
        with pytest.raises((PerceptionFailedError, SourceEndedError), match="all 1 frames played"):
            service.answer("find the red cup")
