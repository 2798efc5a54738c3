"""Compiled loops over the organized grid for the segmentation primitives: passes over pixels or pixel pairs that
whole-array numpy would make with many temporaries, and loops over a few pieces that numpy would make call by call.

The kernels give exactly what the numpy or OpenCV expressions they replace give (integer and boolean results,
values picked from the input unchanged, sums added in the same order), except :func:`symmetric_eigen`, which
agrees with ``np.linalg.eigh`` to rounding. They are compiled by numba on first use (numba is imported then, not
with this module) and the machine code is cached on disk next to this file.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np


def _compiled_on_first_use(function: Callable[..., Any]) -> Callable[..., Any]:
    """``function`` compiled by numba (no Python objects, cached on disk) when it is first called."""

    @functools.cache
    def compiled() -> Callable[..., Any]:
        from numba import njit

        return njit(cache=True, nogil=True)(function)

    @functools.wraps(function)
    def call(*args: Any) -> Any:
        return compiled()(*args)

    return call


@_compiled_on_first_use
def touching_keys(labels: np.ndarray, base: int) -> np.ndarray:
    """``min(a, b) * base + max(a, b)`` (int64) of every horizontally or vertically adjacent pixel pair of
    different non-zero labels ``a``, ``b`` (HxW integer labels), once per pixel pair, in no particular order."""
    keys = np.empty(2 * labels.size, dtype=np.int64)
    count = 0
    rows, cols = labels.shape
    for r in range(rows):
        for c in range(cols):
            a = labels[r, c]
            if a <= 0:
                continue
            if c + 1 < cols:
                b = labels[r, c + 1]
                if b > 0 and b != a:
                    keys[count] = min(a, b) * base + max(a, b)
                    count += 1
            if r + 1 < rows:
                b = labels[r + 1, c]
                if b > 0 and b != a:
                    keys[count] = min(a, b) * base + max(a, b)
                    count += 1
    return keys[:count]


@_compiled_on_first_use
def facing_values(
    rows: np.ndarray, cols: np.ndarray, target: np.ndarray, values: np.ndarray, radius: int
) -> np.ndarray:
    """The ``values`` (HxW) of the ``target`` pixels (HxW bool) within ``radius`` pixels (a square window) of any
    of the marked pixels ``rows``, ``cols`` (distinct, at least one), in row-major order: what
    ``values[box][cv2.dilate(marked, ones(2 radius + 1)) & target[box]]`` gives on the box of the marked pixels
    grown by ``radius``."""
    height, width = target.shape
    r0, c0 = max(rows.min() - radius, 0), max(cols.min() - radius, 0)
    r1, c1 = min(rows.max() + radius + 1, height), min(cols.max() + radius + 1, width)
    box_rows, box_cols = r1 - r0, c1 - c0
    sums = np.zeros((box_rows + 1, box_cols + 1), dtype=np.int32)  # 2-D prefix sums of the marked pixels
    for k in range(rows.size):
        sums[rows[k] - r0 + 1, cols[k] - c0 + 1] = 1
    for r in range(1, box_rows + 1):
        for c in range(1, box_cols + 1):
            sums[r, c] += sums[r - 1, c] + sums[r, c - 1] - sums[r - 1, c - 1]
    found = np.empty(box_rows * box_cols, dtype=values.dtype)
    count = 0
    for r in range(box_rows):
        top, bottom = max(r - radius, 0), min(r + radius + 1, box_rows)
        for c in range(box_cols):
            if not target[r0 + r, c0 + c]:
                continue
            left, right = max(c - radius, 0), min(c + radius + 1, box_cols)
            if sums[bottom, right] - sums[top, right] - sums[bottom, left] + sums[top, left] > 0:
                found[count] = values[r0 + r, c0 + c]
                count += 1
    return found[:count]


@_compiled_on_first_use
def shadowed_near(occluding: np.ndarray, unmeasured: np.ndarray, shadow_radius: int, near_radius: int) -> np.ndarray:
    """HxW bool: the pixels within ``near_radius`` (a square window) of an occluder (``occluding``, HxW bool) or
    of its shadow - the 4-connected unmeasured regions (``unmeasured``) that touch it (8-neighbours), where they
    lie within ``shadow_radius`` of it. What ``cv2.dilate`` with square kernels of ones and
    ``cv2.connectedComponents`` give."""
    rows, cols = occluding.shape

    def box_sums(marked: np.ndarray) -> np.ndarray:  # sums[r, c]: the marked pixels above and left of (r, c)
        sums = np.zeros((rows + 1, cols + 1), dtype=np.int32)
        for r in range(rows):
            running = 0
            for c in range(cols):
                running += marked[r, c]
                sums[r + 1, c + 1] = sums[r, c + 1] + running
        return sums

    def any_within(sums: np.ndarray, r: int, c: int, radius: int) -> bool:
        r0, r1 = max(r - radius, 0), min(r + radius + 1, rows)
        c0, c1 = max(c - radius, 0), min(c + radius + 1, cols)
        return sums[r1, c1] - sums[r0, c1] - sums[r1, c0] + sums[r0, c0] > 0

    occluder_sums = box_sums(occluding)
    region = occluding.copy()
    stack = np.empty(rows * cols, dtype=np.int64)
    seen = np.zeros((rows, cols), dtype=np.bool_)
    top = 0
    for r in range(rows):  # the shadow's seeds: unmeasured pixels beside the occluder
        for c in range(cols):
            if unmeasured[r, c] and any_within(occluder_sums, r, c, 1):
                seen[r, c] = True
                stack[top] = r * cols + c
                top += 1
    while top > 0:  # their 4-connected unmeasured regions, kept within reach of the occluder
        top -= 1
        r, c = stack[top] // cols, stack[top] % cols
        if any_within(occluder_sums, r, c, shadow_radius):
            region[r, c] = True
        for dr, dc in ((0, -1), (0, 1), (-1, 0), (1, 0)):
            nr, nc = r + dr, c + dc
            if 0 <= nr < rows and 0 <= nc < cols and unmeasured[nr, nc] and not seen[nr, nc]:
                seen[nr, nc] = True
                stack[top] = nr * cols + nc
                top += 1
    region_sums = box_sums(region)
    near = np.zeros((rows, cols), dtype=np.bool_)
    for r in range(rows):
        for c in range(cols):
            near[r, c] = any_within(region_sums, r, c, near_radius)
    return near


@_compiled_on_first_use
def upsampled_labels(
    labels: np.ndarray,
    coarse_depth: np.ndarray,
    depth: np.ndarray,
    keep: np.ndarray,
    step: int,
    absolute: float,
    relative: float,
) -> np.ndarray:
    """HxW int32 (the shape of ``depth``, float32): each pixel's label in ``labels`` (every ``step``-th pixel's)
    where ``keep`` (HxW bool) allows it and no depth jump (:func:`depth_jump`'s float32 arithmetic) parts it from
    its coarse sample's depth ``coarse_depth``; 0 elsewhere."""
    rows, cols = depth.shape
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    fine = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            label = labels[r // step, c // step]
            if label == 0 or not keep[r, c]:
                continue
            z, sample = depth[r, c], coarse_depth[r // step, c // step]
            nearer = sample if np.isnan(z) else (z if np.isnan(sample) else min(z, sample))
            if not abs(z - sample) > nearer * relative32 + absolute32:
                fine[r, c] = label
    return fine


@_compiled_on_first_use
def label_pixels(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The flat indices of the labelled pixels of HxW ``labels`` sorted by label (increasing within one), ``starts``
    so label k owns ``pixels[starts[k]:starts[k + 1]]``, and each label's box ``(x0, y0, x1, y1)`` (exclusive;
    row k for label k, zeros for a label without pixels)."""
    rows, cols = labels.shape
    count = 0
    for r in range(rows):
        for c in range(cols):
            count = max(count, labels[r, c])
    starts = np.zeros(count + 2, dtype=np.int64)
    boxes = np.zeros((count + 1, 4), dtype=np.int64)
    boxes[:, 0], boxes[:, 1] = cols, rows
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            if label > 0:
                starts[label + 1] += 1
                boxes[label, 0], boxes[label, 1] = min(boxes[label, 0], c), min(boxes[label, 1], r)
                boxes[label, 2], boxes[label, 3] = max(boxes[label, 2], c + 1), max(boxes[label, 3], r + 1)
    for label in range(1, count + 2):
        starts[label] += starts[label - 1]
    pixels = np.empty(starts[count + 1], dtype=np.int64)
    filled = starts[:-1].copy()
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            if label > 0:
                pixels[filled[label]] = r * cols + c
                filled[label] += 1
    for label in range(count + 1):
        if starts[label + 1] == starts[label]:
            boxes[label] = 0
    return pixels, starts, boxes


@_compiled_on_first_use
def label_moments(
    labels: np.ndarray, values: np.ndarray, means: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per label ``0..count-1`` of N ``labels``: the number of values, the sums of the 3xN ``values`` (float64) and
    the sums of the products ``(v_i - m_i) (v_j - m_j)`` for ``i <= j`` in the order 00, 01, 02, 11, 12, 22, with
    ``m`` the label's row of ``means`` (Kx3; zeros for plain second moments). Added up in the order of the values,
    as ``np.bincount`` adds its weights, so the sums are the same."""
    counts = np.zeros(count, dtype=np.int64)
    sums = np.zeros((count, 3))
    products = np.zeros((count, 6))
    for k in range(labels.size):
        label = labels[k]
        a, b, c = values[0, k] - means[label, 0], values[1, k] - means[label, 1], values[2, k] - means[label, 2]
        counts[label] += 1
        sums[label, 0] += values[0, k]
        sums[label, 1] += values[1, k]
        sums[label, 2] += values[2, k]
        products[label, 0] += a * a
        products[label, 1] += a * b
        products[label, 2] += a * c
        products[label, 3] += b * b
        products[label, 4] += b * c
        products[label, 5] += c * c
    return counts, sums, products


@_compiled_on_first_use
def label_centres(labels: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Per label ``0..count-1`` of HxW ``labels`` (label 0 counted too): the number of pixels and the sums of
    their rows and columns (Kx2 float64; exact, they are integers)."""
    counts = np.zeros(count, dtype=np.int64)
    sums = np.zeros((count, 2))
    rows, cols = labels.shape
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            counts[label] += 1
            sums[label, 0] += r
            sums[label, 1] += c
    return counts, sums


@_compiled_on_first_use
def grouped_pixels(labels: np.ndarray, where: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The flat indices of the ``where`` pixels (HxW bool) with a label 1..count in HxW ``labels``, sorted by label
    (row-major within one), and ``starts`` (count + 2) so label k owns ``pixels[starts[k]:starts[k + 1]]``."""
    rows, cols = labels.shape
    starts = np.zeros(count + 2, dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if where[r, c] and labels[r, c] > 0:
                starts[labels[r, c] + 1] += 1
    for label in range(1, count + 2):
        starts[label] += starts[label - 1]
    pixels = np.empty(starts[count + 1], dtype=np.int64)
    filled = starts[:-1].copy()
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            if where[r, c] and label > 0:
                pixels[filled[label]] = r * cols + c
                filled[label] += 1
    return pixels, starts


@_compiled_on_first_use
def symmetric_eigen(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (Kx3, increasing) and unit eigenvectors (Kx3x3, column i for value i) of K symmetric 3x3
    matrices, by cyclic Jacobi rotations to full double precision: ``np.linalg.eigh`` for many small matrices
    without a LAPACK call each (the values agree to rounding; a vector's sign may differ)."""
    count = matrices.shape[0]
    values = np.empty((count, 3))
    vectors = np.empty((count, 3, 3))
    a = np.empty((3, 3))
    v = np.empty((3, 3))
    for k in range(count):
        for i in range(3):
            for j in range(3):
                a[i, j] = matrices[k, i, j]
                v[i, j] = 1.0 if i == j else 0.0
        for _ in range(50):
            off = a[0, 1] * a[0, 1] + a[0, 2] * a[0, 2] + a[1, 2] * a[1, 2]
            scale = a[0, 0] * a[0, 0] + a[1, 1] * a[1, 1] + a[2, 2] * a[2, 2]
            if off <= 1e-36 * scale or off == 0.0 or not np.isfinite(off):
                break
            for p, q in ((0, 1), (0, 2), (1, 2)):
                if a[p, q] == 0.0:
                    continue
                theta = (a[q, q] - a[p, p]) / (2.0 * a[p, q])
                t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for r in range(3):  # A <- A J (columns p, q)
                    arp, arq = a[r, p], a[r, q]
                    a[r, p], a[r, q] = c * arp - s * arq, s * arp + c * arq
                for r in range(3):  # A <- J^T A (rows p, q)
                    apr, aqr = a[p, r], a[q, r]
                    a[p, r], a[q, r] = c * apr - s * aqr, s * apr + c * aqr
                for r in range(3):
                    vrp, vrq = v[r, p], v[r, q]
                    v[r, p], v[r, q] = c * vrp - s * vrq, s * vrp + c * vrq
        first, middle, last = 0, 1, 2  # the diagonal's order, by three comparisons
        if a[first, first] > a[middle, middle]:
            first, middle = middle, first
        if a[middle, middle] > a[last, last]:
            middle, last = last, middle
        if a[first, first] > a[middle, middle]:
            first, middle = middle, first
        for i, column in enumerate((first, middle, last)):
            values[k, i] = a[column, column]
            for r in range(3):
                vectors[k, r, i] = v[r, column]
    return values, vectors


@_compiled_on_first_use
def organized_normals(points: np.ndarray, step: int, smoothing: int, absolute: float, relative: float) -> np.ndarray:
    """HxWx3 float32 unit normals facing the camera of an organized HxWx3 float32 cloud (NaN where unknown):
    the cross product of the central differences across ``step`` pixels, summed over a ``smoothing`` x
    ``smoothing`` window (each raw normal of unit length; none where a neighbour is missing or across a depth jump
    of more than ``absolute + relative * nearer depth``), then normalised. The grid ``step`` pixels wide along the
    border gets none (see :func:`annotators.cloud.normals.grid_normals`)."""
    height, width = points.shape[0], points.shape[1]
    normals = np.full((height, width, 3), np.nan, dtype=np.float32)
    if height <= 2 * step or width <= 2 * step:
        return normals
    rows, cols = height - 2 * step, width - 2 * step
    raw = np.zeros((rows, cols, 3), dtype=np.float32)
    broken = np.ones((rows, cols), dtype=np.bool_)
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    for r in range(rows):
        for c in range(cols):
            pr, pc = r + step, c + step
            z = points[pr, pc, 2]
            if not np.isfinite(z):
                continue
            jump = False
            for nr, nc in ((pr, pc - step), (pr, pc + step), (pr - step, pc), (pr + step, pc)):
                other = points[nr, nc, 2]
                if not np.isfinite(other) or abs(z - other) > min(z, other) * relative32 + absolute32:
                    jump = True
            if jump:
                continue
            broken[r, c] = False
            h0 = points[pr, pc + step, 0] - points[pr, pc - step, 0]
            h1 = points[pr, pc + step, 1] - points[pr, pc - step, 1]
            h2 = points[pr, pc + step, 2] - points[pr, pc - step, 2]
            v0 = points[pr + step, pc, 0] - points[pr - step, pc, 0]
            v1 = points[pr + step, pc, 1] - points[pr - step, pc, 1]
            v2 = points[pr + step, pc, 2] - points[pr - step, pc, 2]
            n0, n1, n2 = h1 * v2 - h2 * v1, h2 * v0 - h0 * v2, h0 * v1 - h1 * v0
            length = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            if not length > 0:
                length = np.float32(1.0)
            sign = np.float32(-1.0) if n0 * points[pr, pc, 0] + n1 * points[pr, pc, 1] + n2 * z > 0 else np.float32(1.0)
            scale = sign / length
            for axis, value in enumerate((n0 * scale, n1 * scale, n2 * scale)):
                raw[r, c, axis] = value if np.isfinite(value) else np.float32(0.0)
    radius = smoothing // 2
    for r in range(rows):
        for c in range(cols):
            if broken[r, c]:
                continue
            s0, s1, s2 = 0.0, 0.0, 0.0
            for wr in range(max(r - radius, 0), min(r + smoothing - radius, rows)):
                for wc in range(max(c - radius, 0), min(c + smoothing - radius, cols)):
                    s0 += raw[wr, wc, 0]
                    s1 += raw[wr, wc, 1]
                    s2 += raw[wr, wc, 2]
            length = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
            if not length > 0:
                length = 1.0
            normals[r + step, c + step, 0] = np.float32(s0 / length)
            normals[r + step, c + step, 1] = np.float32(s1 / length)
            normals[r + step, c + step, 2] = np.float32(s2 / length)
    return normals
