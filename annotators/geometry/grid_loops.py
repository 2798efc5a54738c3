"""The compiled loops behind :mod:`annotators.geometry.grid_kernels` (numba, machine code cached on disk next to
this file). Importing this module imports numba; the segmentation modules reach it through
:mod:`~annotators.geometry.grid_kernels` only, on first use."""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from annotators.geometry.footprint_loops import ranked_values


@njit(cache=True, nogil=True)
def _looked_up(table: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """HxW int32: ``table[keys[r, c]]`` at every pixel (a renumbering of HxW ``keys``)."""
    rows, cols = keys.shape
    labels = np.empty((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            labels[r, c] = table[keys[r, c]]
    return labels


@njit(cache=True, nogil=True)
def touching_keys(labels: np.ndarray, base: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.touching_keys`."""
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


@njit(cache=True, nogil=True)
def near_label_pairs(labels: np.ndarray, reach: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.near_label_pairs`."""
    count = 0
    rows, cols = labels.shape
    for r in range(rows):
        for c in range(cols):
            count = max(count, labels[r, c])
    near = np.zeros((count + 1, count + 1), dtype=np.bool_)
    for r in range(rows):
        for c in range(cols):
            a = labels[r, c]
            if a <= 0:
                continue
            for dy in range(0, min(reach, rows - 1 - r) + 1):
                first = 1 if dy == 0 else max(-reach, -c)
                for dx in range(first, min(reach, cols - 1 - c) + 1):
                    b = labels[r + dy, c + dx]
                    if b > 0 and b != a:
                        near[min(a, b), max(a, b)] = True
    found = 0
    for a in range(count + 1):
        for b in range(count + 1):
            found += near[a, b]
    pairs = np.empty((found, 2), dtype=np.int64)
    found = 0
    for a in range(count + 1):
        for b in range(count + 1):
            if near[a, b]:
                pairs[found, 0], pairs[found, 1] = a, b
                found += 1
    return pairs


@njit(cache=True, nogil=True)
def facing_values(
    rows: np.ndarray, cols: np.ndarray, target: np.ndarray, values: np.ndarray, radius: int
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.facing_values`."""
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


@njit(cache=True, nogil=True)
def shadowed_near(occluding: np.ndarray, unmeasured: np.ndarray, shadow_radius: int, near_radius: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.shadowed_near`."""
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


@njit(cache=True, nogil=True)
def upsampled_labels(
    labels: np.ndarray,
    coarse_depth: np.ndarray,
    depth: np.ndarray,
    keep: np.ndarray,
    step: int,
    absolute: float,
    relative: float,
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.upsampled_labels`."""
    rows, cols = depth.shape
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    fine = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        coarse_row = r // step
        for coarse_col in range((cols + step - 1) // step):  # cell by cell: an unlabelled cell is skipped whole
            label = labels[coarse_row, coarse_col]
            if label == 0:
                continue
            sample = coarse_depth[coarse_row, coarse_col]
            for c in range(coarse_col * step, min(coarse_col * step + step, cols)):
                if not keep[r, c]:
                    continue
                z = depth[r, c]
                nearer = sample if np.isnan(z) else (z if np.isnan(sample) else min(z, sample))
                if not abs(z - sample) > nearer * relative32 + absolute32:
                    fine[r, c] = label
    return fine


@njit(cache=True, nogil=True)
def _run_end(labels: np.ndarray, r: int, c: int) -> int:
    """The column after the run of equal labels that starts at ``labels[r, c]`` (exclusive)."""
    label, cols = labels[r, c], labels.shape[1]
    c += 1
    while c < cols and labels[r, c] == label:
        c += 1
    return c


@njit(cache=True, nogil=True)
def label_pixels(labels: np.ndarray, top: int, left: int, width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.label_pixels` (row by row, one run of equal labels at a time)."""
    rows, cols = labels.shape
    count = 0
    for r in range(rows):
        for c in range(cols):
            count = max(count, labels[r, c])
    starts = np.zeros(count + 2, dtype=np.int64)
    boxes = np.zeros((count + 1, 4), dtype=np.int64)
    boxes[:, 0], boxes[:, 1] = cols, rows
    for r in range(rows):
        c = 0
        while c < cols:
            label = labels[r, c]
            end = _run_end(labels, r, c)
            if label > 0:
                starts[label + 1] += end - c
                boxes[label, 0], boxes[label, 1] = min(boxes[label, 0], c), min(boxes[label, 1], r)
                boxes[label, 2], boxes[label, 3] = max(boxes[label, 2], end), max(boxes[label, 3], r + 1)
            c = end
    for label in range(1, count + 2):
        starts[label] += starts[label - 1]
    pixels = np.empty(starts[count + 1], dtype=np.int64)
    filled = starts[:-1].copy()
    for r in range(rows):
        c = 0
        while c < cols:
            label = labels[r, c]
            end = _run_end(labels, r, c)
            if label > 0:
                first, offset = filled[label], (r + top) * width + left
                for k in range(c, end):
                    pixels[first + k - c] = offset + k
                filled[label] = first + end - c
            c = end
    for label in range(count + 1):
        if starts[label + 1] == starts[label]:
            boxes[label] = 0
    return pixels, starts, boxes


@njit(cache=True, nogil=True)
def fill_label_masks(labels: np.ndarray, slots: np.ndarray, masks: np.ndarray, top: int, left: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.label_masks` (row by row, one run of equal labels at a time)."""
    rows, cols = labels.shape
    boxes = np.zeros((masks.shape[0], 4), dtype=np.int64)
    boxes[:, 0], boxes[:, 1] = cols, rows
    seen = np.zeros(masks.shape[0], dtype=np.bool_)
    for r in range(rows):
        c = 0
        while c < cols:
            label = labels[r, c]
            end = _run_end(labels, r, c)
            if 0 < label < slots.size and slots[label] >= 0:
                slot = slots[label]
                masks[slot, r + top, c + left : end + left] = True
                seen[slot] = True
                boxes[slot, 0], boxes[slot, 1] = min(boxes[slot, 0], c), min(boxes[slot, 1], r)
                boxes[slot, 2], boxes[slot, 3] = max(boxes[slot, 2], end), max(boxes[slot, 3], r + 1)
            c = end
    for slot in range(masks.shape[0]):
        if not seen[slot]:
            boxes[slot] = 0
    return boxes


@njit(cache=True, nogil=True)
def label_moments(
    labels: np.ndarray, values: np.ndarray, means: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.label_moments`."""
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


@njit(cache=True, nogil=True)
def label_centres(labels: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.label_centres`."""
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


@njit(cache=True, nogil=True)
def grouped_pixels(labels: np.ndarray, where: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.grouped_pixels`."""
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


@njit(cache=True, nogil=True)
def symmetric_eigen(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.symmetric_eigen`."""
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


@njit(cache=True, nogil=True)
def organized_normals(points: np.ndarray, step: int, smoothing: int, absolute: float, relative: float) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.organized_normals`."""
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


@njit(cache=True, nogil=True)
def piece_near(
    own: np.ndarray,
    window: tuple[int, int, int],
    occluding: np.ndarray,
    depth: np.ndarray,
    radius: int,
    points: np.ndarray,
) -> tuple[int, float, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.piece_near`."""
    width, y0, x0 = window
    rows, cols = own // width, own % width
    facing = facing_values(rows, cols, occluding, depth, radius)
    total, known = 0.0, 0
    for value in facing:
        if np.isfinite(value):
            total += value
            known += 1
    occluder_depth = total / known if known else np.nan
    total, known = 0.0, 0
    for k in range(own.size):
        value = depth[rows[k], cols[k]]
        if np.isfinite(value):
            total += value
            known += 1
    piece_depth = total / known if known else np.nan
    grid_cols = points.shape[1]
    flat = (rows + y0) * grid_cols + cols + x0
    xyz = np.empty((own.size, 3), dtype=np.float32)
    centre = np.zeros(3)
    count = 0
    for k in range(own.size):
        r, c = rows[k] + y0, cols[k] + x0
        if np.isfinite(points[r, c, 0]) and np.isfinite(points[r, c, 1]) and np.isfinite(points[r, c, 2]):
            for axis in range(3):
                xyz[count, axis] = points[r, c, axis]
                centre[axis] += points[r, c, axis]
            count += 1
    if count:
        centre /= count
    pixel = np.array([rows.mean() + y0, cols.mean() + x0])
    return facing.size, piece_depth, occluder_depth, flat, xyz[:count], centre, pixel


@njit(cache=True, nogil=True)
def boundary_pairs(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    reach: int,
    absolute: float,
    relative: float,
    near_factor: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.boundary_pairs`."""
    rows, cols = labels.shape
    base = np.int64(labels.max()) + 1
    size = 2 * labels.size
    keys = np.empty(size, dtype=np.int64)
    jumps = np.empty(size, dtype=np.bool_)
    near = np.empty(size, dtype=np.bool_)
    dots = np.empty(size, dtype=np.float32)
    convex = np.empty(size, dtype=np.float32)
    absolute32, relative32, near32 = np.float32(absolute), np.float32(relative), np.float32(near_factor)
    count = 0
    for down, right in ((0, 1), (1, 0)):
        for r in range(rows - down):
            for c in range(cols - right):
                a, b = labels[r, c], labels[r + down, c + right]
                if a == b or a <= 0 or b <= 0:
                    continue
                keys[count] = min(a, b) * base + max(a, b)
                za, zb = points[r, c, 2], points[r + down, c + right, 2]
                nearer = zb if np.isnan(za) else (za if np.isnan(zb) else min(za, zb))
                jumps[count] = abs(za - zb) > nearer * relative32 + absolute32
                d0 = points[r, c, 0] - points[r + down, c + right, 0]
                d1 = points[r, c, 1] - points[r + down, c + right, 1]
                d2 = za - zb
                near[count] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) <= near32 * nearer
                dots[count], convex[count] = np.nan, np.nan
                br, bc = r - reach * down, c - reach * right
                ar, ac = r + (reach + 1) * down, c + (reach + 1) * right
                if br >= 0 and bc >= 0 and ar < rows and ac < cols and labels[br, bc] == a and labels[ar, ac] == b:
                    n0 = normals[br, bc, 0] - normals[ar, ac, 0]
                    n1 = normals[br, bc, 1] - normals[ar, ac, 1]
                    n2 = normals[br, bc, 2] - normals[ar, ac, 2]
                    o0 = points[br, bc, 0] - points[ar, ac, 0]
                    o1 = points[br, bc, 1] - points[ar, ac, 1]
                    o2 = points[br, bc, 2] - points[ar, ac, 2]
                    dots[count] = (
                        normals[br, bc, 0] * normals[ar, ac, 0]
                        + normals[br, bc, 1] * normals[ar, ac, 1]
                        + normals[br, bc, 2] * normals[ar, ac, 2]
                    )
                    convex[count] = (n0 * o0 + n1 * o1 + n2 * o2) / np.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
                count += 1
    return keys[:count], jumps[:count], near[:count], dots[:count], convex[:count]


@njit(cache=True, nogil=True)
def standing_candidates(
    heights: np.ndarray,
    mask: np.ndarray,
    points: np.ndarray,
    basis: np.ndarray,
    raster: np.ndarray,
    low: np.ndarray,
    cell: float,
    min_height: float,
    max_height: float,
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.standing_candidates`."""
    rows, cols = heights.shape
    candidates = np.zeros((rows, cols), dtype=np.bool_)
    cell32, low32, high32 = np.float32(cell), np.float32(min_height), np.float32(max_height)
    for r in range(rows):
        for c in range(cols):
            height = heights[r, c]
            if not (mask[r, c] and height > low32 and height < high32):
                continue
            x, y, z = points[r, c, 0], points[r, c, 1], points[r, c, 2]
            u = x * basis[0, 0] + y * basis[1, 0] + z * basis[2, 0]
            v = x * basis[0, 1] + y * basis[1, 1] + z * basis[2, 1]
            column, row = np.floor((u - low[0]) / cell32), np.floor((v - low[1]) / cell32)
            if 0 <= column < raster.shape[1] and 0 <= row < raster.shape[0]:
                candidates[r, c] = raster[int(row), int(column)] > 0
    return candidates


@njit(cache=True, nogil=True)
def connected_parts(region: np.ndarray, min_points: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.connected_parts`."""
    return _equal_parts(region, min_points)


@njit(cache=True, nogil=True)
def label_pieces(labels: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.label_pieces`."""
    return _equal_parts(labels, 1)


@njit(cache=True, nogil=True)
def _equal_parts(values: np.ndarray, min_points: int) -> np.ndarray:
    """HxW int32: the 4-connected parts of the pixels whose ``values`` are non-zero, neighbours joined where their
    values are equal, with at least ``min_points`` pixels, labelled 1..n in the raster order of their first pixels;
    0 elsewhere."""
    rows, cols = values.shape
    provisional = np.zeros((rows, cols), dtype=np.int32)
    parent = np.empty(rows * cols + 1, dtype=np.int32)
    count = 0

    def root(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    for r in range(rows):
        for c in range(cols):
            value = values[r, c]
            if not value:
                continue
            left = provisional[r, c - 1] if c > 0 and values[r, c - 1] == value else 0
            up = provisional[r - 1, c] if r > 0 and values[r - 1, c] == value else 0
            if left == 0 and up == 0:
                count += 1
                parent[count] = count
                provisional[r, c] = count
            elif left == 0 or up == 0:
                provisional[r, c] = left + up
            else:
                a, b = root(left), root(up)
                if a != b:
                    parent[max(a, b)] = min(a, b)
                provisional[r, c] = min(a, b)
    sizes = np.zeros(count + 1, dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if provisional[r, c]:
                provisional[r, c] = root(provisional[r, c])
                sizes[provisional[r, c]] += 1
    final = np.zeros(count + 1, dtype=np.int32)
    number = 0
    for label in range(1, count + 1):  # roots are each part's first label in raster order
        if parent[label] == label and sizes[label] >= min_points:
            number += 1
            final[label] = number
    return _looked_up(final, provisional)


@njit(cache=True, nogil=True)
def object_pieces(labels: np.ndarray, parts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.object_pieces`."""
    rows, cols = labels.shape
    width = np.int64(parts.max()) + 1
    present = np.zeros((np.int64(labels.max()) + 1) * width, dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if parts[r, c] > 0:
                present[labels[r, c] * width + parts[r, c]] = 1
    count = 0
    for key in range(present.size):  # numbered in increasing (object, part) order
        if present[key]:
            count += 1
            present[key] = count
    owner = np.zeros(count + 1, dtype=np.int64)
    sizes = np.zeros(count + 1, dtype=np.int64)
    pieces = np.zeros((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            if parts[r, c] > 0:
                piece = present[labels[r, c] * width + parts[r, c]]
                pieces[r, c] = piece
                owner[piece] = labels[r, c]
                sizes[piece] += 1
    sizes[0] = rows * cols - sizes.sum()
    return pieces, owner, sizes


@njit(cache=True, nogil=True)
def labelled_values(labels: np.ndarray, values: np.ndarray, finite_only: bool) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.labelled_values`."""
    rows, cols = labels.shape
    count = 0
    for r in range(rows):
        for c in range(cols):
            if labels[r, c] > 0 and (not finite_only or np.isfinite(values[r, c, 0])):
                count += 1
    found = np.empty(count, dtype=labels.dtype)
    gathered = np.empty((3, count))
    k = 0
    for r in range(rows):
        for c in range(cols):
            if labels[r, c] > 0 and (not finite_only or np.isfinite(values[r, c, 0])):
                found[k] = labels[r, c]
                for axis in range(3):
                    gathered[axis, k] = values[r, c, axis]
                k += 1
    return found, gathered


@njit(cache=True, nogil=True)
def normal_halves(
    patches: np.ndarray, normals: np.ndarray, mean: np.ndarray, direction: np.ndarray, wide: np.ndarray
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.normal_halves`."""
    rows, cols = patches.shape
    split = np.zeros((rows, cols), dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            label = patches[r, c]
            if label <= 0 or not np.isfinite(normals[r, c, 0]):
                continue
            side = 0
            if wide[label]:
                along = (np.float64(normals[r, c, 0]) - mean[label, 0]) * direction[label, 0]
                along += (np.float64(normals[r, c, 1]) - mean[label, 1]) * direction[label, 1]
                along += (np.float64(normals[r, c, 2]) - mean[label, 2]) * direction[label, 2]
                side = 1 if along > 0 else 0
            split[r, c] = np.int64(label) * 2 + side + 1
    return split


@njit(cache=True, nogil=True)
def _jump(z_a: float, z_b: float, absolute32: float, relative32: float) -> bool:
    """``depth_jump`` of grid_segmentation for two float32 depths (float32 arithmetic)."""
    nearer = z_b if np.isnan(z_a) else (z_a if np.isnan(z_b) else min(z_a, z_b))
    return abs(z_a - z_b) > nearer * relative32 + absolute32


@njit(cache=True, nogil=True)
def seam_pixels(depth: np.ndarray, candidates: np.ndarray, absolute: float, relative: float) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.seam_pixels`."""
    rows, cols = depth.shape
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    seams = np.zeros((rows, cols), dtype=np.bool_)
    for down, right in ((0, 1), (1, 0)):
        for r in range(rows - down):
            for c in range(cols - right):
                if not (candidates[r, c] and candidates[r + down, c + right]):
                    continue
                z_a, z_b = depth[r, c], depth[r + down, c + right]
                if _jump(z_a, z_b, absolute32, relative32):
                    if z_a > z_b:
                        seams[r, c] = True
                    else:
                        seams[r + down, c + right] = True
    return seams


@njit(cache=True, nogil=True)
def surface_growth(
    labels: np.ndarray, region: np.ndarray, depth: np.ndarray, absolute: float, relative: float, rounds: int
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.surface_growth`."""
    rows, cols = labels.shape
    absolute32, relative32 = np.float32(absolute), np.float32(relative)
    grown = labels.copy()
    for _ in range(rounds):
        before = grown.copy()
        changed = False
        for r in range(rows):
            for c in range(cols):
                if not region[r, c] or before[r, c] != 0:
                    continue
                for nr, nc in ((r, c - 1), (r, c + 1), (r - 1, c), (r + 1, c)):
                    inside = 0 <= nr < rows and 0 <= nc < cols
                    if inside and before[nr, nc] > 0 and not _jump(depth[r, c], depth[nr, nc], absolute32, relative32):
                        grown[r, c] = before[nr, nc]
                        changed = True
                        break
        if not changed:
            break
    return grown


@njit(cache=True, nogil=True)
def dense_keys(keys: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.dense_keys`."""
    rows, cols = keys.shape
    largest = 0
    for r in range(rows):
        for c in range(cols):
            largest = max(largest, keys[r, c])
    number = np.zeros(largest + 1, dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            number[keys[r, c]] = 1
    number[0] = 0
    count = 0
    for key in range(largest + 1):
        if number[key]:
            count += 1
            number[key] = count
    return _looked_up(number, keys)


@njit(cache=True, nogil=True)
def cell_patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.cell_patches`."""
    rows, cols = surfaces.shape
    across, down = -(-cols // cell), -(-rows // cell)
    keys = np.zeros((rows, cols), dtype=np.int64)
    for r in range(rows):
        for c in range(cols):
            if surfaces[r, c] > 0:
                keys[r, c] = np.int64(surfaces[r, c]) * (across * down) + (r // cell) * across + c // cell + 1
    return dense_keys(keys)


@njit(cache=True, nogil=True)
def _root(parent: np.ndarray, node: int) -> int:
    """The root of ``node`` in the union-find forest ``parent``, halving the path on the way."""
    while parent[node] != node:
        parent[node] = parent[parent[node]]
        node = parent[node]
    return node


@njit(cache=True, nogil=True)
def graph_components(pairs: np.ndarray, count: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.graph_components`."""
    parent = np.arange(count)
    for k in range(pairs.shape[0]):
        a, b = _root(parent, pairs[k, 0]), _root(parent, pairs[k, 1])
        parent[max(a, b)] = min(a, b)  # each root is the smallest node of its component
    components = np.empty(count, dtype=np.int64)
    number = 0
    for node in range(count):
        root = _root(parent, node)
        if root == node:
            components[node] = number
            number += 1
        else:
            components[node] = components[root]
    return components


@njit(cache=True, nogil=True)
def nearest_labels_within(labels: np.ndarray, region: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.nearest_labels_within`."""
    rows, cols = labels.shape
    grown = labels.copy()
    for r in range(rows):
        for c in range(cols):
            if labels[r, c] != 0 or not region[r, c]:
                continue
            for k in range(offsets.shape[0]):
                nr, nc = r + offsets[k, 0], c + offsets[k, 1]
                if 0 <= nr < rows and 0 <= nc < cols and labels[nr, nc] > 0:
                    grown[r, c] = labels[nr, nc]
                    break
    return grown


@njit(cache=True, nogil=True)
def nearest_seed_labels(
    window: np.ndarray,
    unlabelled: np.ndarray,
    distance: np.ndarray,
    nearest: np.ndarray,
    max_distance: np.float32,
    grown: np.ndarray,
) -> None:
    """See :func:`annotators.geometry.grid_kernels.nearest_seed_labels`."""
    rows, cols = window.shape
    count = 0
    for r in range(rows):
        for c in range(cols):
            count = max(count, nearest[r, c])
    lookup = np.zeros(count + 1, dtype=window.dtype)
    for r in range(rows):
        for c in range(cols):
            if window[r, c] > 0:
                lookup[nearest[r, c]] = window[r, c]
    for r in range(rows):
        for c in range(cols):
            if unlabelled[r, c] and distance[r, c] <= max_distance:
                grown[r, c] = lookup[nearest[r, c]]


@njit(cache=True, nogil=True)
def unlabelled_box(labels: np.ndarray, region: np.ndarray, margin: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """See :func:`annotators.geometry.grid_kernels.unlabelled_box`."""
    rows, cols = labels.shape
    unlabelled = np.zeros((rows, cols), dtype=np.bool_)
    left, top, right, bottom = cols, rows, -1, -1  # the box's bounds as scalars: no array write per pixel
    labelled = False
    for r in range(rows):
        for c in range(cols):
            if labels[r, c] != 0:
                labelled = True
            elif region[r, c]:
                unlabelled[r, c] = True
                left, right = min(left, c), max(right, c + 1)
                top, bottom = min(top, r), max(bottom, r + 1)
    if right < 0 or not labelled:
        return unlabelled, np.zeros(4, dtype=np.int64), False
    box = np.array([left, top, right, bottom], dtype=np.int64)
    box[0], box[1] = max(box[0] - margin, 0), max(box[1] - margin, 0)
    box[2], box[3] = min(box[2] + margin, cols), min(box[3] + margin, rows)
    return unlabelled, box, True


@njit(cache=True, nogil=True)
def finite_rows(values: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.finite_rows`."""
    rows = np.empty((indices.size, values.shape[1]), dtype=values.dtype)
    kept = 0
    for index in indices:
        finite = True
        for column in range(values.shape[1]):
            finite = finite and np.isfinite(values[index, column])
        if finite:
            rows[kept] = values[index]
            kept += 1
    return rows[:kept]


@njit(cache=True, nogil=True)
def jump_between(z_a: np.float32, z_b: np.float32, absolute: float, relative: float) -> bool:
    """See :func:`annotators.geometry.grid_kernels.jump_between`."""
    return _jump(np.float32(z_a), np.float32(z_b), np.float32(absolute), np.float32(relative))


@njit(cache=True, nogil=True)
def window_counts(labels: np.ndarray, count: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.window_counts`."""
    counts = np.zeros(count + 1, dtype=np.int64)
    rows, cols = labels.shape
    for r in range(rows):
        for c in range(cols):
            counts[labels[r, c]] += 1
    return counts


@njit(cache=True, nogil=True)
def strided_crop(values: np.ndarray, step: int, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.strided_crop`."""
    channels = values.shape[2]
    crop = np.empty((y1 - y0, x1 - x0, channels), dtype=values.dtype)
    if channels == 3:  # points and colours: a fixed-length copy per pixel, row by row (several times faster)
        for r in range(y1 - y0):
            source, target = values[(r + y0) * step], crop[r]
            for c in range(x1 - x0):
                pixel = source[(c + x0) * step]
                target[c, 0], target[c, 1], target[c, 2] = pixel[0], pixel[1], pixel[2]
        return crop
    for r in range(y1 - y0):
        for c in range(x1 - x0):
            for k in range(channels):
                crop[r, c, k] = values[(r + y0) * step, (c + x0) * step, k]
    return crop


@njit(cache=True, nogil=True)
def groups_unless_apart(
    count: int, pairs: np.ndarray, apart: np.ndarray, weak: np.ndarray, sizes: np.ndarray, least: float
) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.groups_unless_apart`."""
    parent = np.arange(count)
    total = sizes.copy()  # per root: the sizes of its group's nodes summed
    apart_roots = apart.copy()  # the groups of the two nodes of every apart pair, kept up to date
    for k in range(pairs.shape[0]):
        first, second = _root(parent, pairs[k, 0]), _root(parent, pairs[k, 1])
        if first == second:
            continue
        if weak[k] and total[first] >= least and total[second] >= least:
            continue
        kept_apart = False
        for m in range(apart_roots.shape[0]):
            a, b = apart_roots[m, 0], apart_roots[m, 1]
            if (a == first and b == second) or (a == second and b == first):
                kept_apart = True
                break
        if kept_apart:
            continue
        parent[second] = first
        total[first] += total[second]
        for m in range(apart_roots.shape[0]):
            for side in range(2):
                if apart_roots[m, side] == second:
                    apart_roots[m, side] = first
    for node in range(count):
        parent[node] = _root(parent, node)
    return parent


@njit(cache=True, nogil=True)
def joined_labels(labels: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.joined_labels`."""
    rows, cols = labels.shape
    count = 1
    for r in range(rows):
        for c in range(cols):
            count = max(count, labels[r, c] + 1)
    parent = np.arange(count)
    for k in range(pairs.shape[0]):
        a, b = _root(parent, pairs[k, 0]), _root(parent, pairs[k, 1])
        parent[max(a, b)] = min(a, b)  # each group's root is its smallest label
    present = np.zeros(count, dtype=np.bool_)
    for r in range(rows):
        for c in range(cols):
            present[labels[r, c]] = True
    number = np.zeros(count, dtype=np.int32)  # each root's new label, in order of the groups' first present label
    renumber = np.zeros(count, dtype=np.int32)
    numbered = 0
    for label in range(1, count):
        if present[label]:
            root = _root(parent, label)
            if number[root] == 0:
                numbered += 1
                number[root] = numbered
            renumber[label] = number[root]
    return _looked_up(renumber, labels)


@intrinsic
def _fused_multiply_add(typing_context, a, b, c):
    """``a * b + c`` of three float32 rounded once (LLVM's ``fma``), as BLAS kernels accumulate products."""
    signature = types.float32(types.float32, types.float32, types.float32)

    def codegen(context, builder, signature, arguments):
        single = ir.FloatType()
        function = builder.module.declare_intrinsic("llvm.fma", [single], ir.FunctionType(single, [single] * 3))
        return builder.call(function, arguments)

    return signature, codegen


@njit(cache=True, nogil=True)
def plane_coordinates(points: np.ndarray, to_plane: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """See :func:`annotators.geometry.grid_kernels.plane_coordinates`."""
    count = points.shape[0]
    result = np.empty((count, 3), dtype=np.float32)
    for i in range(count):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        for k in range(3):
            total = x * to_plane[0, k]
            total = _fused_multiply_add(y, to_plane[1, k], total)
            total = _fused_multiply_add(z, to_plane[2, k], total)
            result[i, k] = total + offset[k]
    return result


@njit(cache=True, nogil=True)
def sampled_median(values: np.ndarray, indices: np.ndarray, step: int) -> float:
    """See :func:`annotators.geometry.grid_kernels.sampled_median`."""
    count = (indices.size + step - 1) // step
    if count == 0:
        return np.nan
    picked = np.empty(count, dtype=np.float64)
    for k in range(count):
        value = values[indices[k * step]]
        if np.isnan(value):
            return np.nan
        picked[k] = value
    middle = ranked_values(picked, np.array([(count - 1) // 2, count // 2]))
    return (middle[0] + middle[1]) / 2.0
