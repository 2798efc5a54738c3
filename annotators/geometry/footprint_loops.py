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

    The points strictly inside the octagon of the eight extreme points (least and largest x, y, x + y and x - y)
    cannot be vertices and are dropped first (Akl-Toussaint); the rest are sorted by x, then y, and the monotone
    chain builds the lower and upper hulls."""
    count = points.shape[0]
    if count < 3:
        return points.copy()
    x = points[:, 0].astype(np.float64)
    y = points[:, 1].astype(np.float64)
    # counter-clockwise around the points: west, south-west, south, south-east, east, north-east, north, north-west
    corners = np.zeros(8, dtype=np.int64)
    for i in range(1, count):
        if x[i] < x[corners[0]]:
            corners[0] = i
        if x[i] + y[i] < x[corners[1]] + y[corners[1]]:
            corners[1] = i
        if y[i] < y[corners[2]]:
            corners[2] = i
        if x[i] - y[i] > x[corners[3]] - y[corners[3]]:
            corners[3] = i
        if x[i] > x[corners[4]]:
            corners[4] = i
        if x[i] + y[i] > x[corners[5]] + y[corners[5]]:
            corners[5] = i
        if y[i] > y[corners[6]]:
            corners[6] = i
        if y[i] - x[i] > y[corners[7]] - x[corners[7]]:
            corners[7] = i
    kept = np.empty(count, dtype=np.int64)
    size = 0
    for i in range(count):
        inside = True
        for k in range(8):
            a, b = corners[k], corners[(k + 1) % 8]
            if a != b and _turn(x[a], y[a], x[b], y[b], x[i], y[i]) <= 0.0:
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
        while (
            length >= 2
            and _turn(
                x[chain[length - 2]], y[chain[length - 2]], x[chain[length - 1]], y[chain[length - 1]], x[i], y[i]
            )
            <= 0.0
        ):
            length -= 1
        chain[length] = i
        length += 1
    lower = length + 1
    for j in range(size - 2, -1, -1):  # upper hull, right to left
        i = kept[j]
        while (
            length >= lower
            and _turn(
                x[chain[length - 2]], y[chain[length - 2]], x[chain[length - 1]], y[chain[length - 1]], x[i], y[i]
            )
            <= 0.0
        ):
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
def quantile_rank(count: int, share: float) -> int:
    """The index ``round(share * (count - 1))`` (half to even) of the ``share`` quantile of ``count`` sorted
    values."""
    return int(np.rint(share * (count - 1)))


@njit(cache=True, nogil=True)
def select_rank(values: np.ndarray, first: int, end: int, rank: int) -> float:
    """The value of rank ``rank`` among ``values[first:end]`` (no NaN), found by quickselect in place: afterwards
    ``values[rank]`` holds it, with no greater value before it and no smaller one after it (within first:end).

    Each partition is branch-free (every value is swapped, the boundary advances by the comparison), so its cost
    does not depend on how well the processor guesses the comparisons. The pivot is the median of three values at
    pseudo-random positions (a fixed sequence), since points in pixel order are far from random: their distances
    to the centre fall and rise again, which defeats pivots taken at fixed positions."""
    state = np.uint64(0x9E3779B97F4A7C15)
    while end - first > 16:
        span = end - first
        state = state * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)  # Knuth's LCG
        a = values[first + int((state >> np.uint64(33)) % np.uint64(span))]
        state = state * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
        b = values[first + int((state >> np.uint64(33)) % np.uint64(span))]
        state = state * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
        c = values[first + int((state >> np.uint64(33)) % np.uint64(span))]
        pivot = max(min(a, b), min(max(a, b), c))  # the median of three
        store = first
        for i in range(first, end):  # the values below the pivot to the front
            value = values[i]
            values[i] = values[store]
            values[store] = value
            store += value < pivot
        if store == first:  # none below: the pivot is the least, split off the values equal to it
            for i in range(first, end):
                value = values[i]
                values[i] = values[store]
                values[store] = value
                store += value <= pivot
            if rank < store:
                return pivot
            first = store
        elif rank < store:
            end = store
        else:
            first = store
    for i in range(first + 1, end):  # insertion sort of the few left
        value = values[i]
        j = i - 1
        while j >= first and values[j] > value:
            values[j + 1] = values[j]
            j -= 1
        values[j + 1] = value
    return values[rank]


@njit(cache=True, nogil=True)
def ranked_values(values: np.ndarray, ranks: np.ndarray) -> np.ndarray:
    """float64: the values of 1-D ``values`` at the (ascending) ``ranks`` of their sorted order - what
    ``np.sort(values)[ranks]`` gives, NaN sorted last - by selection (``values`` is reordered)."""
    picked = np.empty(ranks.size)
    for value in values:
        if np.isnan(value):
            ordered = np.sort(values)
            for k in range(ranks.size):
                picked[k] = ordered[ranks[k]]
            return picked
    high = values.size
    for k in range(ranks.size - 1, -1, -1):
        if k < ranks.size - 1 and ranks[k] == ranks[k + 1]:
            picked[k] = picked[k + 1]
            continue
        if ranks[k] == high - 1:  # the greatest of the values up to the rank picked last: moved to its rank
            at = 0
            for i in range(1, high):
                if values[i] > values[at]:
                    at = i
            values[at], values[high - 1] = values[high - 1], values[at]
        else:
            select_rank(values, 0, high, ranks[k])
        picked[k] = values[ranks[k]]
        high = ranks[k]
    return picked


@njit(cache=True, nogil=True)
def outside_extents(near: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.outside_extents`."""
    return rim_outside_extents(near, heights[quantile_rank(heights.size, 0.95)])


