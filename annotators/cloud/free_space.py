"""Free-space estimation: where on a supporting surface an object of a given footprint can be put.

The supporting plane's inliers (within the cloud's points of interest, e.g. a region's box) are the surface;
every other point of interest higher than ``min_height`` above it occupies the cells it projects onto
(:mod:`annotators.geometry.surface_grid`). Free placements are the largest free rectangles that hold the
footprint, largest first and disjoint (:mod:`annotators.geometry.free_rectangles`); each is written as a
:class:`~robokudo.core.types.FreePlacement` with its centre on the surface and its axes, in the world frame when
the camera pose is known, else in the camera frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from annotators.cloud.clusters import supporting_plane
from annotators.cloud.point_cloud import cloud_problem
from annotators.geometry.free_rectangles import free_rectangles
from annotators.geometry.support_frame import usable_pose
from annotators.geometry.surface_grid import SurfaceGrid, check_grid_settings, surface_frame, surface_grid
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.geometry import quaternion_from_matrix
from robokudo.core.types import CameraInfo, CasType, FreePlacement, Plane, PointCloud

DEFAULT_CELL_M = 0.01
"""Side of an occupancy-grid cell on the surface."""

DEFAULT_CLEARANCE_M = 0.01
"""Distance every reported placement keeps from anything standing on the surface."""


def grid_stride(points: np.ndarray, surface: np.ndarray, cell: float, samples: int = 500) -> int:
    """The pixel stride that keeps about two measured points per ``cell`` along the surface: the median distance
    between horizontally neighbouring surface points (a sample of them) says how far apart pixels are."""
    rows, cols = np.nonzero(surface[::8, :-1:8])
    rows, cols = rows * 8, cols * 8
    paired = surface[rows, cols + 1]
    rows, cols = rows[paired], cols[paired]
    if rows.size == 0:
        return 1
    pick = np.linspace(0, rows.size - 1, min(samples, rows.size)).astype(np.int64)
    gaps = np.linalg.norm(points[rows[pick], cols[pick] + 1] - points[rows[pick], cols[pick]], axis=1)
    gaps = gaps[np.isfinite(gaps)]
    spacing = float(np.median(gaps)) if gaps.size else 0.0
    return max(1, int(cell / 2 / spacing)) if spacing > 0 else 1


class FreeSpaceEstimator(Annotator):
    """Finds free placements for a footprint on the supporting surface: an occupancy grid of the plane's inliers
    and the points above them, then the largest free rectangles that hold the footprint.

    ``footprint`` is (width, depth) in metres; ``max_height`` the height above the surface up to which points
    block (what hangs higher does not touch the object put there); ``region`` with ``box_pose`` (16 numbers, the
    region box's world pose) aligns the grid with the region's axes and names the region in each placement.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, Plane)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (FreePlacement,)
    capability: ClassVar[Capability] = Capability(
        label="free space estimator",
        synonyms=("free space", "placement finder"),
        preconditions=("NeedsDepth",),
        cost_ms=15.0,
        reliability=0.9,
    )

    def __init__(
        self,
        footprint: Sequence[float],
        *,
        region: str = "",
        box_pose: Sequence[float] | None = None,
        box_size: Sequence[float] | None = None,
        cell: float = DEFAULT_CELL_M,
        min_height: float = 0.015,
        max_height: float = 0.35,
        clearance: float = DEFAULT_CLEARANCE_M,
        max_placements: int = 10,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        size = tuple(float(v) for v in footprint)
        if len(size) != 2 or not all(np.isfinite(size)) or min(size) <= 0:
            raise ValueError(f"footprint must be two positive lengths (width, depth) in metres, got {footprint!r}")
        if max_placements < 1:
            raise ValueError(f"max_placements must be at least 1, got {max_placements}")
        self.footprint: tuple[float, float] = (size[0], size[1])
        self.region = region
        self.box_pose = None if box_pose is None else np.asarray(box_pose, dtype=np.float64).reshape(4, 4)
        del box_size  # handed to every annotator needing a region; the box's axes are all this one uses
        self.cell = cell
        self.min_height = min_height
        self.max_height = max_height
        self.clearance = clearance
        self.max_placements = max_placements
        check_grid_settings(cell, min_height, max_height, clearance)
        self.last_grid: SurfaceGrid | None = None
        """The occupancy grid of the last run (for inspection and drawing)."""

    def analyse(self) -> None:
        """Write one FreePlacement per free rectangle that holds the footprint (none when nothing fits)."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        support = supporting_plane(cloud, self.annotations(Plane))
        if isinstance(support, str):
            self.fail(support)
        model, inliers = support
        of_interest = cloud.mask.copy()
        on_surface = np.zeros_like(of_interest)
        on_surface.reshape(-1)[inliers] = True
        on_surface &= of_interest
        if not on_surface.any():
            self.fail("no point of the supporting plane is among the points of interest")
        of_interest &= ~on_surface
        stride = grid_stride(cloud.points, on_surface, self.cell)
        points = cloud.points[::stride, ::stride]
        surface_points = points[on_surface[::stride, ::stride]].astype(np.float64)
        surface_points = surface_points[np.isfinite(surface_points).all(axis=1)]
        if surface_points.shape[0] < 3:
            self.fail(f"the supporting plane has {surface_points.shape[0]} finite points among the points of interest")
        other_points = points[of_interest[::stride, ::stride]]
        camera = self.optional_view(CameraInfo)
        cam_to_world = usable_pose(camera)
        hint = None
        if self.box_pose is not None and cam_to_world is not None:
            hint = cam_to_world[:3, :3].T @ self.box_pose[:3, 0]
        grid = surface_grid(
            surface_points,
            other_points,
            surface_frame(model, hint, surface_points),
            cell=self.cell,
            min_height=self.min_height,
            max_height=self.max_height,
            clearance=self.clearance,
        )
        self.last_grid = grid
        rows, cols = grid.cells_for(*self.footprint)
        to_frame = cam_to_world if cam_to_world is not None else np.eye(4)
        frame = "world" if cam_to_world is not None else (camera.frame_id if camera is not None else "camera")
        rotation = to_frame[:3, :3] @ grid.surface_to_camera[:3, :3]
        orientation = quaternion_from_matrix(rotation)
        for rectangle in free_rectangles(grid.free, rows, cols, self.max_placements):
            centre = to_frame[:3, :3] @ grid.centre(rectangle) + to_frame[:3, 3]
            self.write(
                FreePlacement(
                    position=centre,
                    orientation=orientation.copy(),
                    size=grid.extent(rectangle),
                    footprint=self.footprint,
                    frame=frame,
                    region=self.region,
                    fits=rectangle.fits(rows, cols),
                    source=self.name,
                    confidence=grid.seen_share(rectangle),
                )
            )
