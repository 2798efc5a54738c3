"""Unorganized clouds (HEIGHT 1) are read through a virtual camera image and segmented like organized ones.

A shared mOSD learn scene is turned into an unorganized cloud here: its finite points, shuffled, written as a binary
PCD (label x y z rgba) into a temporary folder. Read back with the default camera, with a camera_params.json beside
it, and with other intrinsics given, the tabletop tree finds the same labelled objects as from the organized file.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.readers.frame_readers import PcdReader
from annotators.readers.pcd_io import DEFAULT_INTRINSICS, read_pcd
from robokudo.core.engine import Engine
from robokudo.core.types import CameraIntrinsics, ObjectHypothesis
from tests.annotators.conftest import SHARED_DATA, require_folder
from trees.tabletop import create_pipeline

pytestmark = pytest.mark.real_data


def write_unorganized(path: Path, organized: Path, seed: int = 0) -> int:
    """The finite points of an organized PCD, shuffled, as a binary HEIGHT 1 PCD at ``path``; their count."""
    frame = read_pcd(organized)
    valid = np.isfinite(frame.points[..., 2])
    order = np.random.default_rng(seed).permutation(np.count_nonzero(valid))
    points = frame.points[valid][order]
    rgb = frame.color[valid][order].astype(np.uint32)
    record = np.zeros(
        points.shape[0], dtype=[("label", "<u4"), ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgba", "<u4")]
    )
    record["label"] = frame.labels[valid][order]
    record["x"], record["y"], record["z"] = points.T
    record["rgba"] = (255 << 24) | (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
    header = (
        "VERSION 0.7\nFIELDS label x y z rgba\nSIZE 4 4 4 4 4\nTYPE U F F F U\nCOUNT 1 1 1 1 1\n"
        f"WIDTH {points.shape[0]}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points.shape[0]}\nDATA binary\n"
    )
    path.write_bytes(header.encode("ascii") + record.tobytes())
    return points.shape[0]


def found_objects(reader: PcdReader) -> tuple[int, dict[int, float]]:
    """The number of hypotheses of the tabletop tree and, per labelled object, the best point IoU of one of them."""
    root = create_pipeline(reader)
    assert Engine(root).tick() is Status.SUCCESS, [(c.name, c.feedback_message) for c in root.children]
    hypotheses = root.cas.annotations(ObjectHypothesis)
    frame = reader.last_frame
    labels, valid = frame.labels.astype(int), np.isfinite(frame.points[..., 2])
    best = {}
    for object_id in sorted({label // 10 for label in np.unique(labels) if label >= 20}):
        truth = valid & (labels >= 20) & (labels // 10 == object_id)
        best[object_id] = max(np.count_nonzero(h.mask & truth) / np.count_nonzero(h.mask | truth) for h in hypotheses)
    return len(hypotheses), best


@pytest.fixture(scope="module")
def learn() -> Path:
    return require_folder(SHARED_DATA / "pcl_mosd_tabletop" / "learn")


@pytest.mark.parametrize("scene", ["learn0", "learn17"])
def test_an_unorganized_scene_gives_the_objects_of_the_organized_one(tmp_path: Path, learn: Path, scene: str) -> None:
    organized = learn / f"{scene}.pcd"
    written = write_unorganized(tmp_path / f"{scene}.pcd", organized)
    frame = read_pcd(tmp_path / f"{scene}.pcd")
    assert frame.intrinsics == DEFAULT_INTRINSICS and frame.depth.shape == (480, 640)
    assert np.count_nonzero(np.isfinite(frame.points[..., 2])) == written  # mOSD's camera is the default one
    expected_count, expected = found_objects(PcdReader(organized))
    count, found = found_objects(PcdReader(tmp_path / f"{scene}.pcd"))
    assert count == expected_count and found.keys() == expected.keys()
    assert all(iou >= 0.5 for iou in found.values()), found
    assert all(abs(found[key] - expected[key]) < 0.02 for key in found), (found, expected)


def test_camera_params_beside_or_given_intrinsics_make_the_virtual_camera(tmp_path: Path, learn: Path) -> None:
    write_unorganized(tmp_path / "scene.pcd", learn / "learn0.pcd")
    # a wider virtual camera than the one that took the scene: fewer pixels, the same objects
    (tmp_path / "camera_params.json").write_text(
        json.dumps({"img_width": 480, "img_height": 360, "fx": 400.0, "fy": 400.0, "x_offset": 240, "y_offset": 180})
    )
    reader = PcdReader(tmp_path / "scene.pcd")
    count, found = found_objects(reader)
    assert reader.last_frame.depth.shape == (360, 480) and reader.last_frame.intrinsics.fx == 400.0
    assert count == 2 and all(iou >= 0.5 for iou in found.values()), found
    given = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)
    count, found = found_objects(PcdReader(tmp_path / "scene.pcd", intrinsics=given))  # given beats the file
    assert count == 2 and all(iou >= 0.5 for iou in found.values()), found
