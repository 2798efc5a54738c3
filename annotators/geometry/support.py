"""Support on the organized grid: pieces that could not stand by themselves join the object that holds them.

Every object rests on something: the support plane, or another object it stands on. A piece of a segmentation
that does neither is part of an object it touches. Such a piece is smaller than that neighbour, much of its
footprint lies within the neighbour's (its points over the area the neighbour's convex hull covers on the plane),
its lowest heights are above the neighbour's - it does not reach the table beside the neighbour - and they reach
down into the lower part of the neighbour's heights, so it cannot rest on the neighbour's top either. The inside
of a mug or bowl seen over its rim together with the rim and the handle's top is such a piece: the convexity
grouping cuts it from the outside along the concave fold of the inner wall. Two solid objects standing side by
side have footprints apart, an object standing on another starts at the other's top, and a can standing in a bowl
is larger than the piece of the bowl's outside it touches; none of them is joined.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import (
    Boundaries,
    inside_share,
    join_labels,
    label_groups,
    touching_pairs,
)


@dataclass(frozen=True)
class SupportRules:
    """Thresholds of :func:`join_unsupported`: the share of a piece's footprint that must lie within its holder's
    hull (``held_share``; a handle beside the body may take up the rest), the height noise (metres) by which its
    lowest heights must exceed the holder's (``tolerance``), the share of the holder's heights (from its 5 % to its
    95 % height) its lowest heights must lie below (``reach_down``), the raster cell of the footprints (metres) and
    the points sampled per piece."""

    held_share: float = 0.4
    tolerance: float = 0.003
    reach_down: float = 0.5
    cell: float = 0.005
    samples: int = 400


@dataclass(frozen=True)
class _Heights:
    """The 5 % and 95 % heights above the plane of each label (NaN where a label has no finite point)."""

    low: np.ndarray
    high: np.ndarray
    top: np.ndarray


def _heights(pixels: np.ndarray, starts: np.ndarray, plane_points: np.ndarray, samples: int) -> _Heights:
    """The 5 %, 95 % and 99 % heights of every label."""
    count = starts.size - 1
    low, high, top = np.full(count, np.nan), np.full(count, np.nan), np.full(count, np.nan)
    for label in range(1, count):
        own = pixels[starts[label] : starts[label + 1]]
        heights = plane_points[own[:: max(1, own.size // samples)], 2]
        heights = np.sort(heights[np.isfinite(heights)])
        if heights.size:
            last = heights.size - 1
            low[label], high[label] = heights[round(0.05 * last)], heights[round(0.95 * last)]
            top[label] = heights[round(0.99 * last)]
    return _Heights(low, high, top)


def _hull(pixels: np.ndarray, starts: np.ndarray, plane_points: np.ndarray, label: int, samples: int) -> np.ndarray:
    own = pixels[starts[label] : starts[label + 1]]
    feet = plane_points[own[:: max(1, own.size // samples)], :2]
    feet = np.ascontiguousarray(feet[np.isfinite(feet).all(axis=1)], dtype=np.float32)
    return cv2.convexHull(feet).reshape(-1, 2) if feet.shape[0] >= 3 else feet


def unsupported_holders(labels: np.ndarray, plane_points: np.ndarray, rules: SupportRules) -> list[tuple[int, int]]:
    """``(piece, holder)`` pairs: each piece that cannot stand by itself with the touching neighbour whose hull
    holds the largest share of its footprint (see the module docstring); ``plane_points`` are the ``(u, v,
    height)`` plane coordinates of every pixel of ``labels`` (HxWx3 or (H*W)x3)."""
    pairs = touching_pairs(labels)
    if pairs.shape[0] == 0:
        return []
    flat_points = plane_points.reshape(-1, 3)
    pixels, starts = label_groups(labels)
    heights = _heights(pixels, starts, flat_points, rules.samples)
    both = np.concatenate([pairs, pairs[:, ::-1]])  # (piece, holder) both ways round
    piece_low, holder_low, holder_high = heights.low[both[:, 0]], heights.low[both[:, 1]], heights.high[both[:, 1]]
    with np.errstate(invalid="ignore"):
        candidates = (piece_low > holder_low + rules.tolerance) & (
            piece_low < holder_low + rules.reach_down * (holder_high - holder_low)
        )
    hulls: dict[int, np.ndarray] = {}
    best: dict[int, tuple[float, int]] = {}
    sizes = np.diff(starts)
    candidates &= sizes[both[:, 1]] >= sizes[both[:, 0]]  # a piece of an object is smaller than the rest of it
    for piece, holder in both[candidates].tolist():
        for label in (piece, holder):
            if label not in hulls:
                hulls[label] = _hull(pixels, starts, flat_points, label, rules.samples)
        if hulls[piece].shape[0] < 3 or hulls[holder].shape[0] < 3:
            continue
        share = inside_share(hulls[piece], hulls[holder], rules.cell)
        if share >= rules.held_share and share > best.get(piece, (-1.0, 0))[0]:
            best[piece] = (share, holder)
    return [(piece, holder) for piece, (_, holder) in best.items()]


def join_unsupported(labels: np.ndarray, plane_points: np.ndarray, rules: SupportRules | None = None) -> np.ndarray:
    """Labels with every piece that cannot stand by itself joined to the neighbour that holds it, repeated while
    a join makes another piece held (a mug's inside first joins its outside, whose footprint then holds the rim
    and handle); renumbered 1..n when anything joined."""
    r = rules or SupportRules()
    for _ in range(int(labels.max(initial=0))):
        joins = unsupported_holders(labels, plane_points, r)
        if not joins:
            break
        labels = join_labels(labels, joins)
    return labels


@dataclass(frozen=True)
class AppendageRules:
    """Thresholds of :func:`join_appendages`: a piece at most ``small_share`` of its neighbour's size, touching it
    in 3-D (close, see :class:`~annotators.geometry.grid_segmentation.Boundaries`) along at least ``close_share``
    of their shared border and ``boundary_share`` times the square root of its size (at least ``min_boundary``
    pixel pairs), its heights (5 %-95 %) within the neighbour's (5 %-99 %, ``tolerance`` metres of slack)."""

    small_share: float = 0.25
    close_share: float = 0.6
    boundary_share: float = 0.6
    min_boundary: int = 3
    tolerance: float = 0.003
    samples: int = 400


