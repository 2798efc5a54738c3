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
    """The box of an object's camera-frame points and its frame: upright in "world" when the pose is known."""
    if cam_to_world is not None:
        transform = np.asarray(cam_to_world, dtype=np.float64)
        world = finite_points(points_camera) @ transform[:3, :3].T + transform[:3, 3]
        return upright_box(world), "world"
    return principal_box(points_camera), "camera"
