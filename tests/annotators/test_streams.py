"""Frame streams: the kitchen camera at its rate and pointed where asked; recordings played in order, looped or once
(then a clear "source ended"); a bag played at its recorded rate; the stream reader in a pipeline.

Rates are checked loosely by counting frames over a window (never as timing asserts of single frames).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.readers.frame_io import Frame, read_color_depth_pair
from annotators.readers.frame_readers import KITCHEN_RECORDING
from annotators.readers.streams import (
    FrameStream,
    KitchenCameraStream,
    SourceEndedError,
    StreamReader,
    recorded_stream,
    stream_for,
)
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, PointCloud
from tests.annotators.bag_writing import write_bag
from tests.annotators.conftest import require_folder


def frames_within(stream: FrameStream, seconds: float) -> int:
    """How many frames the stream delivers in a window of ``seconds`` (after its first frame)."""
    stream.next_frame()
    start, count = time.monotonic(), 0
    while time.monotonic() - start < seconds:
        stream.next_frame()
        count += 1
    return count


def test_the_kitchen_camera_produces_frames_at_its_rate() -> None:
    fast = frames_within(KitchenCameraStream(rate_hz=40.0), 1.0)
    slow = frames_within(KitchenCameraStream(rate_hz=5.0), 1.0)
    assert 20 <= fast <= 45, fast
    assert 3 <= slow <= 7, slow
    assert fast > 3 * slow


def test_the_kitchen_camera_skips_frames_a_slow_consumer_missed() -> None:
    # 10 Hz: the non-blocking call below must come before the next frame is due, also on a loaded machine
    stream = KitchenCameraStream(rate_hz=10.0)
    first = stream.next_frame()
    time.sleep(0.65)
    later = stream.next_frame()
    assert first is not None and later is not None
    assert later.sequence == first.sequence + 1 and later.index >= first.index + 5
    assert stream.next_frame(block=False) is None  # the next frame is not due yet


def test_the_kitchen_camera_can_be_pointed_at_a_region() -> None:
    stream = KitchenCameraStream(rate_hz=50.0)
    table = stream.next_frame()
    assert stream.look_at("Fridge") == "fridge"
    fridge = stream.next_frame()
    assert table is not None and fridge is not None
    assert (table.camera.frame_id, fridge.camera.frame_id) == ("kitchen/table", "kitchen/fridge")
    assert fridge.camera.recording == table.camera.recording == KITCHEN_RECORDING
    assert not np.allclose(table.camera.cam_to_world, fridge.camera.cam_to_world)
    with pytest.raises(ValueError, match="garage"):
        stream.look_at("garage")
    with pytest.raises(ValueError, match="attic"):
        stream.set_view("attic")
    assert stream.view == "fridge"


def test_closing_wakes_a_waiting_reader_with_source_ended() -> None:
    stream = KitchenCameraStream(rate_hz=0.2)
    stream.next_frame()
    outcome: list[BaseException] = []

    def wait() -> None:
        try:
            stream.next_frame()
        except SourceEndedError as error:
            outcome.append(error)

    waiter = threading.Thread(target=wait)
    waiter.start()
    time.sleep(0.1)
    stream.close()
    waiter.join(timeout=5.0)
    assert not waiter.is_alive() and len(outcome) == 1 and "closed" in str(outcome[0])


@pytest.mark.real_data
def test_a_recording_played_once_plays_in_order_then_ends(uoc_folder: Path) -> None:
    stream = recorded_stream(str(uoc_folder), rate_hz=100.0, loop=False)
    played = [stream.next_frame() for _ in range(5)]
    assert [f.index for f in played if f] == [0, 1, 2, 3, 4]
    expected = read_color_depth_pair(uoc_folder, 3)
    assert played[3] is not None and np.array_equal(played[3].frame.depth, expected.depth)
    assert played[3].camera.recording == f"{uoc_folder.resolve()}#000003"
    for _ in range(2):  # and stays ended
        with pytest.raises(SourceEndedError, match="all 5 frames played"):
            stream.next_frame()
    assert stream.ended


@pytest.mark.real_data
def test_a_looped_recording_starts_over(uoc_folder: Path) -> None:
    stream = recorded_stream(str(uoc_folder), rate_hz=100.0)
    indices = [f.index for f in (stream.next_frame() for _ in range(12)) if f]
    assert indices == [0, 1, 2, 3, 4, 0, 1, 2, 3, 4, 0, 1]
    assert stream.loops == 2 and not stream.ended


@pytest.fixture(scope="module")
def uoc_bag(uoc_folder: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    frames: list[Frame] = [read_color_depth_pair(uoc_folder, i) for i in range(3)]
    return write_bag(tmp_path_factory.mktemp("bag") / "frames", frames, ros1=False, period_ns=150_000_000)


@pytest.mark.real_data
def test_a_bag_plays_at_its_recorded_rate_with_its_stamps(uoc_bag: Path) -> None:
    stream = recorded_stream(str(uoc_bag), loop=False)
    start = time.monotonic()
    played = [stream.next_frame() for _ in range(3)]
    elapsed = time.monotonic() - start
    assert [f.camera.timestamp for f in played if f] == pytest.approx([1.7e9, 1.7e9 + 0.15, 1.7e9 + 0.3])
    assert elapsed >= 0.29  # two recorded gaps of 0.15 s; a lower bound only
    with pytest.raises(SourceEndedError):
        stream.next_frame()


@pytest.mark.real_data
def test_the_stream_reader_feeds_a_pipeline_until_the_source_ends(uoc_bag: Path) -> None:
    reader = StreamReader(stream_for(str(uoc_bag), rate_hz=100.0, loop=False))
    pipeline = Pipeline("perceive", [reader, PointCloudGenerator()])
    sequences = []
    for _ in range(3):
        pipeline.tick_once()
        assert pipeline.status is Status.SUCCESS, reader.feedback_message
        assert pipeline.cas.view(PointCloud) is not None
        assert pipeline.cas.view(CameraInfo).recording == str(uoc_bag.resolve())
        assert reader.last_frame is not None
        sequences.append(reader.last_frame.sequence)
    assert sequences == [0, 1, 2]
    pipeline.tick_once()
    assert reader.status is Status.FAILURE and reader.ended
    assert reader.feedback_message.startswith("source ended:")


def test_a_stream_reader_that_does_not_wait_runs_until_a_new_frame_is_due() -> None:
    camera = KitchenCameraStream(rate_hz=2.0)
    camera.prepare()
    reader = StreamReader(camera, wait=False)
    pipeline = Pipeline("perceive", [reader])
    pipeline.tick_once()
    first = reader.last_frame
    assert reader.status is Status.SUCCESS
    assert first is not None and first.camera.frame_id == "kitchen/table"
    pipeline.tick_once()  # a new run: the next frame is not due yet, and the last one is not handed out again
    assert reader.status is Status.RUNNING and reader.feedback_message == "waiting for the next frame"
    assert reader.last_frame is first
    deadline = time.monotonic() + 5
    while reader.status is Status.RUNNING and time.monotonic() < deadline:
        time.sleep(0.02)
        pipeline.tick_once()
    assert reader.status is Status.SUCCESS and reader.last_frame is not first
    assert reader.last_frame is not None and reader.last_frame.sequence == first.sequence + 1


def test_bad_rates_and_paths_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="positive"):
        stream_for(None, rate_hz=0.0)
    with pytest.raises(ValueError, match="positive"):
        stream_for(str(tmp_path), rate_hz=float("nan"))
    with pytest.raises(ValueError, match="no known layout"):
        stream_for(str(tmp_path))


@pytest.mark.real_data
def test_a_grabber_sequence_plays_in_time_order_at_its_recorded_rate(shared_data: Path) -> None:
    folder = require_folder(shared_data / "pcl_grabber_sequences")
    stream = recorded_stream(str(folder), loop=False)
    start = time.monotonic()
    played = [stream.next_frame() for _ in range(3)]
    elapsed = time.monotonic() - start
    stamps = [f.camera.timestamp for f in played if f]
    assert stamps == sorted(stamps) and len(set(stamps)) == 3
    assert elapsed >= 0.95 * (stamps[-1] - stamps[0])  # the recorded gaps (about 0.25 s each); a lower bound only
    assert {f.camera.recording for f in played if f} == {str(folder.resolve())}
    with pytest.raises(SourceEndedError, match="all 3 frames played"):
        stream.next_frame()


def test_a_scripted_person_walks_through_the_kitchen_stream_and_each_frame_has_its_ground_truth() -> None:
    from annotators.simulation.kitchen_person import PERSON_OBJECT_ID, Motion, PersonScript

    walk = PersonScript((Motion("walk", 0.6, ((-0.6, 0.8), (0.6, 0.8))),))
    stream = KitchenCameraStream(rate_hz=20.0, view="person", person=walk)
    first = stream.next_frame()
    time.sleep(0.4)
    later = stream.next_frame()
    assert first is not None and later is not None
    poses = [stream.pose_at_stamp(f.camera.timestamp) for f in (first, later)]
    assert all(p is not None for p in poses)
    assert poses[1].position[0] > poses[0].position[0] + 0.3  # the figure walked between the frames
    assert np.any(stream.last_scene.object_ids == PERSON_OBJECT_ID)  # and is in the picture
    assert not np.array_equal(first.frame.depth, later.frame.depth)


def test_without_a_person_the_kitchen_stream_has_no_person_views() -> None:
    with pytest.raises(ValueError, match="person"):
        KitchenCameraStream(view="person")
