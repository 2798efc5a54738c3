"""The compiled loops behind the footprint gateways of :mod:`annotators.geometry.grid_kernels`: the convex hull of a
part's footprint on the support plane and the extents of a part seen as a container's outside (numba, machine code
cached on disk next to this file). Importing this module imports numba; the segmentation modules reach it through
:mod:`~annotators.geometry.grid_kernels` only, on first use."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _turn(ox: float, oy: float, ax: float, ay: float, bx: float, by: float) -> float:
    """The cross product ``(a - o) x (b - o)``: positive when ``o, a, b`` turn counter-clockwise."""
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)


@njit(cache=True, nogil=True)
def convex_hull(points: np.ndarray) -> np.ndarray:
    """Kx2 (``points``' dtype): the convex hull of Nx2 ``points``, counter-clockwise, without collinear vertices.

    The points strictly inside the quadrilateral of the four extreme points (least and largest x and y) cannot be
    vertices and are dropped first (Akl-Toussaint); the rest are sorted by x, then y, and the monotone chain
    builds the lower and upper hulls."""
    count = points.shape[0]
    if count < 3:
        return points.copy()
    x = points[:, 0].astype(np.float64)
    y = points[:, 1].astype(np.float64)
    west = east = south = north = 0
    for i in range(1, count):
        if x[i] < x[west]:
            west = i
        if x[i] > x[east]:
            east = i
        if y[i] < y[south]:
            south = i
        if y[i] > y[north]:
            north = i
    corners = (west, south, east, north)  # counter-clockwise around the points
    kept = np.empty(count, dtype=np.int64)
    size = 0
    for i in range(count):
        inside = True
        for k in range(4):
            a, b = corners[k], corners[(k + 1) % 4]
            if _turn(x[a], y[a], x[b], y[b], x[i], y[i]) <= 0.0:
                inside = False
                break
        if not inside:
            kept[size] = i
            size += 1
    kept = kept[:size]
    kept = kept[np.argsort(y[kept], kind="mergesort")]
    kept = kept[np.argsort(x[kept], kind="mergesort")]
    chain = np.empty(2 * size + 1, dtype=np.int64)
    length = 0
    for i in kept:  # lower hull, left to right
        while length >= 2 and _turn(
            x[chain[length - 2]], y[chain[length - 2]], x[chain[length - 1]], y[chain[length - 1]], x[i], y[i]
        ) <= 0.0:
            length -= 1
        chain[length] = i
        length += 1
    lower = length + 1
    for j in range(size - 2, -1, -1):  # upper hull, right to left
        i = kept[j]
        while length >= lower and _turn(
            x[chain[length - 2]], y[chain[length - 2]], x[chain[length - 1]], y[chain[length - 1]], x[i], y[i]
        ) <= 0.0:
            length -= 1
        chain[length] = i
        length += 1
    length = max(length - 1, 1)  # the last vertex repeats the first
    hull = np.empty((length, 2), dtype=points.dtype)
    for k in range(length):
        hull[k, 0] = points[chain[k], 0]
        hull[k, 1] = points[chain[k], 1]
    return hull


@njit(cache=True, nogil=True)
def _rank(count: int, share: float) -> int:
    """The index ``round(share * (count - 1))`` (half to even) of the ``share`` quantile of ``count`` sorted
    values."""
    return int(np.rint(share * (count - 1)))


@njit(cache=True, nogil=True)
def outside_extents(near: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.outside_extents`."""
    count = near.shape[0]
    result = np.full(8, np.nan)
    cx = 0.0
    cy = 0.0
    for i in range(count):
        cx += near[i, 0]
        cy += near[i, 1]
    cx /= count
    cy /= count
    distance = np.sqrt(cx * cx + cy * cy)
    if distance < 1e-6:
        return result
    ax, ay = cx / distance, cy / distance
    across = np.empty(count)
    along = np.empty(count)
    for i in range(count):
        across[i] = -ay * near[i, 0] + ax * near[i, 1]
        along[i] = ax * near[i, 0] + ay * near[i, 1]
    low, middle, high = _rank(count, 0.05), _rank(count, 0.5), _rank(count, 0.95)
    across = np.partition(across, np.array([low, high]))
    along = np.partition(along, np.array([low, middle]))
    result[0], result[1] = ax, ay
    result[2], result[3] = across[low], across[high]
    result[4] = heights[_rank(heights.size, 0.95)]
    result[5], result[6] = along[low], along[middle]
    result[7] = distance
    return result
