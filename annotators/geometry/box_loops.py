"""The compiled loops behind the batched box fits of :mod:`annotators.geometry.boxes` (numba, machine code cached
on disk next to this file). Importing this module imports numba; :mod:`~annotators.geometry.boxes` reaches it on
first use only.

Every loop works on point sets stored one after another as 3xN float64 rows (x, y and z each contiguous), the
sets' sizes given in order, and gives what the NumPy expressions of :mod:`~annotators.geometry.boxes` give: order
statistics are picked from the input unchanged, and sums are added in NumPy's order (its pairwise summation).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import intrinsic

from annotators.geometry.footprint_loops import select_rank

_BLOCK = 128
"""NumPy's pairwise-summation block: shorter runs are added with eight interleaved accumulators."""


@intrinsic
def _fused_multiply_add(typing_context: object, a: types.Type, b: types.Type, c: types.Type) -> tuple:
    """``a * b + c`` rounded once (LLVM's fma): what BLAS matrix products on FMA hardware add up."""
    signature = types.float64(types.float64, types.float64, types.float64)

    def generate(context: object, builder: object, signature: object, arguments: list) -> object:
        return builder.fma(*arguments)

    return signature, generate


@njit(cache=True, nogil=True)
def _pairwise_sum(values: np.ndarray, start: int, count: int) -> float:
    """The sum of ``values[start:start + count]`` added in the order of NumPy's pairwise summation."""
    if count < 8:
        total = -0.0
        for i in range(start, start + count):
            total += values[i]
        return total
    if count <= _BLOCK:
        r0, r1, r2, r3 = values[start], values[start + 1], values[start + 2], values[start + 3]
        r4, r5, r6, r7 = values[start + 4], values[start + 5], values[start + 6], values[start + 7]
        i = 8
        whole = count - count % 8
        while i < whole:
            at = start + i
            r0 += values[at]
            r1 += values[at + 1]
            r2 += values[at + 2]
            r3 += values[at + 3]
            r4 += values[at + 4]
            r5 += values[at + 5]
            r6 += values[at + 6]
            r7 += values[at + 7]
            i += 8
        total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < count:
            total += values[start + i]
            i += 1
        return total
    half = count // 2
    half -= half % 8
    return _pairwise_sum(values, start, half) + _pairwise_sum(values, start + half, count - half)


@njit(cache=True, nogil=True)
def reduced_sum(values: np.ndarray, start: int, count: int) -> float:
    """``np.add.reduce(values[start:start + count])`` (count >= 1) as NumPy adds it: the first value plus the
    pairwise sum of the rest."""
    return values[start] + _pairwise_sum(values, start + 1, count - 1)


@njit(cache=True, nogil=True)
def _least(values: np.ndarray, first: int, end: int) -> float:
    """The least of ``values[first:end]`` (not empty)."""
    least = values[first]
    for i in range(first + 1, end):
        least = min(least, values[i])
    return least


_SAMPLE = 64
"""Values sampled to bracket a rank before the pass that counts and gathers the values near it."""
_MARGIN = 10
"""Sample slots either side of a rank's expected slot that bracket it (about 2.5 standard deviations)."""


