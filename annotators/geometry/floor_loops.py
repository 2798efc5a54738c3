"""The compiled loops behind :func:`annotators.geometry.container_floors.claim_container_floors` (numba, machine
code cached on disk next to this file): the table-level pixels with the labels enclosing them
(:func:`~annotators.geometry.container_floors.enclosing_labels` is the reference form) and whether a claimed pixel
touches another label. Importing this module imports numba; :mod:`~annotators.geometry.container_floors`
imports it on first use."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def floor_seeds(
    labels: np.ndarray, valid: np.ndarray, heights: np.ndarray, min_height: np.float32
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(level, enclosing, boxes, enclosed)`` of HxW int32 ``labels`` in one pass over the grid (rows in order):
    the table-level pixels (``valid``, unlabelled, ``|heights| < min_height`` in float32), at each of them the label
    of :func:`enclosing_labels` (else 0), each label's pixel box ``(y0, y1, x0, x1)`` (exclusive; ``(rows, 0, cols,
    0)`` for absent labels) and which labels enclose a table-level pixel (bool per label)."""
    rows, cols = labels.shape
    count = 0
    up = np.empty((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            count = max(count, label)
            up[r, c] = label if label > 0 or r == 0 else up[r - 1, c]
    down = np.empty((rows, cols), dtype=np.int32)
    for r in range(rows - 1, -1, -1):
        for c in range(cols):
            label = labels[r, c]
            down[r, c] = label if label > 0 or r == rows - 1 else down[r + 1, c]
    count += 1
    boxes = np.zeros((count, 4), dtype=np.int64)
    boxes[:, 0], boxes[:, 2] = rows, cols
    enclosed = np.zeros(count, dtype=np.bool_)
    level = np.zeros((rows, cols), dtype=np.bool_)
    enclosing = np.zeros((rows, cols), dtype=np.int32)
    right = np.empty(cols, dtype=np.int32)
    for r in range(rows):
        seen = 0
        for c in range(cols - 1, -1, -1):
            if labels[r, c] > 0:
                seen = labels[r, c]
            right[c] = seen
        seen = 0
        for c in range(cols):
            label = labels[r, c]
            if label > 0:
                seen = label
                boxes[label, 0], boxes[label, 1] = min(boxes[label, 0], r), r + 1
                boxes[label, 2], boxes[label, 3] = min(boxes[label, 2], c), max(boxes[label, 3], c + 1)
                continue
            if not valid[r, c] or not abs(heights[r, c]) < min_height:
                continue
            level[r, c] = True
            a, b, u, d = seen, right[c], up[r, c], down[r, c]
            found = 0
            if a == b and (a == u or a == d):  # noqa: SIM109 (numba: no tuple membership)
                found = a
            elif u == d and (u == a or u == b):  # noqa: SIM109
                found = u
            if found > 0:
                enclosing[r, c] = found
                enclosed[found] = True
    return level, enclosing, boxes, enclosed


@njit(cache=True, nogil=True)
def touches_other_labels(labels: np.ndarray, marked: np.ndarray) -> bool:
    """Whether a ``marked`` pixel has a 4-neighbour with another non-zero label than its own (see
    :func:`annotators.geometry.container_floors.touches_other_labels`)."""
    rows, cols = labels.shape
    for r in range(rows):
        for c in range(cols):
            if not marked[r, c]:
                continue
            own = labels[r, c]
            for dr, dc in ((0, 1), (0, -1), (1, 0), (-1, 0)):
                rr, cc = r + dr, c + dc
                if 0 <= rr < rows and 0 <= cc < cols:
                    other = labels[rr, cc]
                    if other > 0 and other != own:
                        return True
    return False
