"""The compiled loops behind :mod:`annotators.geometry.rims` (numba, machine code cached on disk next to this
file): a piece's top edge, the circle through points, and the measures of an arc around a centre. Importing this
module imports numba; :mod:`~annotators.geometry.rims` imports it on first use."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from annotators.geometry.footprint_loops import ranked_values


@njit(cache=True, nogil=True)
def share_value(values: np.ndarray, share: float) -> float:
    """See :func:`annotators.geometry.rims.share_value` (NaN for no values)."""
    if values.size == 0:
        return np.nan
    rank = round(share * (values.size - 1))
    return float(ranked_values(values.copy(), np.array([rank]))[0])


@njit(cache=True, nogil=True)
def top_height(points: np.ndarray) -> float:
    """The 95 % height of the finite Nx3 ``(u, v, height)`` points (NaN for none)."""
    heights = np.empty(points.shape[0], dtype=np.float64)
    count = 0
    for i in range(points.shape[0]):
        if np.isfinite(points[i, 2]):
            heights[count] = points[i, 2]
            count += 1
    return share_value(heights[:count], 0.95)


@njit(cache=True, nogil=True)
def top_edge(points: np.ndarray, band: float) -> tuple[np.ndarray, float]:
    """See :func:`annotators.geometry.rims.top_edge`: the (u, v) of the finite points within ``band`` of their
    95 % height, and that height."""
    heights = np.empty(points.shape[0], dtype=np.float64)
    count = 0
    for i in range(points.shape[0]):
        if np.isfinite(points[i, 0]) and np.isfinite(points[i, 1]) and np.isfinite(points[i, 2]):
            heights[count] = points[i, 2]
            count += 1
    if count == 0:
        return np.zeros((0, 2), dtype=np.float64), np.nan
    top = share_value(heights[:count], 0.95)
    edge = np.empty((count, 2), dtype=np.float64)
    kept = 0
    for i in range(points.shape[0]):
        if np.isfinite(points[i, 0]) and np.isfinite(points[i, 1]) and points[i, 2] >= top - band:
            edge[kept, 0], edge[kept, 1] = points[i, 0], points[i, 1]
            kept += 1
    return edge[:kept], top


@njit(cache=True, nogil=True)
def fit_circle(points: np.ndarray) -> tuple[float, float, float]:
    """See :func:`annotators.geometry.rims.fit_circle`: ``(u, v, radius)`` of the algebraic least-squares circle
    through Nx2 points, by its 3x3 normal equations; radius 0 when the points fix no circle."""
    normal = np.zeros((3, 3))
    right = np.zeros(3)
    for i in range(points.shape[0]):
        row = (2.0 * points[i, 0], 2.0 * points[i, 1], 1.0)
        target = points[i, 0] * points[i, 0] + points[i, 1] * points[i, 1]
        for a in range(3):
            right[a] += row[a] * target
            for b in range(3):
                normal[a, b] += row[a] * row[b]
    if points.shape[0] < 3 or abs(np.linalg.det(normal)) < 1e-18:
        return np.nan, np.nan, 0.0
    solution = np.linalg.solve(normal, right)
    u, v = solution[0], solution[1]
    return u, v, math.sqrt(max(solution[2] + u * u + v * v, 0.0))


@njit(cache=True, nogil=True)
def arc_measures(edge: np.ndarray, u: float, v: float, radius: float) -> tuple[float, float]:
    """Of an arc (Nx2) around centre ``(u, v)``: the median distance of its points from the circle of ``radius`` and
    the median distance of its points from the origin (the camera's foot)."""
    count = edge.shape[0]
    off = np.empty(count)
    away = np.empty(count)
    for i in range(count):
        du, dv = edge[i, 0] - u, edge[i, 1] - v
        off[i] = abs(math.sqrt(du * du + dv * dv) - radius)
        away[i] = math.sqrt(edge[i, 0] * edge[i, 0] + edge[i, 1] * edge[i, 1])
    return share_value(off, 0.5), share_value(away, 0.5)


@njit(cache=True, nogil=True)
def arc_turn(edge: np.ndarray, u: float, v: float) -> float:
    """The angle (radians) an arc (Nx2) runs around centre ``(u, v)``: a full turn less its widest gap."""
    count = edge.shape[0]
    if count == 0:
        return 0.0
    angles = np.empty(count)
    for i in range(count):
        angles[i] = math.atan2(edge[i, 1] - v, edge[i, 0] - u)
    angles.sort()
    widest = angles[0] + 2.0 * math.pi - angles[count - 1]
    for i in range(1, count):
        widest = max(widest, angles[i] - angles[i - 1])
    return 2.0 * math.pi - widest


@njit(cache=True, nogil=True)
def distance_share(points: np.ndarray, u: float, v: float, share: float) -> float:
    """The value ``share`` of the way up the sorted (u, v) distances of the Nx2+ points with finite (u, v) from
    ``(u, v)`` (NaN for none)."""
    distances = np.empty(points.shape[0])
    count = 0
    for i in range(points.shape[0]):
        du, dv = points[i, 0] - u, points[i, 1] - v
        distance = math.sqrt(du * du + dv * dv)
        if np.isfinite(distance):
            distances[count] = distance
            count += 1
    return share_value(distances[:count], share)
