"""Compiled passes of :mod:`annotators.geometry.border_pixels`: the outline pixels' single-segment test and surface
checks with their normals, and the foot's links and breadth-first spread, each in one loop over the pixels examined.

They compute exactly what the array formulation of the same rules computes, in the same single-precision
arithmetic (a depth jump's limit, the normals' spans, cross products and lengths in ``float32``; a normal's cosine
is compared with the smoothness cosine in ``float64``), so the labels they give are identical to it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_ROW_STEPS = np.array([0, 0, -1, 1], dtype=np.int64)
"""Row steps to the left, right, upper and lower 4-neighbour."""

_COL_STEPS = np.array([-1, 1, 0, 0], dtype=np.int64)
"""Column steps to the left, right, upper and lower 4-neighbour."""


@njit(cache=True, nogil=True)
def _continues(z_a: np.float32, z_b: np.float32, absolute: np.float32, relative: np.float32) -> bool:
    """Whether ``z_b`` is measured and no depth jump lies between it and the measured ``z_a``."""
    if not np.isfinite(z_b):
        return False
    limit = np.float32(min(z_a, z_b) * relative) + absolute
    return not (abs(np.float32(z_a - z_b)) > limit)


@njit(cache=True, nogil=True)
def _span(
    points: np.ndarray, row: int, col: int, k: int, step: int, absolute: np.float32, relative: np.float32
) -> tuple[np.float32, np.float32, np.float32, bool]:
    """The point ``step`` pixels away from ``(row, col)`` toward the ``k``-th 4-neighbour (left, right, up, down)
    when it lies on the pixel's surface, else the pixel's own point; and whether it does."""
    r, c = row + _ROW_STEPS[k] * step, col + _COL_STEPS[k] * step
    inside = 0 <= r < points.shape[0] and 0 <= c < points.shape[1]
    if inside and _continues(points[row, col, 2], points[r, c, 2], absolute, relative):
        return points[r, c, 0], points[r, c, 1], points[r, c, 2], True
    return points[row, col, 0], points[row, col, 1], points[row, col, 2], False


@njit(cache=True, nogil=True)
def _normal(
    points: np.ndarray, row: int, col: int, step: int, absolute: np.float32, relative: np.float32
) -> tuple[np.float32, np.float32, np.float32]:
    """The unit normal (facing the camera) at ``(row, col)`` of the HxWx3 ``points``: each axis spanned by the
    points ``step`` pixels to either side on the pixel's surface, or by the pixel and the one side that is; NaN
    where neither side is."""
    lx, ly, lz, left = _span(points, row, col, 0, step, absolute, relative)
    rx, ry, rz, right = _span(points, row, col, 1, step, absolute, relative)
    tx, ty, tz, up = _span(points, row, col, 2, step, absolute, relative)
    bx, by, bz, down = _span(points, row, col, 3, step, absolute, relative)
    nan = np.float32(np.nan)
    ux, uy, uz = (np.float32(rx - lx), np.float32(ry - ly), np.float32(rz - lz)) if left or right else (nan, nan, nan)
    vx, vy, vz = (np.float32(bx - tx), np.float32(by - ty), np.float32(bz - tz)) if up or down else (nan, nan, nan)
    nx = np.float32(np.float32(uy * vz) - np.float32(uz * vy))
    ny = np.float32(np.float32(uz * vx) - np.float32(ux * vz))
    nz = np.float32(np.float32(ux * vy) - np.float32(uy * vx))
    length = np.float32(np.sqrt(_dot(nx, ny, nz, nx, ny, nz)))
    nx, ny, nz = np.float32(nx / length), np.float32(ny / length), np.float32(nz / length)
    if _dot(nx, ny, nz, points[row, col, 0], points[row, col, 1], points[row, col, 2]) > 0:
        return -nx, -ny, -nz
    return nx, ny, nz


@njit(cache=True, nogil=True)
def _dot(a0: np.float32, a1: np.float32, a2: np.float32, b0: np.float32, b1: np.float32, b2: np.float32) -> np.float32:
    """The single-precision dot product of two 3-vectors, summed left to right."""
    return np.float32(np.float32(np.float32(a0 * b0) + np.float32(a1 * b1)) + np.float32(a2 * b2))


@njit(cache=True, nogil=True)
def claim_outline(
    labels: np.ndarray,
    points: np.ndarray,
    open_: np.ndarray,
    absolute: float,
    relative: float,
    normal_step: int,
    smooth_cosine: float,
    crease: float,
) -> int:
    """Give each pixel of ``open_`` (flat indices of unlabelled pixels of the HxW ``labels``) the label of the one
    segment whose surface it continues, in place; returns how many were claimed.

    A pixel continues a segment when exactly one label lies among its 4-neighbours on its surface (no depth jump,
    measured) and its normal and that of the first such neighbour are within the smoothness angle
    (``smooth_cosine``) or bend convexly (by no less than ``-crease``). All are judged on the labels before the
    call.
    """
    height, width = labels.shape
    absolute32, relative32, crease32 = np.float32(absolute), np.float32(relative), np.float32(-crease)
    claimed = np.empty(open_.size, dtype=np.int64)
    given = np.empty(open_.size, dtype=labels.dtype)
    count = 0
    for pixel in open_:
        row, col = pixel // width, pixel % width
        z = points[row, col, 2]
        highest, lowest, beside_row, beside_col = 0, 0, -1, -1
        for k in range(4):
            r, c = row + _ROW_STEPS[k], col + _COL_STEPS[k]
            if not (0 <= r < height and 0 <= c < width):
                continue
            label = labels[r, c]
            if label <= 0 or not _continues(z, points[r, c, 2], absolute32, relative32):
                continue
            if beside_row < 0:
                highest, lowest, beside_row, beside_col = label, label, r, c
            else:
                highest, lowest = max(highest, label), min(lowest, label)
        if highest <= 0 or lowest != highest:
            continue
        ox, oy, oz = _normal(points, row, col, normal_step, absolute32, relative32)
        tx, ty, tz = _normal(points, beside_row, beside_col, normal_step, absolute32, relative32)
        if not np.float64(_dot(ox, oy, oz, tx, ty, tz)) >= smooth_cosine:  # not aligned: a convex bend?
            dx = np.float32(points[row, col, 0] - points[beside_row, beside_col, 0])
            dy = np.float32(points[row, col, 1] - points[beside_row, beside_col, 1])
            dz = np.float32(points[row, col, 2] - points[beside_row, beside_col, 2])
            length = np.float32(np.sqrt(_dot(dx, dy, dz, dx, dy, dz)))
            bend = _dot(np.float32(ox - tx), np.float32(oy - ty), np.float32(oz - tz), dx, dy, dz)
            if not np.float32(bend / length) >= crease32:
                continue
        claimed[count], given[count] = pixel, labels[beside_row, beside_col]
        count += 1
    for i in range(count):
        labels[claimed[i] // width, claimed[i] % width] = given[i]
    return count


@njit(cache=True, nogil=True)
def claim_foot(
    labels: np.ndarray,
    points: np.ndarray,
    foot: np.ndarray,
    foot_normals: np.ndarray,
    facing_away: np.ndarray,
    coarse_normals: np.ndarray,
    stride: int,
    absolute: float,
    relative: float,
    smooth_cosine: float,
    reach: int,
) -> None:
    """Give the ``foot`` pixels (sorted flat indices of the HxW ``labels``, with their Nx3 ``foot_normals``) that
    are ``facing_away`` from the plane the label of the nearest segment they continue, at most ``reach`` links
    away, in place.

    Neighbouring foot pixels are linked when no depth jump lies between them and their normals are within the
    smoothness angle; a pixel touching a segment's pixel the same way (that pixel's normal is its cell's in
    ``coarse_normals``, every ``stride``-th pixel) starts with its label - of the last such neighbour, in the order
    left, right, up, down. A breadth-first search from all starts at once gives every pixel reached the label of a
    nearest start: where several reach it in the same round, the last of them in the order of the previous round's
    front (ascending pixels in the first), each in the order left, right, up, down.
    """
    height, width = labels.shape
    nodes = np.flatnonzero(facing_away)
    pixels, normals = foot[nodes], foot_normals[nodes]
    size = pixels.size
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    targets = np.full((size, 4), -1, dtype=np.int64)
    label = np.zeros(size, dtype=labels.dtype)
    steps = np.array([-1, 1, -width, width], dtype=np.int64)
    found = np.array([0, 0, 0, 0], dtype=np.int64)  # where each neighbour would sit among the sorted pixels
    for i in range(size):
        row, col = pixels[i] // width, pixels[i] % width
        z = points[row, col, 2]
        for k in range(4):
            r, c = row + _ROW_STEPS[k], col + _COL_STEPS[k]
            if not (0 <= r < height and 0 <= c < width) or not _continues(z, points[r, c, 2], absolute32, relative32):
                continue
            # the neighbours' flat indices grow with i: a pointer for each finds them in one sweep
            while found[k] < size and pixels[found[k]] < pixels[i] + steps[k]:
                found[k] += 1
            j = found[k]
            if j < size and pixels[j] == pixels[i] + steps[k]:
                cosine = _dot(normals[i, 0], normals[i, 1], normals[i, 2], normals[j, 0], normals[j, 1], normals[j, 2])
                if np.float64(cosine) >= smooth_cosine:
                    targets[i, k] = j
            if labels[r, c] > 0:
                cell_row, cell_col = r // stride, c // stride
                cosine = _dot(
                    normals[i, 0],
                    normals[i, 1],
                    normals[i, 2],
                    coarse_normals[cell_row, cell_col, 0],
                    coarse_normals[cell_row, cell_col, 1],
                    coarse_normals[cell_row, cell_col, 2],
                )
                if np.float64(cosine) >= smooth_cosine:
                    label[i] = labels[r, c]
    _spread(label, targets, reach)
    for i in range(size):
        if label[i] > 0:
            labels[pixels[i] // width, pixels[i] % width] = label[i]


@njit(cache=True, nogil=True)
def _spread(label: np.ndarray, targets: np.ndarray, rounds: int) -> None:
    """Breadth-first, in place, for at most ``rounds`` links (``targets`` Nx4 linked nodes, -1 where none): each
    unlabelled node takes the label of a linked node one round after it got one; where several reach it in the
    same round the last in the front's order wins. The front keeps each node once, at its last place."""
    size = label.size
    front = np.flatnonzero(label)
    reached = np.empty(4 * size, dtype=np.int64)
    source = np.empty(4 * size, dtype=np.int64)
    seen = np.full(size, -1, dtype=np.int64)
    for round_ in range(rounds):
        count = 0
        for f in front:
            for k in range(4):
                t = targets[f, k]
                if t >= 0 and label[t] == 0:
                    reached[count], source[count] = t, f
                    count += 1
        if count == 0:
            break
        for q in range(count):
            label[reached[q]] = label[source[q]]
        # the next front: each node reached at the last place it was reached (earlier copies repeat its links)
        kept = 0
        order = np.empty(count, dtype=np.int64)
        for q in range(count - 1, -1, -1):
            if seen[reached[q]] != round_:
                seen[reached[q]] = round_
                order[kept] = reached[q]
                kept += 1
        front = order[:kept][::-1].copy()


