"""Oriented bounding boxes of point sets, robust to tiny, flat and degenerate sets (they never raise).

Two fits: :func:`upright_box` when the up direction is known (the box stands on the floor: z is up and the yaw
comes from the minimum-area rectangle of the footprint), and :func:`principal_box` otherwise (axes from the
principal components of the points).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True, eq=False)
class OrientedBox:
    """A box: centre (3,), rotation (3x3, columns are the box axes) and extents (3,) along those axes."""

    centre: np.ndarray
    rotation: np.ndarray
    extents: np.ndarray

    def transformed(self, transform: np.ndarray) -> OrientedBox:
        """The same box expressed through a 4x4 rigid transform."""
        rotation = transform[:3, :3] @ self.rotation
        return OrientedBox(transform[:3, :3] @ self.centre + transform[:3, 3], rotation, self.extents.copy())


def finite_points(points: np.ndarray) -> np.ndarray:
    """The rows of an Nx3 array that are finite, as float64."""
    points = np.asarray(points).reshape(-1, 3)
    return points[np.isfinite(points).all(axis=1)].astype(np.float64)


STRAY_FENCE = 3.0
"""Tukey's far-out fence: a point farther from the median point than Q3 + 3 IQR of all such distances is a stray."""


def compact_points(points: np.ndarray) -> np.ndarray:
    """The finite points of an object's compact body, without strays.

    A segment of a real depth image carries a few points that do not belong to the object's surface: flying pixels
    at depth edges (between the object and the background behind it) and specks of background. They are few but
    far away, so they would stretch a box by tens of centimetres. A point is a stray when its distance to the median
    point is beyond Tukey's far-out fence of those distances; an elongated or hollow object keeps all its points,
    since its distances spread evenly and the fence lies beyond its far end.
    """
    points = finite_points(points)
    if points.shape[0] < 8:
        return points
    distances = np.linalg.norm(points - np.median(points, axis=0), axis=1)
    q1, q3 = np.percentile(distances, [25.0, 75.0])
    return points[distances <= q3 + STRAY_FENCE * (q3 - q1)]


def _degenerate_box(points: np.ndarray) -> OrientedBox:
    centre = points.mean(axis=0) if points.shape[0] else np.zeros(3)
    extents = np.ptp(points, axis=0) if points.shape[0] else np.zeros(3)
    return OrientedBox(centre, np.eye(3), extents)


def upright_box(points: np.ndarray) -> OrientedBox:
    """The box with a vertical (+z) axis around Nx3 points given in a z-up frame; yaw from the footprint."""
    points = finite_points(points)
    if points.shape[0] < 3:
        return _degenerate_box(points)
    (cx, cy), (width, depth), angle = cv2.minAreaRect(points[:, :2].astype(np.float32))
    yaw = np.radians(angle)
    cos, sin = np.cos(yaw), np.sin(yaw)
    rotation = np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]])
    low, high = points[:, 2].min(), points[:, 2].max()
    centre = np.array([cx, cy, (low + high) / 2])
    return OrientedBox(centre, rotation, np.array([width, depth, high - low], dtype=np.float64))


def principal_box(points: np.ndarray) -> OrientedBox:
    """The box aligned with the principal axes of Nx3 points (a right-handed rotation)."""
    points = finite_points(points)
    if points.shape[0] < 3:
        return _degenerate_box(points)
    mean = points.mean(axis=0)
    centred = points - mean
    _, vectors = np.linalg.eigh(centred.T @ centred)
    rotation = vectors[:, ::-1].copy()  # largest spread first
    if np.linalg.det(rotation) < 0:
        rotation[:, 2] *= -1
    local = centred @ rotation
    low, high = local.min(axis=0), local.max(axis=0)
    centre = mean + rotation @ ((low + high) / 2)
    return OrientedBox(centre, rotation, high - low)


def object_box(points_camera: np.ndarray, cam_to_world: np.ndarray | None) -> tuple[OrientedBox, str]:
    """The box of an object's camera-frame points (strays dropped) and its frame: upright in "world" when the
    camera pose is known."""
    points = compact_points(points_camera)
    if cam_to_world is not None:
        transform = np.asarray(cam_to_world, dtype=np.float64)
        world = points @ transform[:3, :3].T + transform[:3, 3]
        return upright_box(world), "world"
    return principal_box(points), "camera"
