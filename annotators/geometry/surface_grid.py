"""An occupancy grid on a supporting surface: which cells are seen free, seen occupied, or not seen.

The grid lies in a surface frame (z along the surface normal, z = 0 on the surface; x and y span the surface).
A cell is *observed* when some surface point falls in it (one-cell gaps between observed cells are closed, as
sensor noise leaves them), *occupied* when a point above the surface (higher than ``min_height`` and at most
``max_height``) projects into it, grown by ``clearance`` so a placement keeps its distance, and *free* when it is
observed and not occupied. Surface hidden behind an object is not observed, so it is never free: a free cell is
one the sensor saw empty.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.free_rectangles import CellRectangle

MAX_CELLS = 1_000_000
"""The largest grid made; a wider surface gets coarser cells."""


@dataclass(frozen=True, eq=False)
class SurfaceGrid:
    """Cells of ``cell`` metres; cell (row, col) covers x in origin_x + col*cell.., y in origin_y + row*cell..
    of the surface frame, whose pose in the camera frame is ``surface_to_camera``."""

    free: np.ndarray
    seen: np.ndarray
    """Cells some surface point fell in (before gaps were closed)."""
    observed: np.ndarray
    occupied: np.ndarray
    cell: float
    origin: tuple[float, float]
    surface_to_camera: np.ndarray

    def centre(self, rectangle: CellRectangle) -> np.ndarray:
        """The camera-frame centre of a rectangle of cells, on the surface."""
        x = self.origin[0] + 0.5 * (rectangle.col0 + rectangle.col1) * self.cell
        y = self.origin[1] + 0.5 * (rectangle.row0 + rectangle.row1) * self.cell
        return self.surface_to_camera[:3, :3] @ np.array([x, y, 0.0]) + self.surface_to_camera[:3, 3]

    def extent(self, rectangle: CellRectangle) -> tuple[float, float]:
        """A rectangle's size in metres: along the surface x (columns), then y (rows)."""
        return rectangle.cols * self.cell, rectangle.rows * self.cell

    def seen_share(self, rectangle: CellRectangle) -> float:
        """The share of a rectangle's cells in which the surface itself was measured."""
        block = self.seen[rectangle.row0 : rectangle.row1, rectangle.col0 : rectangle.col1]
        return float(block.mean()) if block.size else 0.0

    def cells_for(self, width: float, depth: float) -> tuple[int, int]:
        """The rows x cols a ``width`` (along x) by ``depth`` (along y) footprint covers."""
        return max(1, math.ceil(depth / self.cell - 1e-9)), max(1, math.ceil(width / self.cell - 1e-9))


def surface_frame(model: np.ndarray, x_hint: np.ndarray | None, surface_points: np.ndarray) -> np.ndarray:
    """The surface-to-camera 4x4 transform of plane ``model`` (unit normal toward the camera = z).

    The x axis is ``x_hint`` (a camera-frame direction, e.g. a region box's axis) projected onto the plane; without
    a usable hint it is the principal direction of the surface points. The origin is the camera's foot on the plane.
    """
    normal = np.asarray(model[:3], dtype=np.float64)
    normal /= np.linalg.norm(normal)
    x_axis = None
    if x_hint is not None:
        projected = np.asarray(x_hint, dtype=np.float64) - normal * float(np.dot(x_hint, normal))
        if np.linalg.norm(projected) > 1e-3:
            x_axis = projected
    if x_axis is None and surface_points.shape[0] >= 3:
        centred = surface_points - surface_points.mean(axis=0)
        centred -= np.outer(centred @ normal, normal)
        _, vectors = np.linalg.eigh(centred.T @ centred)
        x_axis = vectors[:, -1]
    if x_axis is None or np.linalg.norm(x_axis) < 1e-9:
        x_axis = np.cross(normal, [0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.cross(normal, [1.0, 0.0, 0.0])
    x_axis = x_axis / np.linalg.norm(x_axis)
    y_axis = np.cross(normal, x_axis)
    transform = np.eye(4)
    transform[:3, 0], transform[:3, 1], transform[:3, 2] = x_axis, y_axis, normal
    transform[:3, 3] = -float(model[3]) * normal
    return transform


def surface_grid(
    surface_points: np.ndarray,
    other_points: np.ndarray,
    surface_to_camera: np.ndarray,
    *,
    cell: float = 0.01,
    min_height: float = 0.015,
    max_height: float = 0.35,
    clearance: float = 0.01,
) -> SurfaceGrid:
    """The occupancy grid of a surface from its camera-frame points and the other points above it (Nx3 each)."""
    check_grid_settings(cell, min_height, max_height, clearance)
    camera_to_surface = np.linalg.inv(surface_to_camera)
    surface = _in_frame(surface_points, camera_to_surface)
    if surface.shape[0] == 0:
        raise ValueError("the surface has no finite point")
    low, high = surface[:, :2].min(axis=0), surface[:, :2].max(axis=0)
    span = np.maximum(high - low, cell)
    cell = max(cell, math.sqrt(float(span[0] * span[1]) / MAX_CELLS))
    cols, rows = (np.floor(span / cell).astype(int) + 1).tolist()
    observed = np.zeros((rows, cols), dtype=np.uint8)
    r, c = _cells(surface, low, cell, rows, cols)
    observed[r, c] = 1
    seen = observed.astype(bool)
    observed = cv2.morphologyEx(observed, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)).astype(bool)
    occupied = np.zeros((rows, cols), dtype=np.uint8)
    above = _in_frame(other_points, camera_to_surface)
    above = above[(above[:, 2] > min_height) & (above[:, 2] <= max_height)]
    r, c = _cells(above, low, cell, rows, cols)
    occupied[r, c] = 1
    grow = math.ceil(clearance / cell - 1e-9)
    if grow > 0:
        occupied = cv2.dilate(occupied, np.ones((2 * grow + 1, 2 * grow + 1), np.uint8))
    occupied_mask = occupied.astype(bool)
    return SurfaceGrid(
        free=observed & ~occupied_mask,
        seen=seen,
        observed=observed,
        occupied=occupied_mask,
        cell=cell,
        origin=(float(low[0]), float(low[1])),
        surface_to_camera=np.asarray(surface_to_camera, dtype=np.float64),
    )


def check_grid_settings(cell: float, min_height: float, max_height: float, clearance: float) -> None:
    """Raise ValueError unless cell > 0, 0 <= min_height < max_height and clearance >= 0 (all metres)."""
    if not cell > 0 or not 0 <= min_height < max_height or not clearance >= 0:
        raise ValueError(
            f"need cell > 0, 0 <= min_height < max_height and clearance >= 0; got cell {cell}, "
            f"heights {min_height}..{max_height}, clearance {clearance}"
        )


def _in_frame(points: np.ndarray, transform: np.ndarray) -> np.ndarray:
    """Finite Nx3 points moved by a 4x4 transform."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    p = p[np.isfinite(p).all(axis=1)]
    return p @ transform[:3, :3].T + transform[:3, 3]


def _cells(points: np.ndarray, low: np.ndarray, cell: float, rows: int, cols: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of each point's cell, for the points inside the grid."""
    col = np.floor((points[:, 0] - low[0]) / cell).astype(np.int64)
    row = np.floor((points[:, 1] - low[1]) / cell).astype(np.int64)
    inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
    return row[inside], col[inside]
