"""Rotations as unit quaternions (x, y, z, w) and 3x3 matrices, and rigid 4x4 transforms.

Convention: :func:`quaternion_from_matrix` returns the quaternion with ``w >= 0`` (q and -q are the same
rotation), so every rotation has one quaternion; a matrix that is not a rotation (NaN, all zero) gives the
identity.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

IDENTITY_QUATERNION: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
"""The quaternion (x, y, z, w) of no rotation."""


def rotation_matrix(quaternion: Sequence[float] | np.ndarray) -> np.ndarray:
    """The 3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in np.asarray(quaternion, dtype=np.float64).reshape(4))
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rotation_matrices(quaternions: np.ndarray) -> np.ndarray:
    """The Nx3x3 rotation matrices of N unit quaternions (Nx4, x, y, z, w), at once: ``I + 2 w K + 2 K K`` with
    ``K`` the cross-product matrix of (x, y, z), which is :func:`rotation_matrix` written for arrays (one call per
    quaternion would cost tens of microseconds each; a sequence's ground truth holds thousands)."""
    q = np.asarray(quaternions, dtype=np.float64).reshape(-1, 4)
    x, y, z, w = q.T
    zero = np.zeros_like(x)
    cross = np.stack(
        [np.stack([zero, -z, y], axis=-1), np.stack([z, zero, -x], axis=-1), np.stack([-y, x, zero], axis=-1)],
        axis=-2,
    )
    return np.eye(3) + 2 * w[:, None, None] * cross + 2 * cross @ cross


def pose_matrix(position: Sequence[float] | np.ndarray, quaternion: Sequence[float] | np.ndarray) -> np.ndarray:
    """The 4x4 homogeneous transform of a position and a unit quaternion (x, y, z, w)."""
    transform = np.eye(4)
    transform[:3, :3] = rotation_matrix(quaternion)
    transform[:3, 3] = np.asarray(position, dtype=np.float64).reshape(3)
    return transform


def quaternion_from_matrix(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion (x, y, z, w), ``w >= 0``, of a 3x3 rotation matrix (identity for a degenerate one).

    The branch on the largest diagonal term keeps the square root away from zero for rotations near 180
    degrees; the result is normalised, so a slightly non-orthogonal matrix gives the nearest unit quaternion.
    """
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.asarray(rotation, dtype=np.float64).reshape(3, 3).tolist()
    if not all(math.isfinite(v) for v in (m00, m01, m02, m10, m11, m12, m20, m21, m22)):
        return np.array(IDENTITY_QUATERNION)
    if m00 * (m11 * m22 - m12 * m21) - m01 * (m10 * m22 - m12 * m20) + m02 * (m10 * m21 - m11 * m20) <= 1e-6:
        return np.array(IDENTITY_QUATERNION)
    trace = m00 + m11 + m22
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s]
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m00 - m11 - m22, 1e-12))
        q = [0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]
    elif m11 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m11 - m00 - m22, 1e-12))
        q = [(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s]
    else:
        s = 2.0 * math.sqrt(max(1.0 + m22 - m00 - m11, 1e-12))
        q = [(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s]
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    quaternion = np.array([v / norm for v in q])
    return quaternion if quaternion[3] >= 0 else -quaternion