@njit(cache=True, nogil=True)
def foot_candidates(
    near: np.ndarray,
    labels: np.ndarray,
    candidates: np.ndarray,
    heights: np.ndarray,
    floor: float,
    top: float,
    coarse_normals: np.ndarray,
    stride: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices, ascending, of the pixels ``near`` a segment (HxW uint8) that are unlabelled, no candidates of
    the segmentation and between ``floor`` and ``top`` above the plane (exclusive; compared in ``heights``' single
    precision), and their Nx3 normals: their cells' in ``coarse_normals`` (every ``stride``-th pixel)."""
    height, width = labels.shape
    floor32, top32 = np.float32(floor), np.float32(top)
    pixels = np.empty(height * width, dtype=np.int64)
    count = 0
    for row in range(height):
        for col in range(width):
            if near[row, col] and labels[row, col] == 0 and not candidates[row, col]:
                above = heights[row, col]
                if above > floor32 and above < top32:
                    pixels[count] = row * width + col
                    count += 1
    normals = np.empty((count, 3), dtype=coarse_normals.dtype)
    for i in range(count):
        row, col = pixels[i] // width // stride, pixels[i] % width // stride
        for axis in range(3):
            normals[i, axis] = coarse_normals[row, col, axis]
    return pixels[:count].copy(), normals
