"""Camera poses the belief store tests look from."""

from __future__ import annotations

import numpy as np


def camera_looking_at_origin(eye: tuple[float, float, float]) -> np.ndarray:
    """cam_to_world of an optical frame at ``eye`` looking horizontally at the world origin's column."""
    forward = -np.array([eye[0], eye[1], 0.0])
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    down = np.cross(forward, right)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, down, forward, eye
    return pose
