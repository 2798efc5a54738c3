"""The Open3D RGB-D folder layout (color/ or image/, depth/, camera JSON, trajectory.log): folders made here with
known numbers, and Open3D's sample frames in ../shared/data/redwood_synthetic_open3d (read in place)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import open3d as o3d
import pytest
from py_trees.common import Status

from annotators.readers.choice import reader_choice, reader_for, recorded_frames
from annotators.readers.frame_io import FrameError
from annotators.readers.frame_readers import Open3dFolderReader
from annotators.readers.open3d_io import read_open3d_frame, read_trajectory
from annotators.readers.streams import stream_for
from annotators.readers.tum_io import PRIMESENSE_INTRINSICS
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, DepthImage
from tests.annotators.conftest import require_folder

SIZE = (48, 64)  # rows, columns of the folders made here
SMALL_CAMERA = {"width": 64, "height": 48, "intrinsic_matrix": [50.0, 0, 0, 0, 51.0, 0, 31.5, 23.5, 1]}
"""An Open3D camera JSON for SIZE (column-major: fx, 0, 0, 0, fy, 0, cx, cy, 1)."""


def make_folder(
    root: Path,
    frames: int = 2,
    color_folder: str = "color",
    intrinsics: dict | None = SMALL_CAMERA,
    size: tuple[int, int] = SIZE,
) -> Path:
    """An Open3D folder of ``frames`` frames: frame k's colour is k*10 grey, its depth 1500 + k mm."""
    (root / color_folder).mkdir(parents=True)
    (root / "depth").mkdir()
    for k in range(frames):
        cv2.imwrite(str(root / color_folder / f"{k:06d}.jpg"), np.full((*size, 3), 10 * k, np.uint8))
        cv2.imwrite(str(root / "depth" / f"{k:06d}.png"), np.full(size, 1500 + k, np.uint16))
    if intrinsics is not None:
        (root / "camera_intrinsic.json").write_text(json.dumps(intrinsics))
    return root


def pose_log(poses: list[np.ndarray]) -> str:
    """An Open3D trajectory.log of ``poses``."""
    lines = []
    for k, pose in enumerate(poses):
        lines.append(f"{k} {k} {k + 1}")
        lines += [" ".join(f"{v:.9f}" for v in row) for row in pose]
    return "\n".join(lines) + "\n"


def test_a_recorder_folder_is_read_with_its_camera_json_column_major(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "rec", frames=3)
    choice = reader_choice(str(folder), 2)
    assert (choice.name, dict(choice.parameters)) == ("Open3dFolderReader", {"folder": str(folder), "frame": 2})
    frame = choice.create().load()
    assert (frame.intrinsics.fx, frame.intrinsics.fy, frame.intrinsics.cx, frame.intrinsics.cy) == (50, 51, 31.5, 23.5)
    assert frame.depth[0, 0] == pytest.approx(1.502)  # millimetres: frame 2 holds 1502
    assert frame.cam_to_world is None
    assert len(recorded_frames(str(folder))) == 3


def test_the_reconstruction_systems_image_folder_and_the_default_camera(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "scene", color_folder="image", intrinsics=None, size=(480, 640))
    frame = reader_for(str(folder), 1).load()
    assert frame.intrinsics == PRIMESENSE_INTRINSICS
    assert frame.color[0, 0, 0] == pytest.approx(10, abs=2)  # frame 1, not frame 0


def test_frames_pair_in_natural_order(tmp_path: Path) -> None:
    folder = tmp_path / "natural"
    (folder / "color").mkdir(parents=True)
    (folder / "depth").mkdir()
    for k in (2, 10):
        cv2.imwrite(str(folder / "color" / f"frame{k}.png"), np.full((*SIZE, 3), k, np.uint8))
        cv2.imwrite(str(folder / "depth" / f"frame{k}.png"), np.full(SIZE, 1000 + k, np.uint16))
    (folder / "camera_intrinsic.json").write_text(json.dumps(SMALL_CAMERA))
    first = read_open3d_frame(folder, 0)
    assert first.color[0, 0, 0] == 2 and first.depth[0, 0] == pytest.approx(1.002)


def test_a_trajectory_gives_every_frame_its_pose(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "walk")
    poses = [np.eye(4), np.eye(4)]
    poses[1][:3, 3] = (0.5, -0.25, 2.0)
    (folder / "trajectory.log").write_text(pose_log(poses))
    reader = Open3dFolderReader(folder, frame=1)
    pipeline = Pipeline("read", [reader])
    pipeline.tick_once()
    assert reader.status is Status.SUCCESS, reader.feedback_message
    info = pipeline.cas.view(CameraInfo)
    assert np.allclose(info.cam_to_world, poses[1])
    assert info.recording == str(folder.resolve())  # one continuous recording: its frames share the world


@pytest.mark.parametrize(
    ("log", "message"),
    [
        ("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 x\n0 0 0 1\n", "line 4: expected 4 numbers"),
        ("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n", "expected 5 per pose"),
        ("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 2 1\n", "line 5: a pose's last row must be 0 0 0 1"),
    ],
)
def test_a_broken_trajectory_is_refused_naming_the_line(tmp_path: Path, log: str, message: str) -> None:
    path = tmp_path / "trajectory.log"
    path.write_text(log)
    with pytest.raises(FrameError, match=message):
        read_trajectory(path)


