"""The compiled loop behind :func:`annotators.geometry.container_floors.enclosing_labels` (numba, machine code
cached on disk next to this file). Importing this module imports numba; :mod:`~annotators.geometry.container_floors`
imports it on first use."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def enclosing_labels(labels: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """HxW int32: at each ``wanted`` pixel the label that is the nearest labelled pixel (itself included) on at
    least three of its four sides, else 0 (see :func:`annotators.geometry.container_floors.enclosing_labels`)."""
    rows, cols = labels.shape
    left = np.zeros((rows, cols), dtype=np.int32)
    up = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        seen = 0
        for c in range(cols):
            if labels[r, c] > 0:
                seen = labels[r, c]
            left[r, c] = seen
    for c in range(cols):
        seen = 0
        for r in range(rows):
            if labels[r, c] > 0:
                seen = labels[r, c]
            up[r, c] = seen
    right = np.zeros((rows, cols), dtype=np.int32)
    down = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        seen = 0
        for c in range(cols - 1, -1, -1):
            if labels[r, c] > 0:
                seen = labels[r, c]
            right[r, c] = seen
    for c in range(cols):
        seen = 0
        for r in range(rows - 1, -1, -1):
            if labels[r, c] > 0:
                seen = labels[r, c]
            down[r, c] = seen
    result = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            if not wanted[r, c]:
                continue
            a, b, u, d = left[r, c], right[r, c], up[r, c], down[r, c]
            if a == b and (a == u or a == d):  # noqa: SIM109 (numba: no tuple membership)
                result[r, c] = a
            elif u == d and (u == a or u == b):  # noqa: SIM109
                result[r, c] = u
    return result
