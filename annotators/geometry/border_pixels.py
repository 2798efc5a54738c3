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
(``bench/bench_border_pixels.py``). The per-pixel work runs in compiled passes (:mod:`annotators.geometry.border_loops`)
in the cloud's single precision (``points`` are ``float32``).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.border_loops import claim_foot, claim_outline, foot_candidates

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


def plane_noise(points: np.ndarray, plane: np.ndarray, plane_indices: np.ndarray) -> float:
    """How far (metres) the supporting plane's own points scatter off it: the :data:`NOISE_SHARE` quantile of the
    distances of its inliers (flat indices ``plane_indices`` of the HxWx3 ``points``, at most :data:`SAMPLE`)."""
    sample = points.reshape(-1, 3)[plane_indices[:: max(1, plane_indices.size // SAMPLE)]]
    with np.errstate(invalid="ignore"):
        distances = np.abs(sample.astype(np.float64) @ np.asarray(plane[:3], dtype=np.float64) + float(plane[3]))
    distances = distances[np.isfinite(distances)]
    return float(np.quantile(distances, NOISE_SHARE)) if distances.size else 0.0


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
    rows, cols = np.divmod(sample[sample % width < width - 1], width)
    here, right = points[rows, cols], points[rows, cols + 1]
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
    near = cv2.dilate((labels > 0).view(np.uint8), kernel)
    pixels, normals = foot_candidates(
        near, labels, candidates, heights, floor, rules.min_height, coarse_normals, rules.stride
    )
    if pixels.size == 0:
        return
    smooth_cosine = np.cos(np.radians(rules.smooth_degrees))
    with np.errstate(invalid="ignore"):
        facing_away = np.abs(normals @ plane[:3]) < smooth_cosine
    claim_foot(
        labels,
        points,
        pixels,
        normals,
        facing_away,
        coarse_normals,
        rules.stride,
        rules.jump_absolute,
        rules.jump_relative,
        float(smooth_cosine),
        reach,
    )


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
    outline = np.zeros(0, dtype=np.int64)
    smooth_cosine = float(np.cos(np.radians(rules.smooth_degrees)))
    args = (rules.jump_absolute, rules.jump_relative, rules.normal_step, smooth_cosine, rules.crease)
    for _ in range(rules.stride - 1):
        ring = cv2.dilate((claimed > 0).view(np.uint8), _CROSS).view(bool)
        ring &= candidates
        ring &= claimed == 0
        outline = np.flatnonzero(ring)
        if claim_outline(claimed, points, outline, *args) == 0:
            break
    # the reach of the foot at the depths of the segments' outline (their own pixels when no outline was examined)
    reach = _foot_reach(points, outline if outline.size else np.flatnonzero(occupied), rules.min_height)
    if reach > 0:
        plane = np.asarray(plane, dtype=np.float64)
        _claim_foot(claimed, points, heights, candidates, plane, floor, coarse_normals, rules, reach)
    return claimed
