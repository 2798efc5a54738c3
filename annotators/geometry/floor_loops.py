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


@njit(cache=True, nogil=True)
def floor_candidate(
    labels: np.ndarray,
    enclosing: np.ndarray,
    plane: np.ndarray,
    label: int,
    box: np.ndarray,
    step: int,
    cell: np.float32,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
    """``(core, rows, cols, feet, possible)`` of one label in its pixel ``box`` ``(y0, y1, x0, x1)``: the feet of its
    pixels away from its outline (all eight neighbours the label) on every ``step``-th pixel of the box, with finite
    ``(u, v)`` (Kx2 float32, row-major: :func:`~annotators.geometry.container_floors.core_feet`); the pixels it
    encloses (``rows``, ``cols`` within the box, row-major) and their feet (Nx2); whether any of those feet lies
    within the core feet's box shrunk by ``cell`` at its low sides
    (:func:`~annotators.geometry.container_floors.may_lie_within`'s test, float32)."""
    y0, y1, x0, x1 = box[0], box[1], box[2], box[3]
    count = 0
    for r in range(y0, y1, step):
        for c in range(x0, x1, step):
            if _core_foot(labels, plane, r, c, label):
                count += 1
    core = np.empty((count, 2), dtype=np.float32)
    count = 0
    for r in range(y0, y1, step):
        for c in range(x0, x1, step):
            if _core_foot(labels, plane, r, c, label):
                core[count, 0], core[count, 1] = plane[r, c, 0], plane[r, c, 1]
                count += 1
    enclosed = 0
    for r in range(y0, y1):
        for c in range(x0, x1):
            enclosed += enclosing[r, c] == label
    seed_rows = np.empty(enclosed, dtype=np.int64)
    seed_cols = np.empty(enclosed, dtype=np.int64)
    feet = np.empty((enclosed, 2), dtype=np.float32)
    enclosed = 0
    for r in range(y0, y1):
        for c in range(x0, x1):
            if enclosing[r, c] == label:
                seed_rows[enclosed], seed_cols[enclosed] = r - y0, c - x0
                feet[enclosed, 0], feet[enclosed, 1] = plane[r, c, 0], plane[r, c, 1]
                enclosed += 1
    possible = False
    if count > 0:
        low_u, low_v, high_u, high_v = core[0, 0], core[0, 1], core[0, 0], core[0, 1]
        for k in range(1, count):
            low_u, high_u = min(low_u, core[k, 0]), max(high_u, core[k, 0])
            low_v, high_v = min(low_v, core[k, 1]), max(high_v, core[k, 1])
        low_u, low_v = np.float32(low_u + cell), np.float32(low_v + cell)
        for k in range(enclosed):
            u, v = feet[k, 0], feet[k, 1]
            if u >= low_u and u <= high_u and v >= low_v and v <= high_v:
                possible = True
                break
    return core, seed_rows, seed_cols, feet, possible


@njit(cache=True, nogil=True)
def _core_foot(labels: np.ndarray, plane: np.ndarray, r: int, c: int, label: int) -> bool:
    """Whether pixel ``(r, c)`` and all eight neighbours lie in the grid and carry ``label``, and its ``(u, v)`` is
    finite."""
    rows, cols = labels.shape
    if r == 0 or c == 0 or r == rows - 1 or c == cols - 1:
        return False
    for dr in range(-1, 2):
        for dc in range(-1, 2):
            if labels[r + dr, c + dc] != label:
                return False
    return np.isfinite(plane[r, c, 0]) and np.isfinite(plane[r, c, 1])


@njit(cache=True, nogil=True)
def overhung(
    feet: np.ndarray,
    labels: np.ndarray,
    plane: np.ndarray,
    label: int,
    box: np.ndarray,
    clearance: np.float32,
    cell: np.float32,
) -> np.ndarray:
    """N bool: :func:`annotators.geometry.container_floors.overhung` of the Nx2 float32 ``feet`` (N >= 1) and the
    points of ``label`` in its pixel ``box`` ``(y0, y1, x0, x1)`` of ``plane`` (HxWx3 float32), in float32 as numpy
    computes it; the raster's 3x3 closing ignores what lies outside it, as OpenCV's does."""
    y0, y1, x0, x1 = box[0], box[1], box[2], box[3]
    count = 0
    low_u, low_v = feet[0, 0], feet[0, 1]
    high_u, high_v = feet[0, 0], feet[0, 1]
    for k in range(1, feet.shape[0]):
        low_u, high_u = min(low_u, feet[k, 0]), max(high_u, feet[k, 0])
        low_v, high_v = min(low_v, feet[k, 1]), max(high_v, feet[k, 1])
    for r in range(y0, y1):
        for c in range(x0, x1):
            if labels[r, c] == label and _finite(plane, r, c):
                count += 1
                low_u, high_u = min(low_u, plane[r, c, 0]), max(high_u, plane[r, c, 0])
                low_v, high_v = min(low_v, plane[r, c, 1]), max(high_v, plane[r, c, 1])
    result = np.zeros(feet.shape[0], dtype=np.bool_)
    if count == 0:
        return result
    two = np.float32(2.0 * cell)
    low_u, low_v = np.float32(low_u - two), np.float32(low_v - two)
    high_u, high_v = np.float32(high_u + two), np.float32(high_v + two)
    width = int(np.ceil(np.float32(np.float32(high_u - low_u) / cell))) + 1
    height = int(np.ceil(np.float32(np.float32(high_v - low_v) / cell))) + 1
    occupied = np.zeros((height, width), dtype=np.bool_)
    reached = np.zeros((height, width), dtype=np.bool_)
    for r in range(y0, y1):
        for c in range(x0, x1):
            if labels[r, c] == label and _finite(plane, r, c):
                i = int(np.float32(np.float32(plane[r, c, 0] - low_u) / cell))
                j = int(np.float32(np.float32(plane[r, c, 1] - low_v) / cell))
                occupied[j, i] = True
                if plane[r, c, 2] <= clearance:
                    reached[j, i] = True
    dilated = np.zeros((height, width), dtype=np.bool_)
    for j in range(height):
        for i in range(width):
            if occupied[j, i] and not reached[j, i]:
                for dj in range(max(j - 1, 0), min(j + 2, height)):
                    for di in range(max(i - 1, 0), min(i + 2, width)):
                        dilated[dj, di] = True
    for k in range(feet.shape[0]):
        i = int(np.float32(np.float32(feet[k, 0] - low_u) / cell))
        j = int(np.float32(np.float32(feet[k, 1] - low_v) / cell))
        closed = True
        for dj in range(max(j - 1, 0), min(j + 2, height)):
            for di in range(max(i - 1, 0), min(i + 2, width)):
                closed = closed and dilated[dj, di]
        result[k] = closed
    return result


@njit(cache=True, nogil=True)
def _finite(plane: np.ndarray, r: int, c: int) -> bool:
    """Whether all three coordinates of pixel ``(r, c)`` are finite."""
    return np.isfinite(plane[r, c, 0]) and np.isfinite(plane[r, c, 1]) and np.isfinite(plane[r, c, 2])


@njit(cache=True, nogil=True)
def candidate_screen(
    labels: np.ndarray,
    enclosing: np.ndarray,
    plane: np.ndarray,
    boxes: np.ndarray,
    enclosed: np.ndarray,
    step: int,
    cell: np.float32,
) -> tuple[np.ndarray, np.ndarray]:
    """``(counts, possible)`` per label: for every ``enclosed`` label the number of core feet and the box test of
    :func:`floor_candidate` (its pixel box ``boxes[label]`` as ``(y0, y1, x0, x1)``), in two passes over the grid
    for all labels at once; zeros and False for the others."""
    rows, cols = labels.shape
    count = enclosed.size
    counts = np.zeros(count, dtype=np.int64)
    low = np.zeros((count, 2), dtype=np.float32)
    high = np.zeros((count, 2), dtype=np.float32)
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            if label <= 0 or not enclosed[label]:
                continue
            if (r - boxes[label, 0]) % step != 0 or (c - boxes[label, 2]) % step != 0:
                continue
            if not _core_foot(labels, plane, r, c, label):
                continue
            u, v = plane[r, c, 0], plane[r, c, 1]
            if counts[label] == 0:
                low[label, 0], low[label, 1], high[label, 0], high[label, 1] = u, v, u, v
            else:
                low[label, 0], high[label, 0] = min(low[label, 0], u), max(high[label, 0], u)
                low[label, 1], high[label, 1] = min(low[label, 1], v), max(high[label, 1], v)
            counts[label] += 1
    possible = np.zeros(count, dtype=np.bool_)
    for r in range(rows):
        for c in range(cols):
            label = enclosing[r, c]
            if label <= 0 or counts[label] == 0 or possible[label]:
                continue
            u, v = plane[r, c, 0], plane[r, c, 1]
            low_u, low_v = np.float32(low[label, 0] + cell), np.float32(low[label, 1] + cell)
            if u >= low_u and u <= high[label, 0] and v >= low_v and v <= high[label, 1]:
                possible[label] = True
    return counts, possible