def test_a_trajectory_for_other_frames_fails_the_reader_with_the_reason(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "short")
    (folder / "trajectory.log").write_text(pose_log([np.eye(4)]))
    reader = Open3dFolderReader(folder, frame=0)
    Pipeline("read", [reader]).tick_once()
    assert reader.status is Status.FAILURE
    assert "holds 1 poses for 2 frames" in reader.feedback_message


def test_unpaired_folders_and_missing_frames_say_why(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "uneven")
    (folder / "depth" / "000001.png").unlink()
    with pytest.raises(ValueError, match="2 colour images in color/ but 1 depth images"):
        reader_choice(str(folder), 0)
    whole = make_folder(tmp_path / "whole")
    with pytest.raises(ValueError, match="holds 2 colour/depth frames, no frame 2"):
        reader_choice(str(whole), 2)


def test_a_match_file_pairs_the_frames_and_a_bad_line_is_named(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "matched", frames=3)
    (folder / "rgbd.match").write_text("depth/000002.png color/000000.jpg\ndepth/000000.png color/000002.jpg\n")
    first = read_open3d_frame(folder, 0)
    assert first.depth[0, 0] == pytest.approx(1.502) and first.color[0, 0, 0] == pytest.approx(0, abs=2)
    assert len(recorded_frames(str(folder))) == 2
    (folder / "rgbd.match").write_text("depth/000000.png color/000000.jpg\ndepth/000001.png\n")
    with pytest.raises(FrameError, match=r"rgbd.match, line 2: expected 'depth-file colour-file'"):
        read_open3d_frame(folder, 0)


def test_a_malformed_camera_json_is_refused(tmp_path: Path) -> None:
    folder = make_folder(tmp_path / "badcam", intrinsics={"width": 64, "height": 48, "intrinsic_matrix": [1, 2]})
    with pytest.raises(FrameError, match="intrinsic_matrix has 2 numbers, expected 9"):
        read_open3d_frame(folder, 0)


# ------------------------------------------------------------------------------------ Open3D's sample frames


def floor_in_world(folder: Path, frame: int) -> tuple[np.ndarray, float, np.ndarray]:
    """The largest plane of a frame (the living room's floor): its unit normal and offset in the world (by the
    frame's pose), and its normal in the camera frame."""
    read = read_open3d_frame(folder, frame)
    k = read.intrinsics
    rows, cols = np.nonzero(read.depth > 0)
    z = read.depth[rows, cols].astype(np.float64)
    points = np.column_stack([(cols - k.cx) * z / k.fx, (rows - k.cy) * z / k.fy, z])
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    o3d.utility.random.seed(7)
    (a, b, c, d), _ = cloud.segment_plane(0.01, 3, 300)
    normal = np.array([a, b, c])
    rotation, translation = read.cam_to_world[:3, :3], read.cam_to_world[:3, 3]
    world = rotation @ normal
    offset = d - world @ translation
    sign = 1.0 if world[1] >= 0 else -1.0
    return sign * world, sign * offset, normal


@pytest.mark.real_data
def test_open3ds_sample_frames_are_read_with_their_poses(shared_data: Path) -> None:
    """The README of the data: 5 frames, PrimeSense intrinsics in camera_primesense.json, depth in mm (frame 0:
    0.955-2.702 m). Seen from frames 0 and 4 the floor is one plane of the world, though not of the camera."""
    folder = require_folder(shared_data / "redwood_synthetic_open3d")
    assert [c.name for c in recorded_frames(str(folder))] == ["Open3dFolderReader"] * 5
    reader = reader_for(str(folder), 0)
    pipeline = Pipeline("read", [reader])
    pipeline.tick_once()
    depth = pipeline.cas.view(DepthImage).depth
    assert depth[depth > 0].min() == pytest.approx(0.955) and depth.max() == pytest.approx(2.702)
    assert pipeline.cas.view(CameraInfo).intrinsics == PRIMESENSE_INTRINSICS
    first_normal, first_offset, first_in_camera = floor_in_world(folder, 0)
    last_normal, last_offset, last_in_camera = floor_in_world(folder, 4)
    assert np.degrees(np.arccos(min(1.0, abs(first_normal @ last_normal)))) < 1.0
    assert abs(first_offset - last_offset) < 0.01
    assert np.degrees(np.arccos(min(1.0, abs(first_in_camera @ last_in_camera)))) > 2.0  # the camera moved


@pytest.mark.real_data
def test_a_playback_stream_of_the_sample_frames_delivers_their_poses(shared_data: Path) -> None:
    """What a long-running server perceives from: each delivered frame's camera info carries the trajectory's pose."""
    folder = require_folder(shared_data / "redwood_synthetic_open3d")
    poses = read_trajectory(folder / "trajectory.log")
    stream = stream_for(str(folder), rate_hz=1000.0, loop=False)
    try:
        delivered = [stream.next_frame() for _ in range(len(poses))]
    finally:
        stream.close()
    assert all(np.array_equal(d.camera.cam_to_world, pose) for d, pose in zip(delivered, poses, strict=True))
    assert {d.camera.recording for d in delivered} == {str(folder.resolve())}
