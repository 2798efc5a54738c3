"""Point-cloud generation: vectorised back-projection of a depth image into an organized cloud."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from annotators.cloud.cloud_loops import back_project_grid
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CameraIntrinsics, CasType, ColorImage, DepthImage, PointCloud


def pixel_rays(intrinsics: CameraIntrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Per-column ``(u - cx) / fx`` (1xW) and per-row ``(v - cy) / fy`` (Hx1), float32, for back-projection."""
    k = intrinsics
    x_factor = ((np.arange(k.width, dtype=np.float64) - k.cx) / k.fx).astype(np.float32)[None, :]
    y_factor = ((np.arange(k.height, dtype=np.float64) - k.cy) / k.fy).astype(np.float32)[:, None]
    return x_factor, y_factor


def back_project(depth: np.ndarray, rays: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """An HxWx3 float32 cloud from depth (metres) and :func:`pixel_rays`; NaN where depth is 0 or not finite."""
    return organized_cloud(depth, rays)[0]


def organized_cloud(depth: np.ndarray, rays: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`back_project` and the HxW mask of the cloud's finite points, in one pass over the depth image."""
    x_factor, y_factor = rays
    z = np.asarray(depth, dtype=np.float32)
    columns = np.ascontiguousarray(np.broadcast_to(x_factor, (1, z.shape[1]))[0], dtype=np.float32)
    rows = np.ascontiguousarray(np.broadcast_to(y_factor, (z.shape[0], 1))[:, 0], dtype=np.float32)
    return back_project_grid(z, columns, rows)


def intrinsics_problem(intrinsics: CameraIntrinsics, shape: tuple[int, ...]) -> str | None:
    """Why these intrinsics cannot back-project an image of ``shape`` (rows, columns), or None when they can."""
    k = intrinsics
    values = np.array([k.fx, k.fy, k.cx, k.cy], dtype=np.float64)
    if not k.is_valid() or not np.all(np.isfinite(values)):
        return f"invalid intrinsics (fx={k.fx}, fy={k.fy}, size {k.width}x{k.height})"
    if tuple(shape[:2]) != (k.height, k.width):
        return f"depth image is {shape[1]}x{shape[0]} but the intrinsics are for {k.width}x{k.height}"
    return None


def cloud_problem(cloud: PointCloud) -> str | None:
    """Why ``cloud`` cannot be worked on (malformed, empty, no point of interest), or None when it can."""
    points, mask = cloud.points, cloud.mask
    if points.ndim != 3 or points.shape[2] != 3 or points.size == 0:
        return f"the point cloud is empty or not an organized HxWx3 grid (shape {points.shape})"
    if mask.shape != points.shape[:2]:
        return f"the cloud's mask {mask.shape} does not match its grid {points.shape[:2]}"
    if not mask.any():
        return "the point cloud has no point of interest (empty mask)"
    return None


class PointCloudGenerator(Annotator):
    """Back-projects the depth image with the camera intrinsics into an organized cloud (colours when present).

    The per-pixel ray factors are cached for the last intrinsics seen; the mask marks the finite points.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (DepthImage, CameraInfo)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    capability: ClassVar[Capability] = Capability(
        label="point cloud generator",
        preconditions=("NeedsDepth",),
        cost_ms=8.0,
        reliability=1.0,
    )

    def __init__(self, name: str | None = None) -> None:
        super().__init__(name=name)
        self._rays: tuple[CameraIntrinsics, tuple[np.ndarray, np.ndarray]] | None = None

    def rays_for(self, intrinsics: CameraIntrinsics) -> tuple[np.ndarray, np.ndarray]:
        """The cached ray factors for ``intrinsics`` (recomputed when they change)."""
        if self._rays is None or self._rays[0] != intrinsics:
            self._rays = (intrinsics, pixel_rays(intrinsics))
        return self._rays[1]

    def analyse(self) -> None:
        """Build the cloud; fail on inconsistent sizes, bad intrinsics or a depth image without data."""
        depth = self.view(DepthImage).depth
        intrinsics = self.view(CameraInfo).intrinsics
        if depth.ndim != 2 or depth.size == 0:
            self.fail(f"depth image must be a non-empty HxW array, got shape {depth.shape}")
        problem = intrinsics_problem(intrinsics, depth.shape)
        if problem:
            self.fail(problem)
        color_view = self.optional_view(ColorImage)
        colors = None
        if color_view is not None:
            colors = color_view.image
            if colors.shape[:2] != depth.shape or colors.ndim != 3:
                self.fail(f"colour image {colors.shape} and depth image {depth.shape} sizes differ")
        points, mask = organized_cloud(depth, self.rays_for(intrinsics))
        if not mask.any():
            self.fail("the depth image has no valid pixel (all zero or NaN)")
        self.write(PointCloud(points=points, mask=mask, colors=colors))
