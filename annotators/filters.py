"""Cloud filters that narrow the mask of points of interest; the points themselves are shared, never copied."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from annotators.point_cloud import cloud_problem
from robokudo.annotator import Annotator
from robokudo.types import CasType, PointCloud


def range_mask(points: np.ndarray, mask: np.ndarray, min_depth: float, max_depth: float) -> np.ndarray:
    """``mask`` narrowed to points whose depth (z) lies in [min_depth, max_depth] (NaN points drop out)."""
    z = points[..., 2]
    with np.errstate(invalid="ignore"):
        return mask & (z >= min_depth) & (z <= max_depth)


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
