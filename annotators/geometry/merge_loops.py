"""The compiled loops behind the merge evidence of :mod:`annotators.geometry.grid_kernels`: what
:func:`annotators.geometry.grid_segmentation.merge_parts` needs to know of every part and every touching pair of
parts - sampled pixels, footprint hulls, height quantiles, median depths, nested heights, floors and container
insides - in one pass instead of a few kernel calls per part and pair (numba, machine code cached on disk next to
this file). Importing this module imports numba; the segmentation modules reach it through
:mod:`~annotators.geometry.grid_kernels` only, on first use."""

from __future__ import annotations

import numpy as np
from numba import njit

from annotators.geometry.footprint_loops import (
    convex_hull,
    quantile_rank,
    ranked_values,
    rim_outside_extents,
    sight_extents,
)
from annotators.geometry.grid_loops import sampled_median


@njit(cache=True, nogil=True)
def sampled_pixels(
    pixels: np.ndarray, starts: np.ndarray, labels: np.ndarray, most: int
) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.sampled_pixels`."""
    count = starts.size - 1
    offsets = np.zeros(count + 1, dtype=np.int64)
    wanted = np.zeros(count, dtype=np.bool_)
    for label in labels:
        wanted[label] = True
    for label in range(count):
        size = starts[label + 1] - starts[label]
        taken = 0
        if wanted[label] and size > 0:
            step = max(1, size // most)
            taken = (size + step - 1) // step
        offsets[label + 1] = offsets[label] + taken
    sampled = np.empty(offsets[count], dtype=pixels.dtype)
    for label in range(count):
        begin, taken = starts[label], offsets[label + 1] - offsets[label]
        if taken == 0:
            continue
        step = max(1, (starts[label + 1] - begin) // most)
        for k in range(taken):
            sampled[offsets[label] + k] = pixels[begin + k * step]
    return sampled, offsets


@njit(cache=True, nogil=True)
def part_hulls(coordinates: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.part_hulls`."""
    count = offsets.size - 1
    hull_offsets = np.zeros(count + 1, dtype=np.int64)
    hulls = np.empty((offsets[count], 2), dtype=coordinates.dtype)
    for label in range(count):
        begin, end = offsets[label], offsets[label + 1]
        hull_offsets[label + 1] = hull_offsets[label]
        if end == begin:
            continue
        hull = convex_hull(coordinates[begin:end, :2])
        hull_offsets[label + 1] = hull_offsets[label] + hull.shape[0]
        hulls[hull_offsets[label] : hull_offsets[label + 1]] = hull
    return hulls[: hull_offsets[count]], hull_offsets


@njit(cache=True, nogil=True)
def _height_quantiles(heights: np.ndarray, begin: int, end: int) -> np.ndarray:
    """The 5, 50, 95 and 99 % heights (float64) of a part whose sorted heights are ``heights[begin:end]``."""
    size = end - begin
    quantiles = np.empty(4)
    for k, share in enumerate((0.05, 0.5, 0.95, 0.99)):
        quantiles[k] = heights[begin + quantile_rank(size, share)]
    return quantiles


@njit(cache=True, nogil=True)
def _heights_nest(first: np.ndarray, second: np.ndarray, tolerance: float, rim_band: float) -> bool:
    """:func:`annotators.geometry.grid_segmentation.heights_nest` of two parts' height quantiles (5, 50, 95, 99 %)."""
    for inner, outer in ((first, second), (second, first)):
        span = outer[2] - outer[0]
        in_band = inner[2] - inner[0] <= rim_band * span or inner[0] >= outer[0] + rim_band * span
        top = outer[3] if in_band else outer[2]
        if inner[0] >= outer[0] - tolerance and inner[2] <= top + tolerance:
            return True
    return False


@njit(cache=True, nogil=True)
def _floor_width(part: np.ndarray) -> float:
    """The larger of the 5 %-95 % extents of a part's Nx3 plane coordinates along u and v (``np.max`` of the two:
    NaN when one is)."""
    size = part.shape[0]
    ranks = np.array([quantile_rank(size, 0.05), quantile_rank(size, 0.95)])
    u = ranked_values(part[:, 0].copy(), ranks)
    v = ranked_values(part[:, 1].copy(), ranks)
    across, along = u[1] - u[0], v[1] - v[0]
    return np.nan if np.isnan(across) or np.isnan(along) else max(across, along)


