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
def ties_in_order(order: np.ndarray, values: np.ndarray) -> None:
    """Sort each run of equal ``values[order]`` in ``order`` (sorted by value) by index, in place: what a stable
    sort gives. Ties are rare (an insertion sort per run)."""
    for k in range(1, order.size):
        index = order[k]
        j = k - 1
        while j >= 0 and values[order[j]] == values[index] and order[j] > index:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = index


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


BUCKETS = 32768
"""Bucket queue of :func:`grown_patches`: costs in steps of ``1 / STEPS``; every cost from ``BUCKETS / STEPS`` on
shares the last bucket (a pixel that far from its seed, or turned that far, is last in any case)."""
STEPS = 1024.0


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
    """See :func:`annotators.geometry.flat_patches.grown_patches`. A priority flood on a bucket queue: costs taken
    in steps of ``1 / STEPS`` (a thousandth of a pixel ``spacing`` from the seed), first in first out within one
    step; a pixel is queued again only at a lower cost than it waits at already."""
    rows, cols = surfaces.shape
    labels = np.zeros((rows, cols), dtype=np.int32)
    waiting = np.full((rows, cols), np.inf)
    capacity = seeds.size + 4 * rows * cols
    pixels = np.empty(capacity, dtype=np.int64)
    owners = np.empty(capacity, dtype=np.int32)
    following = np.empty(capacity, dtype=np.int64)  # the next entry of the same bucket, -1 for none
    heads = np.full(BUCKETS, -1, dtype=np.int64)
    tails = np.full(BUCKETS, -1, dtype=np.int64)
    entries, queued, current = 0, 0, 0
    for k in range(seeds.size):
        pixels[entries], owners[entries], following[entries] = seeds[k], k + 1, -1
        if tails[0] < 0:
            heads[0] = entries
        else:
            following[tails[0]] = entries
        tails[0] = entries
        entries += 1
        queued += 1
    seed_rows = seeds // cols
    seed_cols = seeds % cols
    while queued > 0:
        while heads[current] < 0:
            current += 1
        entry = heads[current]
        heads[current] = following[entry]
        if heads[current] < 0:
            tails[current] = -1
        queued -= 1
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
            bucket = BUCKETS - 1 if cost * STEPS >= BUCKETS - 1 else max(0, int(cost * STEPS))
            pixels[entries], owners[entries], following[entries] = rr * cols + cc, label, -1
            if tails[bucket] < 0:
                heads[bucket] = entries
            else:
                following[tails[bucket]] = entries
            tails[bucket] = entries
            entries += 1
            queued += 1
            current = min(current, bucket)
    return labels