@njit(cache=True, nogil=True)
def _rank_pair(values: np.ndarray, rank: int, scratch: np.ndarray) -> tuple[float, float]:
    """The values of rank ``rank`` and ``rank + 1`` (0-based, ascending, ``rank + 1 < values.size``) of 1-D
    ``values`` (no NaN; left unchanged), using ``scratch`` (at least ``values.size`` long).

    Values sampled at even steps bracket the rank; one branch-free pass counts the values below the bracket and
    gathers those inside, and a quickselect among these few finds the pair. When the bracket misses the rank (rare),
    a quickselect over all values does."""
    count = values.size
    if count >= 4 * _SAMPLE:
        sample = np.empty(_SAMPLE)
        for k in range(_SAMPLE):
            sample[k] = values[(k * count) // _SAMPLE]
        slot = (rank * _SAMPLE) // count
        low = select_rank(sample, 0, _SAMPLE, slot - _MARGIN) if slot - _MARGIN >= 0 else -np.inf
        high = select_rank(sample, 0, _SAMPLE, slot + _MARGIN + 1) if slot + _MARGIN + 1 < _SAMPLE else np.inf
        below, inside = 0, 0
        for i in range(count):
            value = values[i]
            below += value < low
            scratch[inside] = value
            inside += (value >= low) & (value <= high)
        if below <= rank and rank + 1 < below + inside:
            first = select_rank(scratch, 0, inside, rank - below)
            return first, _least(scratch, rank - below + 1, inside)
    scratch[:count] = values
    first = select_rank(scratch, 0, count, rank)
    return first, _least(scratch, rank + 1, count)


@njit(cache=True, nogil=True)
def _quartiles(values: np.ndarray, scratch: np.ndarray) -> tuple[float, float]:
    """See :func:`annotators.geometry.boxes._quartiles` (8 or more ``values``; ``scratch`` as long)."""
    quartiles = np.empty(2)
    for k in range(2):
        position = (values.size - 1) * (0.25 if k == 0 else 0.75)
        rank = math.floor(position)
        low, high = _rank_pair(values, rank, scratch)
        weight = position - rank
        step = high - low
        quartiles[k] = high - step * (1.0 - weight) if weight >= 0.5 else low + step * weight
    return quartiles[0], quartiles[1]


@njit(cache=True, nogil=True)
def _compact_into(rows: np.ndarray, start: int, count: int, out: np.ndarray, column: int, fence: float) -> int:
    """:func:`annotators.geometry.boxes._compact` of the set ``rows[:, start:start + count]`` (3xN float64),
    written to ``out`` from ``column`` on; returns the column after the last kept point."""
    if count < 8:
        for i in range(start, start + count):
            for axis in range(3):
                out[axis, column] = rows[axis, i]
            column += 1
        return column
    low, high = (count - 1) // 2, count // 2
    median = np.empty(3)
    scratch = np.empty(count)
    for axis in range(3):
        before, middle = _rank_pair(rows[axis, start : start + count], high - 1, scratch)
        median[axis] = ((before if low != high else middle) + middle) / 2.0
    distances = np.empty(count)
    for i in range(count):
        dx = rows[0, start + i] - median[0]
        dy = rows[1, start + i] - median[1]
        dz = rows[2, start + i] - median[2]
        distances[i] = math.sqrt(dx * dx + dy * dy + dz * dz)
    q1, q3 = _quartiles(distances, scratch)
    limit = q3 + fence * (q3 - q1)
    for i in range(count):
        if distances[i] <= limit:
            for axis in range(3):
                out[axis, column] = rows[axis, start + i]
            column += 1
    return column


@njit(cache=True, nogil=True)
def compact_sets(rows: np.ndarray, sizes: np.ndarray, fence: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`annotators.geometry.boxes._compact` of every set: the kept points (3xM rows, sets in order) and how
    many each set kept. A set of fewer than 8 points keeps them all."""
    out = np.empty_like(rows)
    kept = np.zeros(sizes.size, dtype=np.int64)
    start, column = 0, 0
    for group in range(sizes.size):
        end = _compact_into(rows, start, sizes[group], out, column, fence)
        kept[group] = end - column
        start, column = start + sizes[group], end
    return out[:, :column], kept


@njit(cache=True, nogil=True)
def gathered_compact_sets(
    points: np.ndarray, indices: np.ndarray, sizes: np.ndarray, fence: float
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`compact_sets` of the finite points among ``points[indices]`` (Nx3; indices outside the array are
    skipped), each set gathered from a consecutive group of ``sizes`` indices: the kept points as 3xM float64
    rows and how many each set kept (0 for a set without finite points)."""
    total = points.shape[0]
    out = np.empty((3, indices.size))
    kept = np.zeros(sizes.size, dtype=np.int64)
    gathered = np.empty((3, sizes.max() if sizes.size else 0))
    position, column = 0, 0
    for group in range(sizes.size):
        count = 0
        for i in range(position, position + sizes[group]):
            index = indices[i]
            if 0 <= index < total:
                x, y, z = points[index, 0], points[index, 1], points[index, 2]
                if np.isfinite(x) and np.isfinite(y) and np.isfinite(z):
                    gathered[0, count], gathered[1, count], gathered[2, count] = x, y, z
                    count += 1
        position += sizes[group]
        end = _compact_into(gathered, 0, count, out, column, fence)
        kept[group] = end - column
        column = end
    return out[:, :column], kept


@njit(cache=True, nogil=True)
def set_moments(rows: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each set's mean (3xS) and the sums of the products of its centred coordinates xx, xy, xz, yy, yz, zz (6xS):
    ``np.add.reduceat(rows, starts, axis=1) / sizes`` and ``np.add.reduceat`` of the products of
    ``rows - mean[:, owner]``. Every set has at least one point."""
    means = np.empty((3, sizes.size))
    products = np.empty((6, sizes.size))
    first = (0, 0, 0, 1, 1, 2)
    second = (0, 1, 2, 1, 2, 2)
    start = 0
    for group in range(sizes.size):
        count = sizes[group]
        for axis in range(3):
            means[axis, group] = reduced_sum(rows[axis], start, count) / count
        centred = np.empty((3, count))
        for axis in range(3):
            mean = means[axis, group]
            for i in range(count):
                centred[axis, i] = rows[axis, start + i] - mean
        product = np.empty(count)
        for k in range(6):
            a, b = first[k], second[k]
            for i in range(count):
                product[i] = centred[a, i] * centred[b, i]
            products[k, group] = reduced_sum(product, 0, count)
        start += count
    return means, products


@njit(cache=True, nogil=True)
def set_extents(
    rows: np.ndarray, sizes: np.ndarray, means: np.ndarray, rotations: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest coordinates (each Sx3) of every set's centred points along the axes of its rotation
    (Sx3x3, columns are the axes): the minima and maxima of ``rotations[s].T @ (set - mean)``. Each coordinate is
    added up as fused multiply-adds over x, y and z in turn - as OpenBLAS's matrix product does on FMA hardware,
    so the values equal NumPy's there bit for bit, and otherwise to rounding."""
    low = np.empty((sizes.size, 3))
    high = np.empty((sizes.size, 3))
    start = 0
    for group in range(sizes.size):
        r = rotations[group]
        mx, my, mz = means[0, group], means[1, group], means[2, group]
        low0 = low1 = low2 = np.inf
        high0 = high1 = high2 = -np.inf
        for i in range(start, start + sizes[group]):
            x, y, z = rows[0, i] - mx, rows[1, i] - my, rows[2, i] - mz
            v0 = _fused_multiply_add(r[2, 0], z, _fused_multiply_add(r[1, 0], y, r[0, 0] * x))
            v1 = _fused_multiply_add(r[2, 1], z, _fused_multiply_add(r[1, 1], y, r[0, 1] * x))
            v2 = _fused_multiply_add(r[2, 2], z, _fused_multiply_add(r[1, 2], y, r[0, 2] * x))
            low0, high0 = min(low0, v0), max(high0, v0)
            low1, high1 = min(low1, v1), max(high1, v1)
            low2, high2 = min(low2, v2), max(high2, v2)
        low[group, 0], low[group, 1], low[group, 2] = low0, low1, low2
        high[group, 0], high[group, 1], high[group, 2] = high0, high1, high2
        start += sizes[group]
    return low, high


@njit(cache=True, nogil=True)
def rotation_quaternions(rotations: np.ndarray) -> np.ndarray:
    """:func:`robokudo.core.geometry.quaternion_from_matrix` of K 3x3 rotations (Kx3x3 float64) as Kx4 (x, y, z,
    w), with the same arithmetic in the same order."""
    quaternions = np.empty((rotations.shape[0], 4))
    q = np.empty(4)
    for k in range(rotations.shape[0]):
        m = rotations[k]
        m00, m01, m02 = m[0, 0], m[0, 1], m[0, 2]
        m10, m11, m12 = m[1, 0], m[1, 1], m[1, 2]
        m20, m21, m22 = m[2, 0], m[2, 1], m[2, 2]
        finite = True
        for value in (m00, m01, m02, m10, m11, m12, m20, m21, m22):
            finite = finite and math.isfinite(value)
        determinant = m00 * (m11 * m22 - m12 * m21) - m01 * (m10 * m22 - m12 * m20) + m02 * (m10 * m21 - m11 * m20)
        if not finite or determinant <= 1e-6:
            quaternions[k] = (0.0, 0.0, 0.0, 1.0)
            continue
        trace = m00 + m11 + m22
        if trace > 0:
            s = 2.0 * math.sqrt(trace + 1.0)
            q[0], q[1], q[2], q[3] = (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s
        elif m00 >= m11 and m00 >= m22:
            s = 2.0 * math.sqrt(max(1.0 + m00 - m11 - m22, 1e-12))
            q[0], q[1], q[2], q[3] = 0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s
        elif m11 >= m22:
            s = 2.0 * math.sqrt(max(1.0 + m11 - m00 - m22, 1e-12))
            q[0], q[1], q[2], q[3] = (m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s
        else:
            s = 2.0 * math.sqrt(max(1.0 + m22 - m00 - m11, 1e-12))
            q[0], q[1], q[2], q[3] = (m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s
        norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        sign = 1.0 if q[3] / norm >= 0 else -1.0
        for i in range(4):
            quaternions[k, i] = sign * (q[i] / norm)
    return quaternions
