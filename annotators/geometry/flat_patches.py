"""Surface patches whose boundaries follow the data, not a grid: seeded region growing on the organized grid.

:func:`annotators.geometry.convexity.grid_patches` cuts the surfaces into cells counted from a corner, so where an
object's patches end depends on where the cells start (bench/profiles/seg8-analysis.txt). Here the seeds are the
flattest pixels (the least normal change to their neighbours), taken greedily with no two closer than ``spacing``
pixels on one surface, and every surface pixel joins the seed it reaches most cheaply through its own surface: the
cost grows with the squared distance from the seed (in ``spacing`` units) and with how far the pixel's normal turns
from the seed's. Nothing depends on the position of the grid: a shifted crop gives the same patches.
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.flat_patch_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import flat_patch_loops

    return flat_patch_loops


def pixel_bending(surfaces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """HxW float64: the mean ``1 - n . m`` between each surface pixel's normal and those of its 4-neighbours on the
    same surface; infinite where there is no surface, no normal or no such neighbour."""
    return _loops().pixel_bending(np.ascontiguousarray(surfaces), np.ascontiguousarray(normals))


def flat_seeds(surfaces: np.ndarray, bending: np.ndarray, radius: int) -> np.ndarray:
    """Flat pixel indices of the seeds: pixels in order of increasing ``bending`` (ties in row-major order), each
    kept unless a kept seed of its surface lies within ``radius`` pixels (a square window)."""
    flat = bending.reshape(-1)
    candidates = np.flatnonzero(np.isfinite(flat))  # the others can be no seed
    order = candidates[np.argsort(flat[candidates])]  # quicksort, then ties put in row-major order
    _loops().ties_in_order(order, flat)
    return _loops().flat_seeds(np.ascontiguousarray(surfaces), order, bending, radius)


def grown_patches(
    surfaces: np.ndarray,
    normals: np.ndarray,
    points: np.ndarray,
    seeds: np.ndarray,
    spacing: float,
    weight: float,
    relative: float,
) -> np.ndarray:
    """HxW int32 patch labels (seed k gives label k + 1): every surface pixel reachable from a seed through its own
    surface (4-neighbours) joins the seed of the lowest cost, ``d^2 / spacing^2 + weight (1 - n . n_seed) +
    (h / (relative z_seed))^2``: ``d`` pixels from the seed, ``h`` its height over the seed's tangent plane (with
    ``relative`` 0, no height term)."""
    return _loops().grown_patches(
        np.ascontiguousarray(surfaces),
        np.ascontiguousarray(normals),
        np.ascontiguousarray(points),
        seeds,
        spacing,
        weight,
        relative,
    )


def flat_patches(
    surfaces: np.ndarray, normals: np.ndarray, points: np.ndarray, spacing: int, weight: float, relative: float
) -> np.ndarray:
    """Patch labels (int32, 0 = none, 1..n) of the labelled ``surfaces`` (HxW) with the normals ``normals``
    (HxWx3, NaN where unknown) of the ``points`` (HxWx3): seeds at least ``spacing`` pixels apart on each surface,
    grown by :func:`grown_patches`. Pixels of a surface without any normal are left out."""
    bending = pixel_bending(surfaces, normals)
    seeds = flat_seeds(surfaces, bending, max(0, spacing - 1))
    return grown_patches(surfaces, normals, points, seeds, float(spacing), weight, relative)
