"""Border pixels: the measured pixels along a segment's outline that the segmentation left unlabelled.

Two bands of an object's own pixels stay unlabelled after a segmentation on every ``stride``-th pixel:

* the **outline**: the grid is carried back to full resolution by giving each pixel the label of its cell's sample,
  kept only where the pixel lies on the sample's surface; along an outline the sample often lies on the surface
  behind (or is a cut pixel without a label), so up to ``stride - 1`` pixels of the object's rim are lost;
* the **foot**: only points at least ``min_height`` above the supporting plane are candidates, so the lowest
  centimetre of every object, where it stands on the plane, is cut off.

:func:`claim_border_pixels` gives an outline pixel to the one segment it touches (4-neighbours) when it continues
that segment's surface: no depth jump to the neighbour it touches, and normals that agree within the segmenter's
smoothness angle or meet over a convex edge - never a concave crease, where another surface meets the segment; a
pixel touching two segments on its surface lies between them and stays unlabelled. This is done in
``stride - 1`` rounds.

Foot pixels must stand out of the plane's noise (higher than 95 % of the plane's own inliers lie off it,
:func:`plane_noise`) and face away from the plane (the normal of their cell on the segmentation's grid more than the
smoothness angle off the plane's): the plane itself and what lies flat on it stay out. Linked where they continue
one another smoothly (no depth jump, normals within the smoothness angle) and to the segments they continue
smoothly, they join the segment nearest along these links (a breadth-first search at most as many links deep as
``min_height`` spans pixels at the segments' nearest depth), so the foot running along two touching objects is
shared between them.

Only the pixels within that reach of a segment are examined and normals are estimated only at the outline's pixels,
so the step's cost grows with the length of the outlines and the area of the feet, not with the frame
(``bench/bench_border_pixels.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import depth_jump

_CROSS = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=np.uint8)
"""The 4-neighbourhood as a structuring element."""

_NEIGHBOURS: tuple[tuple[int, int], ...] = ((0, -1), (0, 1), (-1, 0), (1, 0))
"""Row and column steps to the left, right, upper and lower 4-neighbour."""

NOISE_SHARE = 0.95
"""The share of the plane's inliers that lie closer to it than its noise level (:func:`plane_noise`)."""

SAMPLE = 500
"""At most this many points are read to measure the plane's noise or the pixel pitch."""


@dataclass(frozen=True)
class BorderRules:
    """Thresholds of :func:`claim_border_pixels`, all the segmenter's own: a depth jump is a difference of more
    than ``jump_absolute + jump_relative * nearer depth`` (metres); normals are spanned by the points
    ``normal_step`` pixels away and continue a surface when they differ by at most ``smooth_degrees`` or bend
    convexly (a concave crease bends by less than ``-crease``, as between touching parts); candidates start
    ``min_height`` above the plane; the segmentation labels every ``stride``-th pixel, so the outline it loses is
    up to ``stride - 1`` pixels wide."""

    jump_absolute: float
    jump_relative: float
    normal_step: int
    smooth_degrees: float
    crease: float
    min_height: float
    stride: int


