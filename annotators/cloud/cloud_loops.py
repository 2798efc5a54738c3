"""Compiled loops (numba, machine code cached on disk) behind the cloud annotators' per-pixel passes: the
back-projection of :mod:`annotators.cloud.point_cloud` and the plane-band passes of :mod:`annotators.cloud.plane`.

Each loop gives exactly what the NumPy/OpenCV expression it replaces gives (same float32 products, plane
distances accumulated in double and rounded to float32), in one pass and without temporaries.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def back_project_grid(depth: np.ndarray, x_factor: np.ndarray, y_factor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An HxWx3 float32 cloud from HxW float32 depth and the per-column / per-row ray factors (float32, W and H),
    and the HxW mask of its finite points; NaN where the depth is 0 or not finite."""
    rows, cols = depth.shape
    points = np.empty((rows, cols, 3), dtype=np.float32)
    finite = np.empty((rows, cols), dtype=np.bool_)
    nan = np.float32(np.nan)
    for r in range(rows):
        fy = y_factor[r]
        for c in range(cols):
            z = depth[r, c]
            valid = np.isfinite(z) and z > 0
            z = z if valid else nan  # a select, not a branch: depth validity is patchy
            points[r, c, 0] = z * x_factor[c]
            points[r, c, 1] = z * fy
            points[r, c, 2] = z
            finite[r, c] = valid
    return points, finite


@njit(cache=True, nogil=True)
def plane_band(points: np.ndarray, valid: np.ndarray, step: int, model: np.ndarray, band: np.float32) -> np.ndarray:
    """On every ``step``-th row and column: the valid points whose float32 distance to the plane ``model``
    (a, b, c, d; float64) is below ``band`` - the mask ``valid & (abs(plane_distances(points, model)) < band)``.
    ``points`` (HxWx3 float32) and ``valid`` (HxW) must be C-contiguous."""
    height, width = valid.shape
    rows, cols = (height + step - 1) // step, (width + step - 1) // step
    flat_points, flat_valid = points.reshape(-1), valid.reshape(-1)
    near = np.empty(rows * cols, dtype=np.bool_)
    a, b, c, d = model[0], model[1], model[2], model[3]
    if step == 1:  # one flat loop the compiler vectorises
        for i in range(rows * cols):
            x, y, z = flat_points[3 * i], flat_points[3 * i + 1], flat_points[3 * i + 2]
            distance = np.float32(a * np.float64(x) + b * np.float64(y) + c * np.float64(z) + d)
            near[i] = flat_valid[i] & (abs(distance) < band)
        return near.reshape(rows, cols)
    for r in range(rows):
        start = r * step * width
        for k in range(cols):
            i = start + k * step
            x, y, z = flat_points[3 * i], flat_points[3 * i + 1], flat_points[3 * i + 2]
            distance = np.float32(a * np.float64(x) + b * np.float64(y) + c * np.float64(z) + d)
            near[r * cols + k] = flat_valid[i] & (abs(distance) < band)  # NaN points are never near
    return near.reshape(rows, cols)


@njit(cache=True, nogil=True)
def centred_scatter(points: np.ndarray, step: int, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean (3, float64) and centred scatter matrix (3x3) of the points at ``indices``, flat indices into
    the grid of every ``step``-th row and column of the HxWx3 ``points``."""
    cols = (points.shape[1] + step - 1) // step
    count = indices.size
    picked = np.empty((count, 3), dtype=np.float64)
    for i in range(count):
        r, k = divmod(indices[i], cols)
        for j in range(3):
            picked[i, j] = points[r * step, k * step, j]
    centre = np.zeros(3, dtype=np.float64)
    for i in range(count):
        for j in range(3):
            centre[j] += picked[i, j]
    centre /= count
    scatter = np.zeros((3, 3), dtype=np.float64)
    for i in range(count):
        dx, dy, dz = picked[i, 0] - centre[0], picked[i, 1] - centre[1], picked[i, 2] - centre[2]
        scatter[0, 0] += dx * dx
        scatter[0, 1] += dx * dy
        scatter[0, 2] += dx * dz
        scatter[1, 1] += dy * dy
        scatter[1, 2] += dy * dz
        scatter[2, 2] += dz * dz
    scatter[1, 0], scatter[2, 0], scatter[2, 1] = scatter[0, 1], scatter[0, 2], scatter[1, 2]
    return centre, scatter


@njit(cache=True, nogil=True)
def depth_range(points: np.ndarray, mask: np.ndarray, low: np.floating, high: np.floating) -> np.ndarray:
    """``mask & (z >= low) & (z <= high)`` for the HxWx3 ``points`` (C-contiguous) and HxW ``mask``, with ``low``
    and ``high`` of the points' dtype; NaN depths drop out."""
    flat_points, flat_mask = points.reshape(-1), mask.reshape(-1)
    kept = np.empty(flat_mask.size, dtype=np.bool_)
    for i in range(flat_mask.size):
        z = flat_points[3 * i + 2]
        kept[i] = flat_mask[i] & (z >= low) & (z <= high)
    return kept.reshape(mask.shape)
