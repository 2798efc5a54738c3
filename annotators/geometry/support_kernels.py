"""Compiled passes over a labelling for :mod:`annotators.geometry.support`: the per-piece summary its joins read,
made in one pass over the label image instead of whole-array numpy with a sort of every sampled pixel.

The kernels give exactly what the numpy expressions they replace give (sizes, heights picked from the input with
the same float32 rounding, the same sampled feet). They are compiled by numba on first use (numba is imported
then, not with this module) and the machine code is cached on disk next to the loops.
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.support_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import support_loops

    return support_loops


MAX_TOUCHING = 512
"""Up to this many labels :func:`piece_summary` finds the touching pairs too (on a label x label table)."""


def piece_summary(
    labels: np.ndarray, plane_points: np.ndarray, step: int
) -> tuple[
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray | None,
    np.ndarray | None,
]:
    """``(sizes, low, high, top, feet, starts, boxes, pairs, border)`` of HxW non-negative integer ``labels``: each
    label's pixel count (int64), the 5 %, 95 % and 99 % of the heights (``plane_points[..., 2]``, HxWx3 float32,
    clipped to +-0.49 metres and rounded as float32 ``height + 0.5``; NaN without one) on every ``step``-th pixel
    with a finite height, and those pixels' ``(u, v)`` (Nx2 float32, row-major within a label; label k owns
    ``feet[starts[k]:starts[k + 1]]``), each label's pixel box ``(x0, y0, x1, y1)`` (exclusive; zeros for label 0
    and absent labels) and the distinct 4-neighbour label pairs ``(a, b)``, ``0 < a < b``, in increasing order
    (what :func:`~annotators.geometry.grid_segmentation.touching_pairs` gives) with the number of 4-neighbour pixel
    pairs along each one's shared ``border`` (both None above :data:`MAX_TOUCHING` labels)."""
    labels = np.ascontiguousarray(labels)
    *summary, pairs, border = _loops().piece_summary(
        labels, np.ascontiguousarray(plane_points, dtype=np.float32), max(1, int(step)), MAX_TOUCHING
    )
    many = int(summary[0].size) > MAX_TOUCHING
    return (*summary, None if many else pairs, None if many else border)


def pixel_footprint(points: np.ndarray) -> float:
    """:func:`~annotators.geometry.grid_segmentation.pixel_footprint` (the median angle between horizontally
    adjacent pixels of HxWx3 float32 ``points``) with its differences taken in one compiled pass."""
    steps = _loops().footprint_steps(np.asarray(points, dtype=np.float32))
    if steps.size == 0:
        return 0.0
    low, high = (steps.size - 1) // 2, steps.size // 2
    ordered = np.partition(steps, (low, high))
    return float((ordered[low] + ordered[high]) / np.float32(2))


def principal_span(feet: np.ndarray, share: float) -> float:
    """The extent of Nx2 plane coordinates (metres) along their principal axis - the major axis of their scatter -
    from their ``share`` to their ``1 - share`` quantile there (linear interpolation, NumPy's default), in one
    compiled pass; 0 for fewer than two points."""
    return float(_loops().principal_span(np.ascontiguousarray(feet), float(share)))


def narrowest_slice_span(
    points: np.ndarray, bottoms: np.ndarray, band: float, min_slice: int, share: float = 0.05
) -> float:
    """The least :func:`principal_span` (``share``) of the ``(u, v)`` of the Nx3 ``(u, v, height)`` points in any
    slice of heights ``[bottom, bottom + band)`` (one per value of ``bottoms``) holding at least ``min_slice`` of
    them; inf when none does."""
    return float(
        _loops().narrowest_slice_span(
            np.ascontiguousarray(points, dtype=np.float64),
            np.ascontiguousarray(bottoms, dtype=np.float64),
            float(band),
            int(min_slice),
            float(share),
        )
    )


def unsupported_candidates(
    pairs: np.ndarray, sizes: np.ndarray, low: np.ndarray, high: np.ndarray, tolerance: float, reach_down: float
) -> np.ndarray:
    """Mx2 ``(piece, holder)`` of the touching ``pairs`` (Kx2), each way round (all pairs as given, then all
    reversed), whose piece's 5 % height ``low`` lies above the holder's by more than ``tolerance`` and below
    ``reach_down`` of the way from its 5 % to its 95 % height (``high``), and whose holder is at least as large
    (``sizes``): the candidates of :func:`~annotators.geometry.support.unsupported_holders`."""
    return _loops().unsupported_candidates(
        np.ascontiguousarray(pairs, dtype=np.int64), sizes, low, high, float(tolerance), float(reach_down)
    )


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
    """Mx2 ``(piece, owner)`` of the touching ``pairs`` (Kx2), each way round (all pairs as given, then all
    reversed), with the piece at most ``small_share`` of the owner's size, its heights (``low``-``high``) within
    the owner's (``low``-``top``, ``tolerance`` of slack; or reaching below the owner's ``low`` with their middle
    above it) and a shared ``border`` (pixel pairs, per pair) at least
    ``max(min_boundary, boundary_share * sqrt(piece size))`` long: the candidates of
    :func:`~annotators.geometry.support.appendage_owners`."""
    return _loops().appendage_candidates(
        np.ascontiguousarray(pairs, dtype=np.int64),
        np.asarray(border, dtype=np.float64),
        sizes,
        low,
        high,
        top,
        float(small_share),
        float(tolerance),
        float(min_boundary),
        float(boundary_share),
    )


def raster_vertices(inner: np.ndarray, outer: np.ndarray, cell: float) -> tuple[np.ndarray, int, int]:
    """The vertices of two polygons (Nx2 and Mx2 float32, metres) on a common ``cell`` raster whose origin is
    their lowest ``u`` and ``v`` (``(N+M)x2`` int32, ``inner``'s first; float32 arithmetic, rounded half to even,
    as numpy rounds ``(polygon - low) / cell``) and the raster's width and height in cells."""
    vertices, width, height = _loops().raster_vertices(
        np.ascontiguousarray(inner, dtype=np.float32), np.ascontiguousarray(outer, dtype=np.float32), float(cell)
    )
    return vertices, int(width), int(height)


def kept_labels(labels: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """HxW ``labels`` (any strides, e.g. a window of a larger grid) with every label ``k`` not ``keep[k]`` (bool per
    label) set to 0, in a new C-ordered array: ``np.where(keep[labels], labels, 0)``."""
    return _loops().kept_labels(labels, keep)


def hull_candidates(points: np.ndarray) -> np.ndarray:
    """The points (Nx2 float32, N >= 1) that can be corners of their convex hull, in the same order: those strictly
    inside the quadrilateral of the leftmost, lowest, rightmost and highest points are dropped (by a margin, so
    that a point rounding could put on an edge stays), and the convex hull of the rest is theirs."""
    return _loops().hull_candidates(np.ascontiguousarray(points, dtype=np.float32))


def box_label_points(labels: np.ndarray, points: np.ndarray, label: int, box: np.ndarray) -> np.ndarray:
    """The rows of ``points`` (HxWxC) at the pixels of ``label`` in ``labels`` (HxW) within ``box`` ``(x0, y0, x1,
    y1)`` (exclusive), row-major: what ``points[y0:y1, x0:x1][labels[y0:y1, x0:x1] == label]`` gives, read in one
    compiled pass without the mask and the copy of the box."""
    return _loops().box_label_points(labels, points, int(label), np.asarray(box, dtype=np.int64))
