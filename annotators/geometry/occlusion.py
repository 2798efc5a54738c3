"""Occlusion completion on the organized grid: the pieces of one object that a nearer object cuts apart.

A box lying across another splits the view of the lower one into two disjoint pieces; a box standing in front of
a can lying on the table leaves its two ends. They are one object when (the Gestalt rule of good continuation
behind an occluder):

* both lie behind a common occluder: near it (within ``rules.band`` pixels, which also bridges the sensor's
  shadow beside an occluding edge, where no depth is measured) they are farther than it by a depth jump;
* they do not touch each other, or only along a border shorter than the touching joins trust (``rules.min_boundary``
  pixel pairs and ``rules.boundary_share`` times the square root of the smaller piece's size): two pieces of a
  box's top on either side of a box lying across it may meet at a corner beyond the occluder's end;
* the surface goes on from one to the other along the line between them: that line lies in the tangent planes
  of both pieces near the occluder (within ``rules.degrees`` for most of their pixels). This holds for one plane
  continuing behind the occluder, for a box's top and front together, and for a can lying on its side seen at
  both ends (the line runs along its axis, across which all its normals lie) - for any surface extruded along
  the hidden stretch;
* the cross-sections agree: seen along that line, both pieces reach the same height above the support plane
  (within ``rules.tolerance`` metres or ``rules.relative`` of the larger) and, unless they lie on one plane
  (``rules.flat`` metres RMS: a flat top may have any outline behind the occluder), the narrower one spans no
  more than the wider one across it (a box turned across the line shows a corner on one side);
* the straight image line between them runs mostly through the occluder (they face each other across it), and
  the occluder is nearer there than the surface joining them would be.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from annotators.geometry.grid_kernels import label_pixels, touching_keys
from annotators.geometry.grid_segmentation import MergeRules, join_labels


@dataclass(frozen=True)
class OcclusionRules:
    """Thresholds of :func:`join_occluded` (pixels, shares, degrees, metres)."""

    band: int = 6
    degrees: float = 20.0
    tangent_share: float = 0.6
    tolerance: float = 0.015
    relative: float = 0.15
    flat: float = 0.005
    through_occluder: float = 0.5
    min_points: int = 20
    boundary_share: float = MergeRules.boundary_share
    min_boundary: int = MergeRules.min_boundary


@dataclass(frozen=True, eq=False)
class _Piece:
    """A piece near an occluder: its pixels there (flat indices), their finite 3-D points and centroid, their
    image centroid, and their finite normals and plane coordinates ``(u, v, height)``."""

    label: int
    band: np.ndarray
    points: np.ndarray
    centre: np.ndarray
    pixel: np.ndarray
    normals: np.ndarray
    section: np.ndarray

    @functools.cached_property
    def middle(self) -> np.ndarray:
        """The median plane position ``(u, v)`` of the band."""
        return np.median(self.section[:, :2], axis=0)

    @functools.cached_property
    def heights(self) -> np.ndarray:
        """The 5 % and 95 % heights of the band above the plane."""
        return np.quantile(self.section[:, 2], (0.05, 0.95))


def join_occluded(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    on_plane: np.ndarray,
    absolute: float,
    relative: float,
    rules: OcclusionRules,
) -> np.ndarray:
    """Labels with the pieces of occluded objects joined (see the module docstring), renumbered 1..n.

    ``points`` and ``normals`` are the HxWx3 grid and its unit normals (NaN where unknown); ``on_plane`` the HxWx3
    coordinates ``(u, v, height)`` of every grid point on the support plane.
    """
    count = int(labels.max(initial=0))
    if count < 3:
        return labels
    depth = points[..., 2]
    flat_labels = labels.reshape(-1)
    touching = _touching(labels, count, rules)
    joined: list[tuple[int, int]] = []
    for occluder, behind in _pieces_behind(labels, points, normals, on_plane, touching, absolute, relative, rules):
        for index, first in enumerate(behind):
            for second in behind[index + 1 :]:
                key = (min(first.label, second.label), max(first.label, second.label))
                if touching[key]:
                    continue
                if (
                    _continues(first, second, rules)
                    and _same_section(first, second, rules)
                    and _across(flat_labels, depth, labels.shape, occluder, first, second) >= rules.through_occluder
                ):
                    joined.append(key)
    return join_labels(labels, joined) if joined else labels


def _loops() -> ModuleType:
    """:mod:`annotators.geometry.occlusion_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import occlusion_loops

    return occlusion_loops


def _pieces_behind(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    on_plane: np.ndarray,
    touching: np.ndarray,
    absolute: float,
    relative: float,
    rules: OcclusionRules,
) -> list[tuple[int, list[_Piece]]]:
    """Each occluder (increasing) with the pieces behind it that may join (increasing): objects farther than it
    as a whole, with at least ``rules.min_points`` pixels in its band (within ``rules.band`` pixels of it or of the
    sensor's shadow beside it) that face as many of its pixels, farther than it there by a depth jump, and apart
    from another such piece (``touching``: the bool matrix of labels that touch). Found in one compiled pass
    (:func:`annotators.geometry.occlusion_loops.pieces_behind`); occluders with fewer than two are left out."""
    count = touching.shape[0] - 1
    _, starts, boxes = label_pixels(np.ascontiguousarray(labels))  # boxes (x0, y0, x1, y1) of labels 0..count
    sizes = np.diff(starts)
    depth = points[..., 2]
    flat_labels = labels.reshape(-1)
    measured = np.isfinite(depth).reshape(-1) & (flat_labels > 0)
    sums = np.bincount(flat_labels[measured], depth.reshape(-1)[measured], minlength=count + 1)
    mean_depth = sums / np.maximum(np.bincount(flat_labels[measured], minlength=count + 1), 1)
    ids, ends, bands, xyz, band_normals, sections, centres, pixels = _loops().pieces_behind(
        np.ascontiguousarray(labels),
        np.ascontiguousarray(points),
        normals.reshape(-1, 3),
        on_plane.reshape(-1, 3),
        mean_depth,
        sizes,
        boxes,
        touching,
        rules.band,
        rules.min_points,
        absolute,
        relative,
    )
    found: list[tuple[int, list[_Piece]]] = []
    for k, (occluder, label) in enumerate(ids.tolist()):
        piece = _Piece(
            label,
            bands[ends[0, k] : ends[0, k + 1]],
            xyz[ends[1, k] : ends[1, k + 1]],
            centres[k],
            pixels[k],
            band_normals[ends[2, k] : ends[2, k + 1]],
            sections[ends[3, k] : ends[3, k + 1]],
        )
        if found and found[-1][0] == occluder:
            found[-1][1].append(piece)
        else:
            found.append((occluder, [piece]))
    return found


def _coplanar(first: _Piece, second: _Piece, flat: float) -> bool:
    """Do the two pieces' points near the occluder lie on one plane (RMS distance at most ``flat`` metres)?"""
    xyz = np.concatenate([first.points, second.points]).astype(np.float64)
    centred = xyz - xyz.mean(axis=0)
    smallest = np.linalg.eigvalsh(centred.T @ centred / xyz.shape[0])[0]
    return bool(np.sqrt(max(smallest, 0.0)) <= flat)


def _continues(first: _Piece, second: _Piece, rules: OcclusionRules) -> bool:
    """Does the line between the pieces' centroids lie in the tangent planes of both (for at least
    ``rules.tangent_share`` of the pixels with a normal of each)?"""
    offset = second.centre - first.centre
    length = float(np.linalg.norm(offset))
    if length < 1e-6:
        return False
    direction = offset / length
    sine = np.sin(np.radians(rules.degrees))
    for piece in (first, second):
        known = piece.normals
        if known.shape[0] < rules.min_points:
            return False
        if np.count_nonzero(np.abs(known @ direction) <= sine) < rules.tangent_share * known.shape[0]:
            return False
    return True


def _same_section(first: _Piece, second: _Piece, rules: OcclusionRules) -> bool:
    """Seen along the line between them, do the pieces reach the same height and span the same width?"""
    a, b = first.section, second.section
    along = second.middle - first.middle
    norm = float(np.linalg.norm(along))
    if norm < 1e-6:
        return False
    across = np.array([-along[1], along[0]]) / norm
    slack = lambda low_a, high_a, low_b, high_b: max(  # noqa: E731
        rules.tolerance, rules.relative * max(high_a - low_a, high_b - low_b)
    )
    (low_a, high_a), (low_b, high_b) = first.heights, second.heights
    if abs(high_a - high_b) > slack(low_a, high_a, low_b, high_b):
        return False  # one reaches higher than the other
    if _coplanar(first, second, rules.flat):
        return True  # one plane going on behind the occluder: any outline of it may continue there
    low_a, high_a = np.quantile(a[:, :2] @ across, (0.05, 0.95))
    low_b, high_b = np.quantile(b[:, :2] @ across, (0.05, 0.95))
    width = slack(low_a, high_a, low_b, high_b)
    # the narrower cross-section lies within the wider (a corner of a box turned across the line is narrower)
    if high_a - low_a > high_b - low_b:
        low_a, high_a, low_b, high_b = low_b, high_b, low_a, high_a
    return low_a >= low_b - width and high_a <= high_b + width


def _touching(labels: np.ndarray, count: int, rules: OcclusionRules) -> np.ndarray:
    """The symmetric (count+1)x(count+1) bool matrix of the labels that touch as 4-neighbours along a border the
    touching joins would trust: at least ``rules.min_boundary`` pixel pairs and ``rules.boundary_share`` times the
    square root of the smaller label's size."""
    span = count + 1
    keys = touching_keys(np.ascontiguousarray(labels), span)  # one per 4-neighbour pixel pair of two labels
    lengths = np.bincount(keys, minlength=span * span).reshape(span, span)
    lengths = lengths + lengths.T
    sizes = np.bincount(labels.reshape(-1), minlength=span)
    needed = np.maximum(rules.min_boundary, rules.boundary_share * np.sqrt(np.minimum.outer(sizes, sizes)))
    return (lengths > 0) & (lengths >= needed)


def _across(
    flat_labels: np.ndarray,
    depth: np.ndarray,
    shape: tuple[int, int],
    occluder: int,
    first: _Piece,
    second: _Piece,
) -> float:
    """The share of the image line between the two pieces' band centroids, outside the two pieces and where depth
    is measured, that the occluder covers in front of the straight 3-D line between their centroids (the hidden
    surface)."""
    (r0, c0), (r1, c1) = first.pixel, second.pixel
    steps = int(max(abs(r1 - r0), abs(c1 - c0))) + 1
    t = np.linspace(0.0, 1.0, steps)
    rows = np.clip(np.round(r0 + t * (r1 - r0)).astype(int), 0, shape[0] - 1)
    cols = np.clip(np.round(c0 + t * (c1 - c0)).astype(int), 0, shape[1] - 1)
    hidden_depth = first.centre[2] + t * (second.centre[2] - first.centre[2])
    on_line = flat_labels[rows * shape[1] + cols]
    line_depth = depth[rows, cols]
    with np.errstate(invalid="ignore"):
        covered = (on_line == occluder) & (line_depth < hidden_depth)
    between = (on_line != first.label) & (on_line != second.label) & np.isfinite(line_depth)
    return float(np.count_nonzero(covered) / max(np.count_nonzero(between), 1))
