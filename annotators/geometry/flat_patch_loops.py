"""The compiled loops behind :mod:`annotators.geometry.flat_patches` (numba, machine code cached on disk next to
this file). Importing this module imports numba; :mod:`~annotators.geometry.flat_patches` imports it on first use."""

from __future__ import annotations

import numpy as np
from numba import njit

NEIGHBOURS = ((-1, 0), (1, 0), (0, -1), (0, 1))


@njit(cache=True, nogil=True)
def _bend(normals: np.ndarray, r: int, c: int, rr: int, cc: int) -> float:
    """``1 - n . m`` between the normals of two pixels (0 when they agree, up to 2)."""
    return 1.0 - (
        normals[r, c, 0] * normals[rr, cc, 0]
        + normals[r, c, 1] * normals[rr, cc, 1]
        + normals[r, c, 2] * normals[rr, cc, 2]
    )


@njit(cache=True, nogil=True)
def pixel_bending(surfaces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.flat_patches.pixel_bending`."""
    rows, cols = surfaces.shape
    bending = np.full((rows, cols), np.inf)
    for r in range(rows):
        for c in range(cols):
            if surfaces[r, c] == 0 or not np.isfinite(normals[r, c, 0]):
                continue
            total, count = 0.0, 0
            for dr, dc in NEIGHBOURS:
                rr, cc = r + dr, c + dc
                inside = 0 <= rr < rows and 0 <= cc < cols
                if inside and surfaces[rr, cc] == surfaces[r, c] and np.isfinite(normals[rr, cc, 0]):
                    total += _bend(normals, r, c, rr, cc)
                    count += 1
            if count > 0:
                bending[r, c] = total / count
    return bending


@njit(cache=True, nogil=True)
def flat_seeds(surfaces: np.ndarray, order: np.ndarray, bending: np.ndarray, radius: int) -> np.ndarray:
    """See :func:`annotators.geometry.flat_patches.flat_seeds`."""
    rows, cols = surfaces.shape
    blocked = np.zeros((rows, cols), dtype=np.bool_)
    seeds = np.empty(order.size, dtype=np.int64)
    count = 0
    for k in range(order.size):
        pixel = order[k]
        r, c = pixel // cols, pixel % cols
        if not np.isfinite(bending[r, c]) or blocked[r, c]:
            continue
        seeds[count] = pixel
        count += 1
        surface = surfaces[r, c]
        for rr in range(max(0, r - radius), min(rows, r + radius + 1)):
            for cc in range(max(0, c - radius), min(cols, c + radius + 1)):
                if surfaces[rr, cc] == surface:
                    blocked[rr, cc] = True
    return seeds[:count]


@njit(cache=True, nogil=True)
def _before(costs: np.ndarray, a: int, b: int) -> bool:
    """Does entry ``a`` come before entry ``b``: a lower cost, then pushed earlier (entries are numbered in push
    order)."""
    return costs[a] < costs[b] or (costs[a] == costs[b] and a < b)


@njit(cache=True, nogil=True)
def _push(heap: np.ndarray, size: int, costs: np.ndarray, entry: int) -> int:
    """Add ``entry`` to the binary heap ``heap`` of ``size`` entry numbers ordered by :func:`_before`; the new
    size."""
    i = size
    while i > 0:
        parent = (i - 1) // 2
        if not _before(costs, entry, heap[parent]):
            break
        heap[i] = heap[parent]
        i = parent
    heap[i] = entry
    return size + 1


@njit(cache=True, nogil=True)
def _pop(heap: np.ndarray, size: int, costs: np.ndarray) -> int:
    """Remove the first entry of the heap of ``size`` entries (the caller has read it); the new size."""
    size -= 1
    last = heap[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and _before(costs, heap[child + 1], heap[child]):
            child += 1
        if not _before(costs, heap[child], last):
            break
        heap[i] = heap[child]
        i = child
    heap[i] = last
    return size


@njit(cache=True, nogil=True)
def grown_patches(
    surfaces: np.ndarray,
    normals: np.ndarray,
    points: np.ndarray,
    seeds: np.ndarray,
    spacing: float,
    weight: float,
    relative: float,
) -> np.ndarray:
    """See :func:`annotators.geometry.flat_patches.grown_patches`. A priority flood on a binary heap of entry
    numbers (each entry's cost, pixel and seed in arrays); a pixel is queued again only at a lower cost than it
    waits at already (a costlier entry, pushed later, could never be taken first)."""
    rows, cols = surfaces.shape
    labels = np.zeros((rows, cols), dtype=np.int32)
    waiting = np.full((rows, cols), np.inf)
    capacity = seeds.size + 4 * rows * cols
    costs = np.empty(capacity)
    pixels = np.empty(capacity, dtype=np.int64)
    owners = np.empty(capacity, dtype=np.int32)
    heap = np.empty(capacity, dtype=np.int64)
    size = 0
    entries = 0
    for k in range(seeds.size):
        costs[entries], pixels[entries], owners[entries] = 0.0, seeds[k], k + 1
        size = _push(heap, size, costs, entries)
        entries += 1
    seed_rows = seeds // cols
    seed_cols = seeds % cols
    while size > 0:
        entry = heap[0]
        size = _pop(heap, size, costs)
        pixel, label = pixels[entry], owners[entry]
        r, c = pixel // cols, pixel % cols
        if labels[r, c] != 0:
            continue
        labels[r, c] = label
        sr, sc = seed_rows[label - 1], seed_cols[label - 1]
        for dr, dc in NEIGHBOURS:
            rr, cc = r + dr, c + dc
            if rr < 0 or rr >= rows or cc < 0 or cc >= cols:
                continue
            if labels[rr, cc] != 0 or surfaces[rr, cc] != surfaces[r, c]:
                continue
            distance = ((rr - sr) ** 2 + (cc - sc) ** 2) / (spacing * spacing)
            turn = 0.0
            if np.isfinite(normals[rr, cc, 0]):
                turn = _bend(normals, sr, sc, rr, cc)
            off = 0.0
            if relative > 0.0:
                for axis in range(3):
                    off += (points[rr, cc, axis] - points[sr, sc, axis]) * normals[sr, sc, axis]
                off /= relative * points[sr, sc, 2]
            cost = distance + weight * turn + off * off
            if cost >= waiting[rr, cc]:
                continue
            waiting[rr, cc] = cost
            costs[entries], pixels[entries], owners[entries] = cost, rr * cols + cc, label
            size = _push(heap, size, costs, entries)
            entries += 1
    return labels