@njit(cache=True, nogil=True)
def rim_outside_extents(near: np.ndarray, rim: float) -> np.ndarray:
    """:func:`outside_extents` of a part whose 95 % height (the rim) is known."""
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
    low, middle, high = quantile_rank(count, 0.05), quantile_rank(count, 0.5), quantile_rank(count, 0.95)
    result[0], result[1] = ax, ay
    result[2:4] = ranked_values(across, np.array([low, high]))
    result[4] = rim
    result[5:7] = ranked_values(along, np.array([low, middle]))
    result[7] = distance
    return result


@njit(cache=True, nogil=True)
def _row_spans(vertices: np.ndarray, start: int, end: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Per row of a convex polygon's raster (integer ``vertices[start:end]``, cell centres at integer coordinates,
    ``height`` rows from 0), the first and last column of the cells the polygon touches within the row (the
    polygon clipped to the row's band ``r - 0.5 .. r + 0.5``); ``first > last`` where it touches none."""
    first = np.full(height, np.iinfo(np.int64).max, dtype=np.int64)
    last = np.full(height, np.iinfo(np.int64).min, dtype=np.int64)
    low = np.full(height, np.inf)
    high = np.full(height, -np.inf)
    size = end - start
    for k in range(size):
        px, py = float(vertices[start + k, 0]), float(vertices[start + k, 1])
        following = start + (k + 1) % size
        qx, qy = float(vertices[following, 0]), float(vertices[following, 1])
        bottom, top = min(py, qy), max(py, qy)
        for row in range(max(0, int(np.floor(bottom + 0.75))), min(height - 1, int(np.ceil(top - 0.75))) + 1):
            y0, y1 = max(bottom, row - 0.25), min(top, row + 0.25)
            if py == qy:
                x0, x1 = px, qx
            else:
                x0 = px + (qx - px) * (y0 - py) / (qy - py)
                x1 = px + (qx - px) * (y1 - py) / (qy - py)
            low[row] = min(low[row], x0, x1)
            high[row] = max(high[row], x0, x1)
    for row in range(height):
        if low[row] <= high[row]:
            first[row] = int(np.floor(low[row] + 0.5))
            last[row] = int(np.ceil(high[row] - 0.5))
    return first, last


@njit(cache=True, nogil=True)
def footprint_shares(
    vertices: np.ndarray, starts: np.ndarray, boxes: np.ndarray, pairs: np.ndarray, count: int
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.footprint_shares`."""
    shares = np.zeros(count)
    for pair in pairs:
        second = pair + count
        a_first, a_last = _row_spans(vertices, starts[pair], starts[pair + 1], boxes[pair, 3])
        b_first, b_last = _row_spans(vertices, starts[second], starts[second + 1], boxes[second, 3])
        areas = np.zeros(2, dtype=np.int64)
        for side, (first, last) in enumerate(((a_first, a_last), (b_first, b_last))):
            for row in range(first.size):
                if first[row] <= last[row]:
                    areas[side] += last[row] - first[row] + 1
        ax, ay, bx, by = boxes[pair, 0], boxes[pair, 1], boxes[second, 0], boxes[second, 1]
        shared = 0
        for y in range(max(ay, by), min(ay + a_first.size, by + b_first.size)):
            a, b = y - ay, y - by
            if a_first[a] > a_last[a] or b_first[b] > b_last[b]:
                continue
            low = max(a_first[a] + ax, b_first[b] + bx)
            high = min(a_last[a] + ax, b_last[b] + bx)
            if low <= high:
                shared += high - low + 1
        shares[pair] = shared / max(1, min(areas[0], areas[1]))
    return shares


@njit(cache=True, nogil=True)
def sight_extents(points: np.ndarray, ax: float, ay: float) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.sight_extents`."""
    count = points.shape[0]
    across = np.empty(count)
    along = np.empty(count)
    for i in range(count):
        across[i] = -ay * points[i, 0] + ax * points[i, 1]
        along[i] = ax * points[i, 0] + ay * points[i, 1]
    low, middle, high = quantile_rank(count, 0.05), quantile_rank(count, 0.5), quantile_rank(count, 0.95)
    extents = np.empty(4)
    extents[:2] = ranked_values(across, np.array([low, high]))
    extents[2:] = ranked_values(along, np.array([middle, high]))
    return extents
