"""Cloud filters that narrow the mask of points of interest; the points themselves are shared, never copied.

* :class:`RangeFilter` keeps a depth range (and optionally one point per voxel);
* :class:`RegionFilter` keeps the points inside a box of the semantic map (needs the camera pose);
* :class:`CropBoxFilter` keeps the points inside an axis box in the camera frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from annotators.cloud.cloud_loops import depth_range
from annotators.cloud.point_cloud import cloud_problem
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, PointCloud


def range_mask(points: np.ndarray, mask: np.ndarray, min_depth: float, max_depth: float) -> np.ndarray:
    """``mask`` narrowed to points whose depth (z) lies in [min_depth, max_depth] (NaN points drop out); the
    bounds are compared in the points' precision."""
    points = np.ascontiguousarray(points)
    organized = points.ndim == 3 and points.shape[2] == 3 and np.shape(mask) == points.shape[:2]
    if not organized or points.dtype not in (np.float32, np.float64):
        z = points[..., 2]
        with np.errstate(invalid="ignore"):
            return mask & (z >= min_depth) & (z <= max_depth)
    # the compiled pass, comparing in the precision NumPy would (a Python float bound: the points' precision)
    low, high = (np.result_type(points.dtype, bound).type(bound) for bound in (min_depth, max_depth))
    return depth_range(points, np.ascontiguousarray(mask, dtype=bool), low, high)


def voxel_mask(points: np.ndarray, mask: np.ndarray, voxel_size: float) -> np.ndarray:
    """``mask`` thinned to one point (the first in grid order) per cubic voxel of side ``voxel_size``."""
    indices = np.flatnonzero(mask)
    thinned = np.zeros(mask.shape, dtype=bool)
    if indices.size == 0:
        return thinned
    cells = np.floor(points.reshape(-1, 3)[indices] / voxel_size).astype(np.int64)
    cells -= cells.min(axis=0)
    span = cells.max(axis=0) + 1
    keys = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]
    _, first = np.unique(keys, return_index=True)
    thinned.reshape(-1)[indices[first]] = True
    return thinned


class RangeFilter(Annotator):
    """Keeps the points between ``min_depth`` and ``max_depth`` metres; optionally one per ``voxel_size`` voxel."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    capability: ClassVar[Capability] = Capability(
        label="range filter",
        cost_ms=2.0,
        reliability=1.0,
    )

    def __init__(
        self,
        min_depth: float = 0.2,
        max_depth: float = 2.5,
        voxel_size: float | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        if not 0 <= min_depth < max_depth:
            raise ValueError(f"need 0 <= min_depth < max_depth, got {min_depth}, {max_depth}")
        if voxel_size is not None and voxel_size <= 0:
            raise ValueError(f"voxel_size must be positive, got {voxel_size}")
        self.min_depth = min_depth
        self.max_depth = max_depth
        self.voxel_size = voxel_size

    def analyse(self) -> None:
        """Narrow the cloud's mask; fail when nothing is left."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        mask = range_mask(cloud.points, cloud.mask, self.min_depth, self.max_depth)
        if self.voxel_size is not None:
            mask = voxel_mask(cloud.points, mask, self.voxel_size)
        if not mask.any():
            self.fail(f"no point between {self.min_depth} and {self.max_depth} m")
        self.write(cloud.with_mask(mask))


def box_mask(points: np.ndarray, mask: np.ndarray, camera_to_box: np.ndarray, half_size: np.ndarray) -> np.ndarray:
    """``mask`` narrowed to the points inside a box: ``camera_to_box`` maps camera coordinates to the box frame
    (box centre at the origin, axes along its edges) and ``half_size`` is half the box's edge lengths.

    Works channel by channel on the whole grid (no gathering of the points), NaN points drop out.
    """
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    inside = mask.copy()
    with np.errstate(invalid="ignore"):
        for axis in range(3):
            row = camera_to_box[axis].astype(np.float32)
            local = x * row[0]
            local += y * row[1]
            local += z * row[2]
            local += row[3]
            inside &= np.abs(local) <= np.float32(half_size[axis])
    return inside


