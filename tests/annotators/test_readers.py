"""Readers: the colour/depth pair layout (checked explicitly) and the built-in kitchen scene."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from py_trees.common import Status

from annotators.readers.frame_io import FrameError, read_camera_params, read_color_depth_pair
from annotators.readers.frame_readers import ColorDepthPairReader, KitchenSceneReader
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, ColorImage, DepthImage

PARAMS = {"img_width": 8, "img_height": 6, "fx": 10.0, "fy": 11.0, "x_offset": 4.0, "y_offset": 3.0}


def write_pair(folder: Path, frame: int = 0, size: tuple[int, int] = (6, 8), params: dict | None = None) -> None:
    """A tiny frame in the uoc layout: colour (BGR on disk), depth in mm, camera_params.json."""
    folder.mkdir(parents=True, exist_ok=True)
    color = np.zeros((6, 8, 3), dtype=np.uint8)
    color[..., 2] = 200  # red in BGR
    cv2.imwrite(str(folder / f"{frame:06d}-color.png"), color)
    depth = np.full(size, 1234, dtype=np.uint16)
    cv2.imwrite(str(folder / f"{frame:06d}-depth.png"), depth)
    (folder / "camera_params.json").write_text(json.dumps(params if params is not None else PARAMS))


def test_a_pair_is_decoded_to_rgb_metres_and_intrinsics(tmp_path: Path) -> None:
    write_pair(tmp_path, frame=7)
    frame = read_color_depth_pair(tmp_path, 7)
    assert frame.color.shape == (6, 8, 3) and tuple(frame.color[0, 0]) == (200, 0, 0)
    assert frame.depth.dtype == np.float32 and np.allclose(frame.depth, 1.234)
    assert (frame.intrinsics.fx, frame.intrinsics.cy, frame.intrinsics.width) == (10.0, 3.0, 8)


def test_depth_scale_comes_from_the_file_or_the_caller(tmp_path: Path) -> None:
    write_pair(tmp_path / "a", params={**PARAMS, "depth_scale": 0.0001})  # metres per unit (RealSense style)
    assert np.allclose(read_color_depth_pair(tmp_path / "a").depth, 0.1234)
    write_pair(tmp_path / "b", params={**PARAMS, "depth_scale": 5000})  # units per metre
    assert np.allclose(read_color_depth_pair(tmp_path / "b").depth, 1234 / 5000)
    assert np.allclose(read_color_depth_pair(tmp_path / "b", depth_scale=2000).depth, 0.617)


@pytest.mark.parametrize(
    ("setup", "message"),
    [
        (lambda p: None, "no such folder"),
        (lambda p: write_pair(p, frame=1), "missing .*000000-color.png"),
        (lambda p: (write_pair(p), (p / "000000-depth.png").unlink()), "missing .*000000-depth.png"),
        (lambda p: (write_pair(p), (p / "camera_params.json").unlink()), "missing camera parameters"),
        (lambda p: write_pair(p, size=(3, 8)), "sizes differ"),
        (lambda p: write_pair(p, params={**PARAMS, "fx": 0}), "invalid intrinsics"),
        (lambda p: write_pair(p, params={**PARAMS, "img_width": 16}), "intrinsics say 16x6"),
        (lambda p: write_pair(p, params={"fx": 1}), "bad camera parameters"),
        (lambda p: (write_pair(p), (p / "000000-color.png").write_bytes(b"not a png")), "cannot decode"),
    ],
)
def test_broken_folders_raise_a_frame_error_with_the_reason(tmp_path: Path, setup, message: str) -> None:
    folder = tmp_path / "frames"
    setup(folder)
    with pytest.raises(FrameError, match=message):
        read_color_depth_pair(folder, 0)


@pytest.mark.real_data
def test_camera_params_of_the_real_layout_are_understood(uoc_folder: Path) -> None:
    intrinsics, scale = read_camera_params(uoc_folder / "camera_params.json")
    assert (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy) == (612.937, 613.173, 322.549, 248.158)
    assert (intrinsics.width, intrinsics.height, scale) == (640, 480, None)


def test_the_pair_reader_decodes_once_and_shares_the_arrays(tmp_path: Path) -> None:
    write_pair(tmp_path)
    reader = ColorDepthPairReader(tmp_path)
    pipeline = Pipeline("p", [reader])
    pipeline.tick_once()
    first = pipeline.cas.view(ColorImage).image
    pipeline.tick_once()
    assert reader.status is Status.SUCCESS
    assert pipeline.cas.view(ColorImage).image is first
    assert pipeline.cas.view(CameraInfo).cam_to_world is None
    assert pipeline.cas.view(DepthImage).depth.shape == (6, 8)


def test_the_pair_reader_fails_with_the_reason(tmp_path: Path) -> None:
    reader = ColorDepthPairReader(tmp_path / "nowhere")
    Pipeline("p", [reader]).tick_once()
    assert reader.status is Status.FAILURE and "no such folder" in reader.feedback_message


def test_the_kitchen_reader_renders_once_per_view_with_the_camera_pose() -> None:
    reader = KitchenSceneReader()
    pipeline = Pipeline("p", [reader])
    pipeline.tick_once()
    scene = reader.last_scene
    assert reader.status is Status.SUCCESS and scene is not None and scene.view == "table"
    assert pipeline.cas.view(ColorImage).image is scene.color
    info = pipeline.cas.view(CameraInfo)
    assert info.cam_to_world is scene.cam_to_world and info.intrinsics.fx == scene.intrinsics.fx
    pipeline.tick_once()
    assert reader.last_scene is scene


def test_missing_real_data_skips_without_ci_and_fails_with_ci(tmp_path: Path, monkeypatch) -> None:
    from tests.annotators.conftest import require_folder

    assert require_folder(tmp_path) == tmp_path
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception):
        require_folder(tmp_path / "missing")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="missing"):
        require_folder(tmp_path / "missing")


def test_the_supported_inputs_a_user_is_shown_do_not_restrict_pcd_files_to_organized_ones(tmp_path: Path) -> None:
    from annotators.readers.choice import SUPPORTED_LAYOUTS, reader_choice

    cloud = tmp_path / "scan.pcd"
    cloud.write_text(
        "VERSION .7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 1 0\n0.1 0 1 0\n"
    )
    assert reader_choice(str(cloud)).name == "PcdReader"  # an unorganized cloud (HEIGHT 1) is an input
    (pcd_line,) = [line for line in SUPPORTED_LAYOUTS if ".pcd" in line]
    assert "unorganized" in pcd_line
    with pytest.raises(ValueError) as caught:
        reader_choice(str(tmp_path / "missing.pcd"))
    assert pcd_line in str(caught.value)
