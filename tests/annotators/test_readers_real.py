"""Every reader on its shared real data: the README's intrinsics and depth scale put a known pixel at its 3-D point.

The expected point is computed here from the raw file value and the constants the data's README gives, so a wrong
depth scale, principal point or focal length in a reader shows as a miss of more than 1 mm.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import open3d as o3d
import pytest
from py_trees.common import Status

from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.readers.choice import reader_for, reader_name_for
from annotators.readers.frame_readers import (
    ColorDepthPairReader,
    PcdReader,
    TiffSequenceReader,
    TumPairReader,
    TumSequenceReader,
)
from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, ColorImage, PointCloud
from tests.annotators.conftest import require_folder

pytestmark = pytest.mark.real_data

PIXELS = ((400, 300), (200, 350), (320, 240))


def cloud_of(reader: Annotator) -> tuple[Pipeline, PointCloud]:
    """Run the reader (and the cloud generator unless it writes the cloud itself); the pipeline and its cloud."""
    nodes = [reader] if PointCloud in reader.outputs else [reader, PointCloudGenerator()]
    pipeline = Pipeline("read", nodes)
    pipeline.tick_once()
    assert all(node.status is Status.SUCCESS for node in nodes), [n.feedback_message for n in nodes]
    return pipeline, pipeline.cas.view(PointCloud)


def expected_point(raw: float, scale: float, fx: float, fy: float, cx: float, cy: float, u: int, v: int) -> np.ndarray:
    z = raw / scale
    return np.array([(u - cx) / fx * z, (v - cy) / fy * z, z])


def assert_pixels_land(cloud: PointCloud, raw_depth: np.ndarray, scale: float, k: tuple[float, ...]) -> None:
    for u, v in PIXELS:
        assert raw_depth[v, u] > 0, f"pick another pixel: ({u}, {v}) has no depth"
        point = cloud.points[v, u].astype(np.float64)
        error = np.linalg.norm(point - expected_point(float(raw_depth[v, u]), scale, *k, u, v))
        assert error < 0.001, f"pixel ({u}, {v}) is {1000 * error:.2f} mm off"


def test_uoc_pairs(uoc_folder: Path) -> None:
    pipeline, cloud = cloud_of(ColorDepthPairReader(uoc_folder, frame=3))
    raw = cv2.imread(str(uoc_folder / "000003-depth.png"), cv2.IMREAD_UNCHANGED)
    assert_pixels_land(cloud, raw, 1000.0, (612.937, 613.173, 322.549, 248.158))
    assert pipeline.cas.view(CameraInfo).cam_to_world is None


def test_tum_pair(shared_data: Path) -> None:
    folder = require_folder(shared_data / "tum_rgbd_sample_open3d")
    pipeline, cloud = cloud_of(TumPairReader(folder / "TUM_color.png"))
    raw = cv2.imread(str(folder / "TUM_depth.png"), cv2.IMREAD_UNCHANGED)
    assert_pixels_land(cloud, raw, 5000.0, (525.0, 525.0, 319.5, 239.5))
    bgr = cv2.imread(str(folder / "TUM_color.png"))
    assert np.array_equal(pipeline.cas.view(ColorImage).image, bgr[..., ::-1])  # RGB order
    assert pipeline.cas.view(CameraInfo).cam_to_world is None


def test_tum_sequence_associates_by_time_stamp(shared_data: Path, tmp_path: Path) -> None:
    """A sequence folder listing the shared pair (read in place) between two unmatched entries."""
    folder = require_folder(shared_data / "tum_rgbd_sample_open3d")
    (tmp_path / "rgb.txt").write_text(
        f"# timestamp filename\n5.000 {folder / 'TUM_color.png'}\n1.000 rgb/unmatched.png\n"
    )
    (tmp_path / "depth.txt").write_text(f"# timestamp filename\n5.012 {folder / 'TUM_depth.png'}\n9.0 depth/x.png\n")
    assert reader_name_for(str(tmp_path)) == "TumSequenceReader"
    reader = reader_for(str(tmp_path), 0)
    pipeline, cloud = cloud_of(reader)
    raw = cv2.imread(str(folder / "TUM_depth.png"), cv2.IMREAD_UNCHANGED)
    assert_pixels_land(cloud, raw, 5000.0, (525.0, 525.0, 319.5, 239.5))
    assert pipeline.cas.view(CameraInfo).timestamp == 5.0
    assert isinstance(reader, TumSequenceReader)
    failing = TumSequenceReader(tmp_path, frame=1)  # the unmatched colour image is no frame
    Pipeline("p", [failing]).tick_once()
    assert failing.status is Status.FAILURE and "1 associated" in failing.feedback_message


def test_pcl_tiff_sequence(shared_data: Path) -> None:
    folder = require_folder(shared_data / "pcl_grabber_sequences")
    for frame, path in enumerate(sorted((folder / "tiff").glob("*_depth.tiff"))):
        reader = TiffSequenceReader(folder, frame=frame)
        pipeline, cloud = cloud_of(reader)
        raw = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        assert_pixels_land(cloud, raw, 1000.0, (525.0, 525.0, 320.0, 240.0))
        stamps = [pipeline.cas.view(CameraInfo).timestamp]
    assert frame == 2 and stamps[0] > 1.3e9
    assert reader_name_for(str(folder / "tiff")) == "TiffSequenceReader"


@pytest.mark.parametrize("scene", ["learn0", "learn35"])
def test_organized_pcd_keeps_points_labels_and_fits_intrinsics(shared_data: Path, scene: str) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    reader = PcdReader(path)
    pipeline, cloud = cloud_of(reader)
    original = np.asarray(o3d.io.read_point_cloud(str(path), remove_nan_points=False).points).reshape(480, 640, 3)
    k = pipeline.cas.view(CameraInfo).intrinsics
    assert (k.fx, k.fy, k.cx, k.cy) == pytest.approx((525.0, 525.0, 319.5, 239.5), abs=1e-3)
    regenerated = cloud_of_depth(path)
    for u, v in ((300, 300), (320, 380), (100, 400)):
        assert np.isfinite(original[v, u]).all()
        assert np.linalg.norm(cloud.points[v, u] - original[v, u]) < 1e-6
        assert np.linalg.norm(regenerated[v, u] - original[v, u]) < 0.001  # depth + fitted intrinsics agree
    labels = reader.last_frame.labels
    assert labels is not None and labels.shape == (480, 640)
    assert {1, 20, 30} <= set(np.unique(labels).tolist())
    assert not np.isfinite(cloud.points[labels == 0]).any()


def cloud_of_depth(path: Path) -> np.ndarray:
    """The cloud the PointCloudGenerator makes from the PCD reader's depth image and fitted intrinsics."""
    generator = PointCloudGenerator()
    pipeline = Pipeline("again", [PcdReader(path), generator])  # the generator's cloud replaces the file's
    pipeline.tick_once()
    assert generator.status is Status.SUCCESS
    return pipeline.cas.view(PointCloud).points
