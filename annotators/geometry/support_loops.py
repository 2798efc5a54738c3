"""The compiled loops behind :mod:`annotators.geometry.support_kernels` (numba, machine code cached on disk next to
this file). Importing this module imports numba; :mod:`~annotators.geometry.support` reaches it through
:mod:`~annotators.geometry.support_kernels` only, on first use."""

from __future__ import annotations

import numpy as np
from numba import njit

from annotators.geometry.footprint_loops import select_rank


@njit(cache=True, nogil=True)
def piece_summary(
    labels: np.ndarray, plane: np.ndarray, step: int, max_touching: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.support_kernels.piece_summary`."""
    rows, cols = labels.shape
    count = 0
    for r in range(rows):
        for c in range(cols):
            count = max(count, labels[r, c])
    count += 1
    sizes = np.zeros(count, dtype=np.int64)
    boxes = np.zeros((count, 4), dtype=np.int64)
    boxes[:, 0], boxes[:, 1] = cols, rows
    side = count if count <= max_touching else 0
    touching = np.zeros((side, side), dtype=np.int64)
    for r in range(rows):
        # runs of one label along the row: its size and box grow once per run
        label, start = labels[r, 0], 0
        for c in range(1, cols + 1):
            following = labels[r, c] if c < cols else -1
            if following != label:
                sizes[label] += c - start
                if label > 0:
                    boxes[label, 0], boxes[label, 1] = min(boxes[label, 0], start), min(boxes[label, 1], r)
                    boxes[label, 2], boxes[label, 3] = max(boxes[label, 2], c), r + 1
                    if side > 0 and following > 0:
                        touching[min(label, following), max(label, following)] += 1
                label, start = following, c
        if side > 0 and r + 1 < rows:
            for c in range(cols):
                above, below = labels[r, c], labels[r + 1, c]
                if above != below and above > 0 and below > 0:
                    touching[min(above, below), max(above, below)] += 1
    pair_count = 0
    for a in range(side):
        for b in range(side):
            pair_count += touching[a, b] > 0
    pairs = np.empty((pair_count, 2), dtype=np.int64)
    border = np.empty(pair_count, dtype=np.int64)
    pair_count = 0
    for a in range(side):
        for b in range(side):
            if touching[a, b] > 0:
                pairs[pair_count, 0], pairs[pair_count, 1] = a, b
                border[pair_count] = touching[a, b]
                pair_count += 1
    for label in range(count):
        if sizes[label] == 0 or label == 0:
            boxes[label] = 0
    # the sampled pixels with a height, read once in row-major order, then grouped by label (a counting sort)
    most = ((rows + step - 1) // step) * ((cols + step - 1) // step)
    sampled = np.empty(most, dtype=np.int64)
    read = np.empty((most, 3), dtype=np.float32)
    found = 0
    starts = np.zeros(count + 1, dtype=np.int64)
    for r in range(0, rows, step):
        for c in range(0, cols, step):
            label = labels[r, c]
            if label > 0 and np.isfinite(plane[r, c, 2]):
                sampled[found] = label
                read[found, 0], read[found, 1], read[found, 2] = plane[r, c, 0], plane[r, c, 1], plane[r, c, 2]
                found += 1
                starts[label + 1] += 1
    for label in range(1, count + 1):
        starts[label] += starts[label - 1]
    feet = np.empty((found, 2), dtype=np.float32)
    heights = np.empty(found, dtype=np.float64)
    filled = starts[:-1].copy()
    floor, ceiling, half = np.float32(-0.49), np.float32(0.49), np.float32(0.5)
    for k in range(found):
        index = filled[sampled[k]]
        feet[index, 0], feet[index, 1] = read[k, 0], read[k, 1]
        # the height as the float32 fraction of the numpy form's sort key, read back in float64
        shifted = np.float32(np.float32(min(max(read[k, 2], floor), ceiling)) + half)
        heights[index] = np.float64(shifted) - 0.5
        filled[sampled[k]] = index + 1
    quantiles = np.full((3, count), np.nan)
    shares = (0.05, 0.95, 0.99)
    for label in range(1, count):
        size = starts[label + 1] - starts[label]
        if size > 0:
            lowest = starts[label]
            for q in range(3):  # ranks increase: each lies among the values at or above the one before
                rank = starts[label] + int(np.rint(shares[q] * (size - 1)))
                select_rank(heights, lowest, starts[label + 1], rank)
                quantiles[q, label] = heights[rank]
                lowest = rank
    return sizes, quantiles[0], quantiles[1], quantiles[2], feet, starts, boxes, pairs, border


@njit(cache=True, nogil=True, error_model="numpy")
def footprint_steps(points: np.ndarray) -> np.ndarray:
    """The finite, positive ``|x / z|`` differences (float32) of horizontally adjacent pixels of HxWx3 ``points``
    (float32), row-major: what :func:`~annotators.geometry.grid_segmentation.pixel_footprint` takes the median of."""
    rows, cols = points.shape[0], points.shape[1]
    steps = np.empty(max(rows * (cols - 1), 0), dtype=np.float32)
    count = 0
    for r in range(rows):
        for c in range(cols - 1):
            step = np.float32(
                abs(
                    np.float32(points[r, c + 1, 0] / points[r, c + 1, 2])
                    - np.float32(points[r, c, 0] / points[r, c, 2])
                )
            )
            if np.isfinite(step) and step > 0:
                steps[count] = step
                count += 1
    return steps[:count]


@njit(cache=True, nogil=True)
def unsupported_candidates(
    pairs: np.ndarray, sizes: np.ndarray, low: np.ndarray, high: np.ndarray, tolerance: float, reach_down: float
) -> np.ndarray:
    """See :func:`annotators.geometry.support_kernels.unsupported_candidates`."""
    chosen = np.empty((2 * pairs.shape[0], 2), dtype=np.int64)
    count = 0
    for way in range(2):
        for k in range(pairs.shape[0]):
            piece, holder = pairs[k, way], pairs[k, 1 - way]
            if (
                low[piece] > low[holder] + tolerance
                and low[piece] < low[holder] + reach_down * (high[holder] - low[holder])
                and sizes[holder] >= sizes[piece]
            ):
                chosen[count, 0], chosen[count, 1] = piece, holder
                count += 1
    return chosen[:count]


@njit(cache=True, nogil=True)
def appendage_candidates(
    pairs: np.ndarray,
    border: np.ndarray,
    sizes: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    top: np.ndarray,
    small_share: float,
    tolerance: float,
    min_boundary: float,
    boundary_share: float,
) -> np.ndarray:
    """See :func:`annotators.geometry.support_kernels.appendage_candidates`."""
    chosen = np.empty((2 * pairs.shape[0], 2), dtype=np.int64)
    count = 0
    for way in range(2):
        for k in range(pairs.shape[0]):
            piece, owner = pairs[k, way], pairs[k, 1 - way]
            if (
                sizes[piece] <= small_share * sizes[owner]
                and (low[piece] >= low[owner] - tolerance or 0.5 * (low[piece] + high[piece]) >= low[owner])
                and high[piece] <= top[owner] + tolerance
                and border[k] >= max(min_boundary, boundary_share * np.sqrt(np.float64(sizes[piece])))
            ):
                chosen[count, 0], chosen[count, 1] = piece, owner
                count += 1
    return chosen[:count]


@njit(cache=True, nogil=True)
def raster_vertices(inner: np.ndarray, outer: np.ndarray, cell: float) -> tuple[np.ndarray, int, int]:
    """See :func:`annotators.geometry.support_kernels.raster_vertices`."""
    count = inner.shape[0] + outer.shape[0]
    low_u, low_v = np.float32(np.inf), np.float32(np.inf)
    for polygon in (inner, outer):
        for k in range(polygon.shape[0]):
            low_u, low_v = min(low_u, polygon[k, 0]), min(low_v, polygon[k, 1])
    step = np.float32(cell)
    vertices = np.empty((count, 2), dtype=np.int32)
    width, height = 0, 0
    index = 0
    for polygon in (inner, outer):
        for k in range(polygon.shape[0]):
            u = np.int32(np.rint(np.float32(np.float32(polygon[k, 0] - low_u) / step)))
            v = np.int32(np.rint(np.float32(np.float32(polygon[k, 1] - low_v) / step)))
            vertices[index, 0], vertices[index, 1] = u, v
            width, height = max(width, u + 1), max(height, v + 1)
            index += 1
    return vertices, width, height


@njit(cache=True, nogil=True)
def kept_labels(labels: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.support_kernels.kept_labels`."""
    rows, cols = labels.shape
    kept = np.empty((rows, cols), dtype=labels.dtype)
    for r in range(rows):
        for c in range(cols):
            label = labels[r, c]
            kept[r, c] = label if keep[label] else 0
    return kept


_INSIDE_MARGIN = 1e-12
"""A point lies strictly inside an edge only this far (cross product, square metres) or more: points nearer an
edge than rounding could blur are kept."""


@njit(cache=True, nogil=True)
def hull_candidates(points: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.support_kernels.hull_candidates`."""
    count = points.shape[0]
    left, bottom, right, top = 0, 0, 0, 0
    for k in range(1, count):
        u, v = points[k, 0], points[k, 1]
        if u < points[left, 0]:
            left = k
        if v < points[bottom, 1]:
            bottom = k
        if u > points[right, 0]:
            right = k
        if v > points[top, 1]:
            top = k
    corner = np.empty((4, 2), dtype=np.float64)  # counter-clockwise: leftmost, lowest, rightmost, highest
    for d, index in enumerate((left, bottom, right, top)):
        corner[d, 0], corner[d, 1] = points[index, 0], points[index, 1]
    keep = np.ones(count, dtype=np.bool_)
    kept = count
    for k in range(count):
        u, v = np.float64(points[k, 0]), np.float64(points[k, 1])
        inside = True
        for d in range(4):
            following = (d + 1) % 4
            eu, ev = corner[following, 0] - corner[d, 0], corner[following, 1] - corner[d, 1]
            if eu * (v - corner[d, 1]) - ev * (u - corner[d, 0]) <= _INSIDE_MARGIN:
                inside = False
                break
        if inside:
            keep[k] = False
            kept -= 1
    candidates = np.empty((kept, 2), dtype=points.dtype)
    index = 0
    for k in range(count):
        if keep[k]:
            candidates[index, 0], candidates[index, 1] = points[k, 0], points[k, 1]
            index += 1
    return candidates


@njit(cache=True, nogil=True)
def box_label_points(labels: np.ndarray, points: np.ndarray, label: int, box: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.support_kernels.box_label_points`."""
    x0, y0, x1, y1 = box[0], box[1], box[2], box[3]
    count = 0
    for r in range(y0, y1):
        for c in range(x0, x1):
            if labels[r, c] == label:
                count += 1
    found = np.empty((count, points.shape[2]), dtype=points.dtype)
    index = 0
    for r in range(y0, y1):
        for c in range(x0, x1):
            if labels[r, c] == label:
                for k in range(points.shape[2]):
                    found[index, k] = points[r, c, k]
                index += 1
    return found


@njit(cache=True, nogil=True)
def principal_span(feet: np.ndarray, share: float) -> float:
    """See :func:`annotators.geometry.support_kernels.principal_span`."""
    count = feet.shape[0]
    if count < 2:
        return 0.0
    mean_u, mean_v = 0.0, 0.0
    for i in range(count):
        mean_u += feet[i, 0]
        mean_v += feet[i, 1]
    mean_u, mean_v = mean_u / count, mean_v / count
    uu, uv, vv = 0.0, 0.0, 0.0
    for i in range(count):
        du, dv = feet[i, 0] - mean_u, feet[i, 1] - mean_v
        uu += du * du
        uv += du * dv
        vv += dv * dv
    angle = 0.5 * np.arctan2(2.0 * uv, uu - vv)  # the major axis of the scatter
    axis_u, axis_v = np.cos(angle), np.sin(angle)
    along = np.empty(count)
    for i in range(count):
        along[i] = (feet[i, 0] - mean_u) * axis_u + (feet[i, 1] - mean_v) * axis_v
    along.sort()
    return _linear_quantile(along, 1.0 - share) - _linear_quantile(along, share)


@njit(cache=True, nogil=True)
def _linear_quantile(ordered: np.ndarray, share: float) -> float:
    """The ``share`` quantile of sorted values, interpolated linearly between the two nearest ranks as NumPy's
    default method does."""
    position = share * (ordered.shape[0] - 1)
    below = int(np.floor(position))
    above = min(below + 1, ordered.shape[0] - 1)
    fraction = position - below
    gap = ordered[above] - ordered[below]
    if fraction >= 0.5:
        return ordered[above] - gap * (1.0 - fraction)
    return ordered[below] + gap * fraction


@njit(cache=True, nogil=True)
def narrowest_slice_span(points: np.ndarray, bottoms: np.ndarray, band: float, min_slice: int, share: float) -> float:
    """See :func:`annotators.geometry.support_kernels.narrowest_slice_span`."""
    narrowest = np.inf
    inside = np.empty((points.shape[0], 2))
    for bottom in bottoms:
        top = bottom + band
        count = 0
        for i in range(points.shape[0]):
            if points[i, 2] >= bottom and points[i, 2] < top:
                inside[count, 0], inside[count, 1] = points[i, 0], points[i, 1]
                count += 1
        if count >= min_slice:
            narrowest = min(narrowest, principal_span(inside[:count], share))
    return narrowest