@njit(cache=True, nogil=True)
def pair_evidence(
    coordinates: np.ndarray,
    heights: np.ndarray,
    offsets: np.ndarray,
    depth: np.ndarray,
    pixels: np.ndarray,
    starts: np.ndarray,
    pairs: np.ndarray,
    overlapping: np.ndarray,
    unjoined: np.ndarray,
    tolerances: np.ndarray,
    inside: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """See :func:`annotators.geometry.grid_kernels.pair_evidence`."""
    count = offsets.size - 1
    nest_tolerance, inside_tolerance, depth_ratio = tolerances[0], tolerances[1], tolerances[2]
    rim_band, flatness, inner_spread = tolerances[3], tolerances[4], tolerances[5]
    quantiles = np.full((count, 4), np.nan)
    widths = np.full(count, np.nan)
    depths = np.full(count, np.nan)
    outsides = np.full((count, 8), np.nan)
    known = np.zeros((count, 4), dtype=np.bool_)  # quantiles, width, depth, outside
    nest = np.zeros(pairs.shape[0], dtype=np.bool_)
    floors = np.zeros(pairs.shape[0], dtype=np.int64)
    holds = np.zeros(pairs.shape[0], dtype=np.bool_)
    for k in range(pairs.shape[0]):
        pair = pairs[k]
        for label in pair:
            if not known[label, 0]:
                known[label, 0] = True
                quantiles[label] = _height_quantiles(heights, offsets[label], offsets[label + 1])
        first, second = pair[0], pair[1]
        if overlapping[k]:
            nest[k] = _heights_nest(quantiles[first], quantiles[second], nest_tolerance, rim_band)
            for bit, floor, walls in ((1, first, second), (2, second, first)):
                if nest[k] or quantiles[floor, 2] > quantiles[walls, 0] + nest_tolerance:
                    continue
                if not known[floor, 1]:
                    known[floor, 1] = True
                    widths[floor] = _floor_width(coordinates[offsets[floor] : offsets[floor + 1]])
                if not quantiles[floor, 2] - quantiles[floor, 0] > flatness * widths[floor]:
                    floors[k] |= bit
        if not (unjoined[k] and inside):
            continue
        for label in pair:
            if not known[label, 2]:
                known[label, 2] = True
                own = pixels[starts[label] : starts[label + 1]]
                depths[label] = sampled_median(depth, own, max(1, own.size // 500))
        near, far = (second, first) if depths[second] < depths[first] else (first, second)
        if not known[near, 3]:
            known[near, 3] = True
            if offsets[near + 1] - offsets[near] >= 3:
                outsides[near] = rim_outside_extents(coordinates[offsets[near] : offsets[near + 1]], quantiles[near, 2])
        holds[k] = _could_hold(
            outsides[near],
            coordinates[offsets[far] : offsets[far + 1]],
            quantiles[far],
            inside_tolerance,
            depth_ratio,
            inner_spread,
        )
    return nest, floors, holds


@njit(cache=True, nogil=True)
def _could_hold(
    outside: np.ndarray,
    far: np.ndarray,
    far_heights: np.ndarray,
    tolerance: float,
    depth_ratio: float,
    inner_spread: float,
) -> bool:
    """:meth:`annotators.geometry.grid_segmentation.ContainerOutside.could_hold` of the extents ``outside``
    (:func:`rim_outside_extents`, NaN for no outside) and part ``far`` (Nx3; its 5, 50, 95 and 99 % heights
    ``far_heights``)."""
    if not np.isfinite(outside[7]) or far.shape[0] < 3:
        return False
    low, high, rim, front, middle = outside[2], outside[3], outside[4], outside[5], outside[6]
    margin = max(tolerance, 0.1 * (high - low))
    far_median, far_top = far_heights[1], far_heights[2]
    if far_top > rim + margin:
        return False
    if not (far_top - far_median >= inner_spread * rim or far_median <= 0.5 * rim):
        return False
    far_low, far_high, far_middle, far_back = sight_extents(far, outside[0], outside[1])
    if far_low < low - margin or far_high > high + margin:
        return False
    return not (far_middle <= middle or far_back > front + depth_ratio * (high - low))
