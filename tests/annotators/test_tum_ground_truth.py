"""A TUM sequence's groundtruth.txt gives its frames their camera poses (sequences made here, with known poses), also
through a playback stream, which reads the sequence's lists once for all its frames."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from py_trees.common import Status

from annotators.readers.choice import reader_for, recorded_frames
from annotators.readers.frame_io import FrameError
from annotators.readers.frame_readers import TumSequenceReader
from annotators.readers.streams import stream_for
from annotators.readers.tum_io import read_ground_truth
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo

QUARTER_TURN_ABOUT_Z = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))  # x, y, z, w


def write_sequence(folder: Path, color_times: list[float], ground_truth: str | None) -> Path:
    """A TUM sequence folder: one 640x480 pair per colour time (depth 2 ms later), and ``ground_truth`` as is."""
    (folder / "rgb").mkdir(parents=True)
    (folder / "depth").mkdir()
    rgb, depth = ["# timestamp filename"], ["# timestamp filename"]
    for k, stamp in enumerate(color_times):
        cv2.imwrite(str(folder / "rgb" / f"{k}.png"), np.zeros((480, 640, 3), np.uint8))
        cv2.imwrite(str(folder / "depth" / f"{k}.png"), np.full((480, 640), 5000, np.uint16))
        rgb.append(f"{stamp:.6f} rgb/{k}.png")
        depth.append(f"{stamp + 0.002:.6f} depth/{k}.png")
    (folder / "rgb.txt").write_text("\n".join(rgb) + "\n")
    (folder / "depth.txt").write_text("\n".join(depth) + "\n")
    if ground_truth is not None:
        (folder / "groundtruth.txt").write_text(ground_truth)
    return folder


def camera_pose(folder: Path, frame: int) -> np.ndarray | None:
    reader = reader_for(str(folder), frame)
    assert isinstance(reader, TumSequenceReader)
    pipeline = Pipeline("read", [reader])
    pipeline.tick_once()
    assert reader.status is Status.SUCCESS, reader.feedback_message
    return pipeline.cas.view(CameraInfo).cam_to_world


def test_each_frame_gets_the_pose_nearest_its_colour_image(tmp_path: Path) -> None:
    x, y, z, w = QUARTER_TURN_ABOUT_Z
    ground_truth = (
        "# timestamp tx ty tz qx qy qz qw\n"
        f"10.030 9 9 9 0 0 0 1\n10.015 1 2 3 {x} {y} {z} {w}\n"  # out of order: the nearer one (15 ms) wins
        "20.500 5 5 5 0 0 0 1\n"
    )
    folder = write_sequence(tmp_path / "seq", [10.0, 20.0], ground_truth)
    pose = camera_pose(folder, 0)
    assert pose is not None
    # the camera's x axis (right) points along the world's y after a quarter turn about z, and sits at (1, 2, 3)
    assert np.allclose(pose @ np.array([1.0, 0.0, 0.0, 1.0]), (1.0, 3.0, 3.0, 1.0))
    assert camera_pose(folder, 1) is None  # the nearest ground truth is 0.5 s away: no pose rather than a wrong one


def test_a_sequence_without_ground_truth_has_no_pose(tmp_path: Path) -> None:
    assert camera_pose(write_sequence(tmp_path / "plain", [1.0], None), 0) is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1.0 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 1\n", "groundtruth.txt:2: expected 'timestamp tx ty tz qx qy qz qw'"),
        ("# header\n1.0 0 0 0 0 0 0 0\n", "groundtruth.txt:2: the orientation quaternion is zero"),
        ("1.0 0 0 nan 0 0 0 1\n", "groundtruth.txt:1: expected"),
    ],
)
def test_a_malformed_ground_truth_names_its_line(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "groundtruth.txt"
    path.write_text(text)
    with pytest.raises(FrameError, match=message):
        read_ground_truth(path)


def test_a_playback_stream_delivers_each_frames_pose_from_the_lists_it_read_once(tmp_path: Path) -> None:
    x, y, z, w = QUARTER_TURN_ABOUT_Z
    lines = ["# timestamp tx ty tz qx qy qz qw"] + [f"{10.0 + k:.3f} {k} 0 0 {x} {y} {z} {w}" for k in range(3)]
    folder = write_sequence(tmp_path / "seq", [10.0, 11.0, 12.0], "\n".join(lines) + "\n")
    choices = recorded_frames(str(folder))
    assert len({id(choice.parameters["opened"]) for choice in choices}) == 1  # one reading shared by all frames
    stream = stream_for(str(folder), rate_hz=1000.0, loop=False)
    try:
        first = stream.next_frame()
        (folder / "groundtruth.txt").unlink()  # the stream goes on from the lists it read when it started
        delivered = [first] + [stream.next_frame() for _ in range(2)]
    finally:
        stream.close()
    positions = [d.camera.cam_to_world[:3, 3] for d in delivered]
    assert np.allclose(positions, [(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    assert camera_pose(folder, 1) is None  # a reader alone reads the lists as they are now
