"""Point-cloud generation and range filtering on small synthetic depth images."""

from __future__ import annotations

import numpy as np
import pytest
from py_trees.common import Status

from annotators.cloud.filters import RangeFilter, range_mask, voxel_mask
from annotators.cloud.point_cloud import PointCloudGenerator, back_project, pixel_rays
from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, CameraIntrinsics, ColorImage, DepthImage, PointCloud, View

K = CameraIntrinsics(fx=612.937, fy=613.173, cx=322.549, cy=248.158, width=640, height=480)


class Seed(Annotator):
    """Writes the given views (test helper)."""

    outputs = (ColorImage, DepthImage, CameraInfo, PointCloud)

    def __init__(self, views: list[View]) -> None:
        super().__init__(name="seed")
        self.views = views

    def analyse(self) -> None:
        for view in self.views:
            self.write(view)


def run(annotator: Annotator, views: list[View]) -> Pipeline:
    pipeline = Pipeline("p", [Seed(views), annotator])
    pipeline.tick_once()
    return pipeline


def test_a_known_pixel_back_projects_to_its_3d_point_within_1_mm() -> None:
    depth = np.full((480, 640), 1.25, dtype=np.float32)
    u, v = 500, 100
    expected = np.array([(u - K.cx) * 1.25 / K.fx, (v - K.cy) * 1.25 / K.fy, 1.25])
    points = back_project(depth, pixel_rays(K))
    assert points.shape == (480, 640, 3) and points.dtype == np.float32
    assert np.linalg.norm(points[v, u] - expected) < 1e-3
    assert np.linalg.norm(points[round(K.cy), round(K.cx), :2]) < 1e-3  # principal point on the optical axis


def test_the_generator_keeps_every_pixel_and_marks_missing_depth_nan() -> None:
    depth = np.full((480, 640), 0.8, dtype=np.float32)
    depth[10, 20] = 0.0
    depth[30, 40] = np.nan
    color = np.zeros((480, 640, 3), dtype=np.uint8)
    generator = PointCloudGenerator()
    pipeline = run(generator, [DepthImage(depth), CameraInfo(K), ColorImage(color)])
    assert generator.status is Status.SUCCESS
    cloud = pipeline.cas.view(PointCloud)
    assert cloud.points.shape == (480, 640, 3)
    assert np.isnan(cloud.points[10, 20]).all() and np.isnan(cloud.points[30, 40]).all()
    assert not cloud.mask[10, 20] and not cloud.mask[30, 40] and cloud.mask.sum() == 480 * 640 - 2
    assert cloud.colors is color  # shared, not copied


def test_the_generator_caches_its_rays_per_intrinsics() -> None:
    generator = PointCloudGenerator()
    first = generator.rays_for(K)
    assert generator.rays_for(K) is first
    other = CameraIntrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
    assert generator.rays_for(other) is not first


def test_range_filter_narrows_the_mask_and_shares_the_points() -> None:
    depth = np.tile(np.linspace(0.1, 3.0, 640, dtype=np.float32), (480, 1))
    points = back_project(depth, pixel_rays(K))
    cloud = PointCloud(points=points, mask=np.isfinite(points[..., 2]))
    range_filter = RangeFilter(min_depth=0.5, max_depth=2.0)
    pipeline = run(range_filter, [cloud])
    assert range_filter.status is Status.SUCCESS
    filtered = pipeline.cas.view(PointCloud)
    assert filtered.points is points
    z = points[..., 2][filtered.mask]
    assert z.min() >= 0.5 and z.max() <= 2.0
    assert np.array_equal(filtered.mask, range_mask(points, cloud.mask, 0.5, 2.0))


def test_voxel_option_keeps_one_point_per_voxel() -> None:
    depth = np.full((48, 64), 1.0, dtype=np.float32)
    k = CameraIntrinsics(fx=60.0, fy=60.0, cx=32.0, cy=24.0, width=64, height=48)
    points = back_project(depth, pixel_rays(k))
    thinned = voxel_mask(points, np.ones((48, 64), bool), 0.05)
    cells = np.floor(points[thinned] / 0.05).astype(int)
    assert 0 < thinned.sum() < 48 * 64
    assert len({tuple(c) for c in cells}) == thinned.sum()


def test_bad_filter_parameters_are_rejected_when_the_tree_is_built() -> None:
    with pytest.raises(ValueError, match="min_depth"):
        RangeFilter(min_depth=2.0, max_depth=1.0)
    with pytest.raises(ValueError, match="voxel_size"):
        RangeFilter(voxel_size=0.0)