def appendage_owners(
    labels: np.ndarray, plane_points: np.ndarray, surface: Boundaries, rules: AppendageRules
) -> list[tuple[int, int]]:
    """``(piece, owner)`` pairs of :func:`join_appendages`: each small piece with the neighbour it touches along
    the longest close border among those that qualify."""
    if surface.pairs.shape[0] == 0:
        return []
    pixels, starts = label_groups(labels)
    sizes = np.diff(starts)
    heights = _heights(pixels, starts, plane_points.reshape(-1, 3), rules.samples)
    both = np.concatenate([surface.pairs, surface.pairs[:, ::-1]])
    close_length = np.tile(surface.close * surface.length, 2)
    with np.errstate(invalid="ignore"):
        qualifies = (
            (np.tile(surface.close, 2) >= rules.close_share)
            & (close_length >= np.maximum(rules.min_boundary, rules.boundary_share * np.sqrt(sizes[both[:, 0]])))
            & (sizes[both[:, 0]] <= rules.small_share * sizes[both[:, 1]])
            & (heights.low[both[:, 0]] >= heights.low[both[:, 1]] - rules.tolerance)
            & (heights.high[both[:, 0]] <= heights.top[both[:, 1]] + rules.tolerance)
        )
    best: dict[int, tuple[float, int]] = {}
    for (piece, owner), length in zip(both[qualifies].tolist(), close_length[qualifies].tolist(), strict=True):
        if length > best.get(piece, (-1.0, 0))[0]:
            best[piece] = (length, owner)
    return [(piece, owner) for piece, (_, owner) in best.items()]


def join_appendages(
    labels: np.ndarray, plane_points: np.ndarray, surface: Boundaries, rules: AppendageRules | None = None
) -> np.ndarray:
    """Labels with every small piece joined to the larger neighbour it sticks out of (see :class:`AppendageRules`):
    a piece a quarter of a neighbour's size or less whose surface touches the neighbour's in 3-D along most of
    their shared border, and which lies within the neighbour's heights - a drill's chuck cut off at the concave
    fold where it leaves the body, a bowl's floor inside its walls. Objects standing side by side touch along a
    line at most; along the rest of their shared border in the image one hides the other (a depth jump)."""
    joins = appendage_owners(labels, plane_points, surface, rules or AppendageRules())
    return join_labels(labels, joins) if joins else labels