def _box_size(box_size: Sequence[float]) -> np.ndarray:
    size = np.asarray(box_size, dtype=np.float64).reshape(-1)
    if size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise ValueError(f"box_size must be 3 positive numbers, got {tuple(box_size)}")
    return size


class RegionFilter(Annotator):
    """Keeps the points inside the box of a semantic-map region (e.g. the fridge's interior).

    ``box_pose`` is the world pose of the box centre as 16 numbers (a row-major 4x4 transform), ``box_size`` its
    edge lengths in metres along the box axes. The camera pose (CameraInfo.cam_to_world) brings the points into
    the world; without it, or when no point of interest is inside the box, the filter fails with the reason.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, CameraInfo)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    capability: ClassVar[Capability] = Capability(
        label="region filter",
        description="Keeps the points inside a semantic-map region's box (needs the camera pose).",
        preconditions=("NeedsDepth", "NeedsRegion"),
        cost_ms=2.0,
        reliability=1.0,
    )

    def __init__(
        self, region: str, box_pose: Sequence[float], box_size: Sequence[float], name: str | None = None
    ) -> None:
        super().__init__(name=name or f"RegionFilter({region})")
        pose = np.asarray(box_pose, dtype=np.float64).reshape(-1)
        if pose.shape != (16,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"box_pose must be 16 finite numbers (a row-major 4x4 transform), got {pose.size}")
        pose = pose.reshape(4, 4)
        rotation = pose[:3, :3]
        if not np.allclose(pose[3], (0, 0, 0, 1)) or not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-6):
            raise ValueError("box_pose must be a rigid transform (orthonormal rotation, last row 0 0 0 1)")
        self.region = region
        self.box_pose = pose
        self.box_size = _box_size(box_size)
        self._world_to_box = np.linalg.inv(pose)

    def analyse(self) -> None:
        """Narrow the cloud's mask to the region's box."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        cam_to_world = self.view(CameraInfo).cam_to_world
        if cam_to_world is None:
            self.fail(f"the camera pose is unknown, so the points cannot be placed in region {self.region!r}")
        transform = np.asarray(cam_to_world, dtype=np.float64)
        if transform.shape != (4, 4) or not np.all(np.isfinite(transform)):
            self.fail(f"camera pose must be a finite 4x4 matrix, got shape {transform.shape}")
        mask = box_mask(cloud.points, cloud.mask, self._world_to_box @ transform, self.box_size / 2)
        if not mask.any():
            self.fail(f"no point of interest lies inside region {self.region!r}")
        self.write(cloud.with_mask(mask))


class CropBoxFilter(Annotator):
    """Keeps the points inside an axis-aligned box of the camera frame (``minimum`` / ``maximum`` corners, metres).

    The default keeps everything from 0.2 to 2.5 m ahead within 1.5 m to either side: a cheap early crop.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    capability: ClassVar[Capability] = Capability(
        label="crop box filter",
        cost_ms=2.5,
        reliability=1.0,
    )

    def __init__(
        self,
        minimum: Sequence[float] = (-1.5, -1.5, 0.2),
        maximum: Sequence[float] = (1.5, 1.5, 2.5),
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        low = np.asarray(minimum, dtype=np.float64).reshape(-1)
        high = np.asarray(maximum, dtype=np.float64).reshape(-1)
        if low.shape != (3,) or high.shape != (3,) or not np.all(np.isfinite(low)) or not np.all(np.isfinite(high)):
            raise ValueError(f"minimum and maximum must be 3 finite numbers each, got {minimum}, {maximum}")
        if np.any(low >= high):
            raise ValueError(f"minimum {tuple(minimum)} must be below maximum {tuple(maximum)} on every axis")
        self.minimum = low
        self.maximum = high

    def analyse(self) -> None:
        """Narrow the cloud's mask to the box."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        camera_to_box = np.eye(4)
        camera_to_box[:3, 3] = -(self.minimum + self.maximum) / 2
        mask = box_mask(cloud.points, cloud.mask, camera_to_box, (self.maximum - self.minimum) / 2)
        if not mask.any():
            low, high = (", ".join(f"{v:g}" for v in corner) for corner in (self.minimum, self.maximum))
            self.fail(f"no point of interest inside the crop box ({low}) .. ({high}) m")
        self.write(cloud.with_mask(mask))