def _neighbours(pixels: np.ndarray, shape: tuple[int, ...], step: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The left, right, upper and lower neighbours ``step`` pixels away of the flat ``pixels`` on a grid of
    ``shape``: Nx4 flat indices (0 where off the grid) and Nx4 bool, which lie on the grid."""
    height, width = shape[:2]
    rows, cols = np.divmod(pixels[:, None], width)
    row_steps = np.array([[0, 0, -step, step]])
    col_steps = np.array([[-step, step, 0, 0]])
    inside = (rows + row_steps >= 0) & (rows + row_steps < height) & (cols + col_steps >= 0)
    inside &= cols + col_steps < width
    neighbours = pixels[:, None] + (row_steps * width + col_steps)
    neighbours[~inside] = 0
    return neighbours, inside


def _on_surface(flat_points: np.ndarray, pixels: np.ndarray, neighbours: np.ndarray, rules: BorderRules) -> np.ndarray:
    """NxK bool: which ``neighbours`` (NxK flat indices) of the ``pixels`` are measured and on their surface."""
    with np.errstate(invalid="ignore"):
        other = flat_points[neighbours, 2]
        return ~depth_jump(flat_points[pixels, 2][:, None], other, rules.jump_absolute, rules.jump_relative) & (
            np.isfinite(other)
        )


def normals_at(points: np.ndarray, pixels: np.ndarray, rules: BorderRules) -> np.ndarray:
    """Nx3 unit normals (facing the camera) of an organized HxWx3 cloud at the flat ``pixels``.

    Each axis is spanned by the points ``rules.normal_step`` pixels to either side, or by the pixel itself and the
    one side on its own surface (no depth jump) at an outline; NaN where neither side is on its surface.
    """
    flat = points.reshape(-1, 3)
    neighbours, inside = _neighbours(pixels, points.shape, rules.normal_step)
    same = inside & _on_surface(flat, pixels, neighbours, rules)
    centre = flat[pixels]
    ends = np.where(same[..., None], flat[neighbours], centre[:, None, :])  # Nx4x3: left, right, up, down
    spans = ends[:, 1::2] - ends[:, 0::2]  # Nx2x3: left to right, up to down
    spans[~(same[:, 0::2] | same[:, 1::2])] = np.nan
    (ux, uy, uz), (vx, vy, vz) = spans[:, 0].T, spans[:, 1].T
    normals = np.column_stack([uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx])
    with np.errstate(invalid="ignore", divide="ignore"):
        normals /= np.sqrt(np.einsum("ij,ij->i", normals, normals))[:, None]
        away = np.einsum("ij,ij->i", normals, centre) > 0
    normals[away] *= -1
    return normals


def plane_noise(points: np.ndarray, plane: np.ndarray, plane_indices: np.ndarray) -> float:
    """How far (metres) the supporting plane's own points scatter off it: the :data:`NOISE_SHARE` quantile of the
    distances of its inliers (flat indices ``plane_indices`` of the HxWx3 ``points``, at most :data:`SAMPLE`)."""
    sample = points.reshape(-1, 3)[plane_indices[:: max(1, plane_indices.size // SAMPLE)]]
    with np.errstate(invalid="ignore"):
        distances = np.abs(sample.astype(np.float64) @ np.asarray(plane[:3], dtype=np.float64) + float(plane[3]))
    distances = distances[np.isfinite(distances)]
    return float(np.quantile(distances, NOISE_SHARE)) if distances.size else 0.0


def _claim_outline(labels: np.ndarray, points: np.ndarray, open_: np.ndarray, rules: BorderRules) -> np.ndarray:
    """Give each pixel of ``open_`` (flat indices of unlabelled pixels) the label of the one segment whose surface
    it continues, in place; returns the pixels claimed. Normals are estimated at the pixels themselves: along an
    outline the grid's are unknown (a depth jump lies within their span)."""
    flat_labels, flat_points = labels.reshape(-1), points.reshape(-1, 3)
    neighbours, inside = _neighbours(open_, labels.shape)
    label = np.where(inside, flat_labels[neighbours], 0)
    on_surface = (label > 0) & _on_surface(flat_points, open_, neighbours, rules)
    highest = np.where(on_surface, label, 0).max(axis=1)
    lowest = np.where(on_surface, label, np.iinfo(label.dtype).max).min(axis=1)
    one = (highest > 0) & (lowest == highest)
    beside = neighbours[one, np.argmax(on_surface[one], axis=1)]  # the first labelled neighbour on its surface
    open_ = open_[one]
    if open_.size == 0:
        return open_
    normals = normals_at(points, np.concatenate([open_, beside]), rules)
    own, theirs = normals[: open_.size], normals[open_.size :]
    offset = flat_points[open_] - flat_points[beside]
    with np.errstate(invalid="ignore", divide="ignore"):
        aligned = np.einsum("ij,ij->i", own, theirs) >= np.cos(np.radians(rules.smooth_degrees))
        convexity = np.einsum("ij,ij->i", own - theirs, offset) / np.linalg.norm(offset, axis=1)
        continues = aligned | (convexity >= -rules.crease)
    claimed = open_[continues]
    flat_labels[claimed] = flat_labels[beside[continues]]
    return claimed


def _sampled(coarse: np.ndarray, pixels: np.ndarray, width: int, stride: int) -> np.ndarray:
    """Nx3: the values of the HxWx3 ``coarse`` grid (every ``stride``-th pixel) at the cells of the flat ``pixels``
    of a full-resolution grid ``width`` pixels wide."""
    rows, cols = pixels // width // stride, pixels % width // stride
    return coarse.reshape(-1, 3)[rows * coarse.shape[1] + cols]


def _foot_reach(points: np.ndarray, pixels: np.ndarray, min_height: float) -> int:
    """How many pixels ``min_height`` spans at most at the depths of the flat ``pixels`` (a sample of them): the
    height over the pitch of a pixel at the nearest depth (the angle between neighbouring pixels times the depth)."""
    width = points.shape[1]
    sample = pixels[:: max(1, pixels.size // SAMPLE)]
    sample = sample[sample % width < width - 1]
    flat = points.reshape(-1, 3)
    here, right = flat[sample], flat[sample + 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        angles = np.abs(here[:, 0] / here[:, 2] - right[:, 0] / right[:, 2])
    angles = angles[np.isfinite(angles) & (angles > 0)]
    depths = here[np.isfinite(here[:, 2]), 2]
    if angles.size == 0 or depths.size == 0:
        return 0
    return int(np.ceil(min_height / (float(np.median(angles)) * float(depths.min()))))


def _claim_foot(
    labels: np.ndarray,
    points: np.ndarray,
    heights: np.ndarray,
    candidates: np.ndarray,
    plane: np.ndarray,
    floor: float,
    coarse_normals: np.ndarray,
    rules: BorderRules,
    reach: int,
) -> None:
    """Give the foot pixels within ``reach`` pixels of a segment that continue a segment the label of the nearest
    such segment, in place.

    The foot pixels facing away from the plane are the nodes of a graph: 4-neighbours are linked when no depth
    jump lies between them and their normals are within the smoothness angle, and a pixel touching a segment the
    same way starts with its label. A breadth-first search from all of them at once, at most ``reach`` links deep
    (the foot spans no more), gives every pixel reached the label of its nearest start.
    """
    kernel = np.ones((2 * reach + 1, 2 * reach + 1), dtype=np.uint8)
    near = cv2.dilate((labels > 0).view(np.uint8), kernel).view(bool)
    near &= labels == 0
    near &= ~candidates
    with np.errstate(invalid="ignore"):
        near &= heights > floor
        near &= heights < rules.min_height
    pixels = np.flatnonzero(near)
    flat_points, flat_labels = points.reshape(-1, 3), labels.reshape(-1)
    if pixels.size == 0:
        return
    smooth_cosine = np.cos(np.radians(rules.smooth_degrees))
    normals = _sampled(coarse_normals, pixels, labels.shape[1], rules.stride)
    with np.errstate(invalid="ignore"):
        facing_away = np.abs(normals @ plane[:3]) < smooth_cosine
    pixels, normals = pixels[facing_away], normals[facing_away]
    if pixels.size == 0:
        return
    neighbours, inside = _neighbours(pixels, labels.shape)
    on_surface = inside & _on_surface(flat_points, pixels, neighbours, rules)
    # links between neighbouring foot pixels, and contacts of foot pixels with the segment pixels they touch
    other = np.minimum(np.searchsorted(pixels, neighbours), pixels.size - 1)  # pixels are sorted
    linked = on_surface & (pixels[other] == neighbours)
    touching = on_surface & (flat_labels[neighbours] > 0)
    node = np.broadcast_to(np.arange(pixels.size)[:, None], other.shape)
    first, second = node[linked], other[linked]
    touching_node, segment_pixels = node[touching], neighbours[touching]
    theirs = _sampled(coarse_normals, segment_pixels, labels.shape[1], rules.stride)
    with np.errstate(invalid="ignore"):
        linked[linked] = np.einsum("ij,ij->i", normals[first], normals[second]) >= smooth_cosine
        touches = np.einsum("ij,ij->i", normals[touching_node], theirs) >= smooth_cosine
    label = np.zeros(pixels.size, dtype=flat_labels.dtype)
    label[touching_node[touches]] = flat_labels[segment_pixels[touches]]
    _spread(label, other, linked, reach)
    reached = label > 0
    flat_labels[pixels[reached]] = label[reached]


def _spread(label: np.ndarray, other: np.ndarray, linked: np.ndarray, rounds: int) -> None:
    """Breadth-first, in place, for at most ``rounds`` links: each unlabelled node takes the label of a linked node
    one round after it got one (``other`` Nx4 node indices, ``linked`` Nx4 bool, symmetric), so every node reached
    ends up with the label of a nearest labelled node."""
    size = label.size
    targets = np.where(linked, other, size)  # node ``size`` is a sentinel that counts as labelled
    labels = np.append(label, np.ones(1, dtype=label.dtype))
    frontier = np.flatnonzero(label)
    for _ in range(rounds):
        reached = targets[frontier]
        fresh = labels[reached] == 0
        if not fresh.any():
            break
        sources = np.broadcast_to(frontier[:, None], reached.shape)[fresh]
        frontier = reached[fresh]  # a node reached from several sides appears more than once: harmless
        labels[frontier] = labels[sources]
    label[:] = labels[:size]


def claim_border_pixels(
    labels: np.ndarray,
    points: np.ndarray,
    heights: np.ndarray,
    candidates: np.ndarray,
    *,
    plane: np.ndarray,
    floor: float,
    coarse_normals: np.ndarray,
    rules: BorderRules,
) -> np.ndarray:
    """``labels`` (HxW int, 0 = none) with the outline and foot pixels that continue a segment given its label (see
    the module docstring). ``points`` is the HxWx3 cloud of the same pixels, ``heights`` their heights above the
    plane (NaN where unmeasured), ``candidates`` the pixels the segmentation could label, ``plane`` the supporting
    plane (unit normal toward the camera) and ``floor`` the height above it below which a point counts as the
    plane's (its noise, :func:`plane_noise`); ``coarse_normals`` are the segmentation's normals on every
    ``rules.stride``-th pixel (the foot's pixels take their cell's)."""
    occupied = (labels > 0).view(np.uint8)
    if not cv2.countNonZero(occupied):
        return labels
    claimed = labels.copy()
    points = np.ascontiguousarray(points)  # one copy of a window's points, so that every flat view is free
    outline = np.zeros(0, dtype=np.int64)
    for _ in range(rules.stride - 1):
        ring = cv2.dilate((claimed > 0).view(np.uint8), _CROSS).view(bool)
        ring &= candidates
        ring &= claimed == 0
        outline = np.flatnonzero(ring)
        if _claim_outline(claimed, points, outline, rules).size == 0:
            break
    # the reach of the foot at the depths of the segments' outline (their own pixels when no outline was examined)
    reach = _foot_reach(points, outline if outline.size else np.flatnonzero(occupied), rules.min_height)
    if reach > 0:
        plane = np.asarray(plane, dtype=np.float64)
        _claim_foot(claimed, points, heights, candidates, plane, floor, coarse_normals, rules, reach)
    return claimed
