"""The surface groups of every object of a frame, in one compiled pass: the loops of
:mod:`annotators.image.color_surfaces` that numpy would make call by call, per object and per group.

For each object, its regular pixels (neither highlight nor dark) are grouped in the log-chroma plane by
flat-kernel mean shift from the fullest histogram cell (each mode taking the pixels within the group radius,
which are then removed, so later modes search only what remains; modes with too few members are dropped); each
pixel goes to the nearest mode, and each group with enough pixels is a surface: its median chromaticity at its lit
lightness (a high percentile of its L*) and its mean linear RGB. An unsaturated group is split into its black
pixels and the rest. The object's dark pool is summarised the same way at its median lightness.

Order statistics are exact (values picked from the pixels); distances are single precision like the pixels'. The
kernel is compiled by numba (its machine code cached on disk next to this file); import this module where the
groups are needed, not at start-up (importing numba takes a fraction of a second).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

GROUP_FIELDS = 9
"""Columns of a group row: object index, kind (0 regular, 1 dark pool), L*, a*, b*, linear R, G, B, pixel count."""

REGULAR, DARK = 0, 1
"""The kinds of a group row (``DARK`` is :data:`~annotators.image.color_surfaces.DARK_GROUP`)."""


@njit(cache=True, nogil=True)
def _round_half_even(value: float) -> int:
    """``round(value)`` as Python rounds: halves go to the even neighbour."""
    low = math.floor(value)
    rest = value - low
    if rest > 0.5 or (rest == 0.5 and low % 2 == 1):
        return int(low) + 1
    return int(low)


@njit(cache=True, nogil=True)
def _select(values: np.ndarray, rank: int) -> float:
    """The ``rank``-th smallest of ``values`` (reordered in place): quickselect with median-of-three pivots and
    branch-free partitions (the values below the pivot to the front, then those equal to it), whose run time
    does not hang on guessing comparisons' outcomes."""
    low, high = 0, values.size - 1
    while high > low:
        first, middle, last = values[low], values[(low + high) // 2], values[high]
        pivot = max(min(first, middle), min(max(first, middle), last))
        below = low
        for i in range(low, high + 1):
            value = values[i]
            values[i] = values[below]
            values[below] = value
            below += value < pivot
        if rank < below:
            high = below - 1
            continue
        equal = below
        for i in range(below, high + 1):
            value = values[i]
            values[i] = values[equal]
            values[equal] = value
            equal += value <= pivot
        if rank < equal:
            return float(pivot)
        low = equal
    return float(values[rank])


@njit(cache=True, nogil=True)
def _write_group(
    out: np.ndarray, at: int, obj: int, kind: int, rows: np.ndarray, members: np.ndarray, percentile: float
) -> None:
    """Row ``at`` of ``out``: the group of the pixels ``members`` (indices into ``rows``' columns): the
    ``percentile`` of L* as its lightness, the median chromaticity at that lightness, the mean linear RGB."""
    count = members.size
    lightness = np.empty(count, dtype=rows.dtype)
    chroma_a = np.empty(count, dtype=rows.dtype)
    chroma_b = np.empty(count, dtype=rows.dtype)
    red = green = blue = 0.0
    for k in range(count):
        i = members[k]
        lightness[k] = rows[0, i]
        chroma_a[k] = rows[1, i]
        chroma_b[k] = rows[2, i]
        red += rows[3, i]
        green += rows[4, i]
        blue += rows[5, i]
    lit_rank = _round_half_even(percentile / 100.0 * (count - 1))
    middle_rank = _round_half_even(0.5 * (count - 1))
    lit = float(_select(lightness, lit_rank))
    out[at, 0] = obj
    out[at, 1] = kind
    out[at, 2] = lit
    out[at, 3] = float(_select(chroma_a, middle_rank)) * (lit + 16.0)
    out[at, 4] = float(_select(chroma_b, middle_rank)) * (lit + 16.0)
    out[at, 5] = red / count
    out[at, 6] = green / count
    out[at, 7] = blue / count
    out[at, 8] = count


@njit(cache=True, nogil=True)
def _modes(
    px: np.ndarray, py: np.ndarray, keys: np.ndarray, radius: np.float32, min_count: float, max_groups: int
) -> np.ndarray:
    """Centres (x, y rows) of the densest modes of the points (``px``, ``py``) with histogram cell ``keys``."""
    alive = np.arange(px.size)
    centres = np.empty((max_groups, 2))
    found = 0
    tolerance = 1e-6 * float(radius) * float(radius)
    radius_squared = radius * radius  # distances are compared squared, in single precision
    cells = np.zeros(keys.max() + 1 if keys.size else 1, dtype=np.int64)
    for _ in range(4 * max_groups):
        if found == max_groups or alive.size < min_count:
            break
        cells[:] = 0
        for i in alive:
            cells[keys[i]] += 1
        fullest = np.argmax(cells)
        sx = sy = 0.0
        seeds = 0
        for i in alive:
            if keys[i] == fullest:
                sx += px[i]
                sy += py[i]
                seeds += 1
        cx, cy = sx / seeds, sy / seeds
        for _ in range(10):
            x32, y32 = np.float32(cx), np.float32(cy)
            sx = sy = 0.0
            near = 0
            for i in alive:
                if (px[i] - x32) ** 2 + (py[i] - y32) ** 2 < radius_squared:
                    sx += px[i]
                    sy += py[i]
                    near += 1
            mx, my = sx / near, sy / near
            if (mx - cx) ** 2 + (my - cy) ** 2 < tolerance:
                break
            cx, cy = mx, my
        x32, y32 = np.float32(cx), np.float32(cy)
        inside = np.empty(alive.size, dtype=np.bool_)
        members = 0
        for k in range(alive.size):
            i = alive[k]
            inside[k] = (px[i] - x32) ** 2 + (py[i] - y32) ** 2 < radius_squared
            members += inside[k]
        if members >= min_count:
            centres[found, 0], centres[found, 1] = cx, cy
            found += 1
        alive = alive[~inside]
    return centres[:found]


@njit(cache=True, nogil=True)
def _object_groups(
    out: np.ndarray,
    at: int,
    obj: int,
    rows: np.ndarray,
    px: np.ndarray,
    py: np.ndarray,
    cells: np.ndarray,
    regular: np.ndarray,
    count: int,
    settings: np.ndarray,
    max_groups: int,
) -> int:
    """The groups of one object's regular pixels, written to ``out`` from row ``at``; returns the next row."""
    radius, min_share, percentile, black_lightness = settings[0], settings[1], settings[2], settings[3]
    achromatic, daylight, tint_ratio = settings[4], settings[5], settings[6]
    min_count = max(3.0, min_share * count)
    indices = np.flatnonzero(regular)
    start = at
    if indices.size >= min_count:
        cx, cy = cells[0, indices], cells[1, indices]
        x, y = cx - cx.min(), cy - cy.min()
        keys = x * (y.max() + 1) + y
        fx, fy = px[indices], py[indices]
        centres = _modes(fx, fy, keys, np.float32(radius), min_count, max_groups)
        owner = np.zeros(indices.size, dtype=np.int64)
        if centres.shape[0] > 1:
            cx32 = centres[:, 0].astype(np.float32)
            cy32 = centres[:, 1].astype(np.float32)
            for k in range(indices.size):
                best, best_distance = 0, np.float32(np.inf)
                for g in range(centres.shape[0]):
                    dx, dy = fx[k] - cx32[g], fy[k] - cy32[g]
                    distance = dx * dx + dy * dy
                    if distance < best_distance:
                        best, best_distance = g, distance
                owner[k] = best
        for g in range(centres.shape[0]):
            members = indices[owner == g]
            if members.size < min_count:
                continue
            _write_group(out, at, obj, REGULAR, rows, members, percentile)
            lightness, a, b = out[at, 2], out[at, 3], out[at, 4]
            radius_a = min(achromatic, tint_ratio * (lightness + 16.0))
            radius_b = min(daylight, 1.5 * tint_ratio * (lightness + 16.0))
            if math.hypot(a / radius_a, b / radius_b) >= 1.0:
                at += 1
                continue
            blackish = rows[0, members] < np.float32(black_lightness)  # black print on white: two surfaces
            rest, black = members[~blackish], members[blackish]
            if rest.size >= min_count:
                _write_group(out, at, obj, REGULAR, rows, rest, percentile)
                at += 1
            if black.size >= min_count:
                _write_group(out, at, obj, REGULAR, rows, black, percentile)
                at += 1
    if at == start and indices.size:  # too few pixels for a group: they are one surface
        _write_group(out, at, obj, REGULAR, rows, indices, percentile)
        at += 1
    return at


@njit(cache=True, nogil=True)
def all_groups(
    rows: np.ndarray,
    px: np.ndarray,
    py: np.ndarray,
    cells: np.ndarray,
    regular: np.ndarray,
    dark: np.ndarray,
    ends: np.ndarray,
    settings: np.ndarray,
    max_groups: int,
) -> np.ndarray:
    """The groups of the objects whose pixels end at ``ends`` (the pixels as 6xN ``rows``: L*, a*/(L*+16),
    b*/(L*+16), linear R, G, B; their log-chroma features ``px``, ``py``, histogram ``cells`` (2xN) and which are
    ``regular`` or ``dark``), as rows of :data:`GROUP_FIELDS` values, object by object, each object's regular
    groups before its dark pool. ``settings``: the group radius, the smallest group's share of the object, the
    lit percentile, the black lightness and the achromatic ellipse (a* radius, b* radius, dark tint ratio) of
    :class:`~annotators.image.color_surfaces.NamingParameters`
    (:func:`~annotators.image.color_surfaces.group_settings`)."""
    out = np.empty((ends.size * (2 * max_groups + 2), GROUP_FIELDS))
    at = 0
    start = 0
    for obj in range(ends.size):
        end = ends[obj]
        object_rows = rows[:, start:end]
        at = _object_groups(
            out,
            at,
            obj,
            object_rows,
            px[start:end],
            py[start:end],
            cells[:, start:end],
            regular[start:end],
            end - start,
            settings,
            max_groups,
        )
        dark_members = np.flatnonzero(dark[start:end])
        if dark_members.size:
            _write_group(out, at, obj, DARK, object_rows, dark_members, 50.0)
            at += 1
        start = end
    return out[:at]
