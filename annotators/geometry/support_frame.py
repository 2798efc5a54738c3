"""The upright frame object experts measure in: z up, on the supporting plane when there is one.

With a supporting plane the frame has its origin at the camera's foot on the plane and z along the plane normal,
so z is the height above the support and the bottom of an object is at z = 0 even where it is hidden. Without a
plane but with the camera pose it is the world frame. Without either, the camera's -y axis is taken as up (a
roughly upright camera) and the frame is only a guess, which :class:`SupportFrame` says.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from annotators.cloud.plane import plane_basis
from robokudo.core.types import CameraInfo, ObjectHypothesis, Plane, PointCloud


@dataclass(frozen=True, eq=False)
class SupportFrame:
    """A camera-to-upright 4x4 transform; ``on_plane``: z = 0 is the support; ``guessed``: up is only assumed."""

    camera_to_frame: np.ndarray
    on_plane: bool
    guessed: bool

    def points(self, camera_points: np.ndarray) -> np.ndarray:
        """Nx3 camera-frame points in this frame."""
        return camera_points @ self.camera_to_frame[:3, :3].T + self.camera_to_frame[:3, 3]

    def directions(self, camera_vectors: np.ndarray) -> np.ndarray:
        """Nx3 camera-frame directions (normals) in this frame."""
        return camera_vectors @ self.camera_to_frame[:3, :3].T


def plane_frame(model: np.ndarray) -> np.ndarray:
    """Camera-to-plane transform: origin at the camera's foot on the plane, z along the (unit) plane normal."""
    normal = np.asarray(model[:3], dtype=np.float64)
    normal = normal / np.linalg.norm(normal)
    plane_to_camera = np.eye(4)
    plane_to_camera[:3, :2] = plane_basis(normal).T
    plane_to_camera[:3, 2] = normal
    plane_to_camera[:3, 3] = -float(model[3]) * normal
    return np.linalg.inv(plane_to_camera)


def usable_plane(planes: list[Plane]) -> Plane | None:
    """The plane with the most inliers whose model is four finite numbers with a unit normal, or None."""
    good = []
    for plane in planes:
        model = np.asarray(plane.model, dtype=np.float64)
        if model.shape == (4,) and np.all(np.isfinite(model)) and 0.99 < np.linalg.norm(model[:3]) < 1.01:
            good.append(plane)
    return max(good, key=lambda p: np.asarray(p.inlier_indices).size) if good else None


def usable_pose(camera: CameraInfo | None) -> np.ndarray | None:
    """The camera pose when it is a finite 4x4 matrix, else None."""
    if camera is None or camera.cam_to_world is None:
        return None
    pose = np.asarray(camera.cam_to_world, dtype=np.float64)
    return pose if pose.shape == (4, 4) and np.all(np.isfinite(pose)) else None


def support_frame(plane: Plane | None, camera: CameraInfo | None) -> SupportFrame:
    """The plane's frame, else the world (camera pose), else a frame with the camera's -y as up."""
    if plane is not None:
        return SupportFrame(plane_frame(np.asarray(plane.model, dtype=np.float64)), on_plane=True, guessed=False)
    pose = usable_pose(camera)
    if pose is not None:
        return SupportFrame(pose, on_plane=False, guessed=False)
    camera_to_frame = np.eye(4)
    camera_to_frame[:3, :3] = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]  # x right, y forward, z up
    return SupportFrame(camera_to_frame, on_plane=False, guessed=True)


def sampled_indices(cloud: PointCloud, hypothesis: ObjectHypothesis, max_points: int = 2000) -> np.ndarray:
    """Up to about ``max_points`` flat grid indices of the hypothesis with finite points, evenly sampled."""
    indices = np.asarray(hypothesis.point_indices).reshape(-1)
    indices = indices[:: max(1, indices.size // max_points)]
    indices = indices[(indices >= 0) & (indices < cloud.mask.size)]
    return indices[np.isfinite(cloud.points.reshape(-1, 3)[indices]).all(axis=1)]
