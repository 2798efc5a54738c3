"""Surface normals on the organized grid: central differences across ``step`` pixels, smoothed, toward the camera.

For every pixel the horizontal and vertical neighbours ``step`` pixels away span the surface; their cross product is
the normal, flipped to face the camera. A pixel whose neighbours are missing or lie across a depth discontinuity
gets NaN. The raw normals are averaged over a ``smoothing`` x ``smoothing`` window (sensor noise), then normalised.
Only the bounding box of the points of interest is computed, on every ``stride``-th pixel (normals vary slowly;
each pixel takes the normal of its cell); everything else is NaN.
"""

from __future__ import annotations

from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.point_cloud import cloud_problem
from annotators.geometry.grid_kernels import organized_normals
from annotators.geometry.grid_segmentation import bounding_box
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, Normals, PointCloud


def grid_normals(
    points: np.ndarray,
    step: int = 3,
    smoothing: int = 5,
    jump_absolute: float = 0.01,
    jump_relative: float = 0.02,
) -> np.ndarray:
    """HxWx3 float32 unit normals (facing the camera at the origin) of an organized HxWx3 cloud; NaN where unknown."""
    grid = np.ascontiguousarray(points, dtype=np.float32)
    return organized_normals(grid, step, smoothing, jump_absolute, jump_relative)


class NormalEstimator(Annotator):
    """Estimates a unit normal (toward the camera) for every point of interest of the organized cloud."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Normals,)
    capability: ClassVar[Capability] = Capability(
        label="normal estimator",
        description="Surface normals on the organized grid (central differences, smoothed).",
        preconditions=("NeedsDepth",),
        cost_ms=3.0,
        reliability=0.95,
    )

    def __init__(self, step: int = 2, smoothing: int = 3, stride: int = 2, name: str | None = None) -> None:
        """``step`` and ``smoothing`` count pixels of the ``stride``-subsampled grid."""
        super().__init__(name=name)
        if step < 1 or smoothing < 1 or stride < 1:
            raise ValueError(f"step, smoothing and stride must be >= 1, got {step}, {smoothing}, {stride}")
        self.step = step
        self.smoothing = smoothing
        self.stride = stride

    def analyse(self) -> None:
        """Write the Normals view (NaN outside the points of interest' bounding box and where unknown)."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        stride = self.stride
        x0, y0, x1, y1 = bounding_box(cloud.mask, margin=(self.step + self.smoothing) * stride)
        coarse = grid_normals(cloud.points[y0:y1:stride, x0:x1:stride], self.step, self.smoothing)
        if stride > 1:
            size = (coarse.shape[1] * stride, coarse.shape[0] * stride)
            coarse = cv2.resize(coarse, size, interpolation=cv2.INTER_NEAREST)[: y1 - y0, : x1 - x0]
        if coarse.shape == cloud.points.shape:
            normals = np.ascontiguousarray(coarse)
        else:
            normals = np.full(cloud.points.shape, np.nan, dtype=np.float32)
            normals[y0:y1, x0:x1] = coarse
        if not np.isfinite(normals[..., 0][cloud.mask]).any():
            self.fail("no point of interest has enough valid neighbours for a normal")
        self.write(Normals(normals))
