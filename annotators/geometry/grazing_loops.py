"""The compiled loop behind :func:`annotators.geometry.grazing.grazing_pixels` (numba, machine code cached on disk
next to this file). Importing this module imports numba; :mod:`~annotators.geometry.grazing` imports it on first
use."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, error_model="numpy")  # x / 0 gives inf or NaN, as in NumPy
def grazing_pixels(points: np.ndarray, pixels: np.ndarray, ratio: float) -> np.ndarray:
    """See :func:`annotators.geometry.grazing.grazing_pixels`: the same arithmetic, in the same order, per pixel."""
    height, width = points.shape[0], points.shape[1]
    grazing = np.zeros(pixels.size, dtype=np.bool_)
    steps = ((0, 1), (0, -1), (1, 0), (-1, 0))
    for i in range(pixels.size):
        row, col = pixels[i] // width, pixels[i] % width
        hx, hy, hz = np.float64(points[row, col, 0]), np.float64(points[row, col, 1]), np.float64(points[row, col, 2])
        length = math.sqrt(hx * hx + hy * hy + hz * hz)
        sx, sy, sz = hx / length, hy / length, hz / length
        for step_row, step_col in steps:
            other_row = min(max(row + step_row, 0), height - 1)
            other_col = min(max(col + step_col, 0), width - 1)
            dx = np.float64(points[other_row, other_col, 0]) - hx
            dy = np.float64(points[other_row, other_col, 1]) - hy
            dz = np.float64(points[other_row, other_col, 2]) - hz
            along = dx * sx + dy * sy + dz * sz
            ax, ay, az = dx - along * sx, dy - along * sy, dz - along * sz
            across = math.sqrt(ax * ax + ay * ay + az * az)
            floor = across if (across > 1e-9 or across != across) else 1e-9
            if abs(along) > ratio * floor:
                grazing[i] = True
    return grazing
