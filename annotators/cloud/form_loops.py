"""The compiled loops behind :mod:`annotators.cloud.form` (numba, machine code cached on disk next to this file).
Importing this module imports numba; :mod:`~annotators.cloud.form` imports it on first use."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sight_runs(heights: np.ndarray, toward: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Per row ``i``: ``max(min_j r_ij, 0)`` with ``r_ij = -(heights[i, j] + offsets[j]) / toward[i, j]`` where
    ``toward[i, j] > 1e-12`` and infinity elsewhere (a NaN anywhere in a row makes it NaN), as NumPy computes it."""
    rows, faces = heights.shape
    runs = np.empty(rows, dtype=np.float64)
    for i in range(rows):
        least = np.inf
        for j in range(faces):
            reach = -(heights[i, j] + offsets[j]) / toward[i, j] if toward[i, j] > 1e-12 else np.inf
            if reach < least or reach != reach:
                least = reach
                if reach != reach:
                    break
        runs[i] = least if (least > 0.0 or least != least) else 0.0
    return runs
