"""The compiled loops behind :mod:`annotators.cloud.body_profile` (numba, machine code cached on disk next to this
file). Importing this module imports numba; :mod:`~annotators.cloud.body_profile` imports it on first use."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def band_system(
    xy: np.ndarray, squares: np.ndarray, band: np.ndarray, keep: np.ndarray, bands: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The least-squares system of one fit to the kept points: the points per band, the bands' mean x, y and
    squared distance (NaN in an empty band), the kept points' x, y minus their band's mean, doubled (the matrix),
    and their squared distance minus their band's mean of it (the right-hand side). Sums are added point by point
    in order, as ``np.bincount`` adds them."""
    counts = np.zeros(bands, dtype=np.float64)
    sums = np.zeros((bands, 3), dtype=np.float64)
    kept = 0
    for i in range(band.size):
        if keep[i]:
            b = band[i]
            counts[b] += 1.0
            sums[b, 0] += xy[i, 0]
            sums[b, 1] += xy[i, 1]
            sums[b, 2] += squares[i]
            kept += 1
    means = np.full((bands, 3), np.nan)
    for b in range(bands):
        if counts[b] > 0.0:
            for k in range(3):
                means[b, k] = sums[b, k] / counts[b]
    matrix = np.empty((kept, 2), dtype=np.float64)
    rhs = np.empty(kept, dtype=np.float64)
    row = 0
    for i in range(band.size):
        if keep[i]:
            b = band[i]
            matrix[row, 0] = 2.0 * (xy[i, 0] - means[b, 0])
            matrix[row, 1] = 2.0 * (xy[i, 1] - means[b, 1])
            rhs[row] = squares[i] - means[b, 2]
            row += 1
    return counts, means, matrix, rhs


@njit(cache=True, nogil=True)
def surface_offsets(xy: np.ndarray, band: np.ndarray, centre: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """How far each point lies off the surface: ``|distance to the axis through centre - its band's radius|``
    (infinite in a band without a radius)."""
    off = np.empty(band.size, dtype=np.float64)
    for i in range(band.size):
        dx, dy = xy[i, 0] - centre[0], xy[i, 1] - centre[1]
        radius = radii[band[i]]
        if not math.isfinite(radius):
            radius = np.inf
        off[i] = abs(math.sqrt(dx * dx + dy * dy) - radius)
    return off
