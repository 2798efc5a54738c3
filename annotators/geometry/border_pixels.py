"""Border pixels: the measured pixels along a segment's outline that the coarse grid left unlabelled.

A segmentation on every ``stride``-th pixel is carried back to full resolution by giving each pixel the label of
its cell's sample, kept only where the pixel lies on the sample's surface. Along an outline the sample often lies
on the surface behind (or is a cut pixel without a label), so a band up to ``stride - 1`` pixels wide of the
object's own pixels stays unlabelled: the masks lose their border.

:func:`claim_border_pixels` gives such a pixel to the one segment it touches (4-neighbours) when it continues that
segment's surface: no depth jump to the neighbour it touches and a normal that differs from the neighbour's by at
most the segmenter's smoothness angle. A pixel touching two segments on its surface lies between them and stays
unlabelled; the normals are estimated only at the pixels examined, so the step costs little beside the
segmentation.
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


@dataclass(frozen=True)
class BorderRules:
    """Thresholds of :func:`claim_border_pixels`, all the segmenter's own: a depth jump is a difference of more
    than ``jump_absolute + jump_relative * nearer depth`` (metres); normals are spanned by the points
    ``normal_step`` pixels away and continue a surface when they differ by at most ``smooth_degrees``."""

    jump_absolute: float
    jump_relative: float
    normal_step: int
    smooth_degrees: float


def normals_at(points: np.ndarray, rows: np.ndarray, cols: np.ndarray, rules: BorderRules) -> np.ndarray:
    """Nx3 unit normals (facing the camera) of an organized HxWx3 cloud at the pixels ``(rows, cols)``.

    Each axis is spanned by the points ``rules.normal_step`` pixels to either side, or by the pixel itself and the
    one side on its own surface (no depth jump) at an outline; NaN where neither side is on its surface.
    """
    height, width = points.shape[:2]
    centre = points[rows, cols]
    spans = []
    for step_row, step_col in ((0, 1), (1, 0)):
        ends = []
        for sign in (1, -1):
            row = rows + sign * step_row * rules.normal_step
            col = cols + sign * step_col * rules.normal_step
            inside = (row >= 0) & (row < height) & (col >= 0) & (col < width)
            other = points[np.where(inside, row, 0), np.where(inside, col, 0)]
            with np.errstate(invalid="ignore"):
                same = inside & ~depth_jump(centre[:, 2], other[:, 2], rules.jump_absolute, rules.jump_relative)
            same &= np.isfinite(other[:, 2])
            ends.append((np.where(same[:, None], other, centre), same))
        (forward, forward_ok), (backward, backward_ok) = ends
        spans.append(np.where((forward_ok | backward_ok)[:, None], forward - backward, np.nan))
    normals = np.cross(spans[0], spans[1])
    with np.errstate(invalid="ignore", divide="ignore"):
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        away = np.einsum("ij,ij->i", normals, centre) > 0
    normals[away] *= -1
    return normals


def claim_border_pixels(
    labels: np.ndarray, points: np.ndarray, candidates: np.ndarray, rules: BorderRules
) -> np.ndarray:
    """``labels`` (HxW int, 0 = none) with the unlabelled ``candidates`` pixels that continue the one segment they
    touch given its label (see the module docstring); ``points`` is the HxWx3 cloud of the same pixels."""
    touching = cv2.dilate((labels > 0).view(np.uint8), _CROSS).view(bool)
    open_ = np.flatnonzero(touching & candidates & (labels == 0))
    if open_.size == 0:
        return labels
    height, width = labels.shape
    rows, cols = open_ // width, open_ % width
    flat_labels = labels.reshape(-1)
    flat_depth = points[..., 2].reshape(-1)
    depth = flat_depth[open_]
    lowest = np.full(open_.size, np.iinfo(np.int64).max, dtype=np.int64)
    highest = np.zeros(open_.size, dtype=np.int64)
    beside = np.full(open_.size, -1, dtype=np.int64)  # the first neighbour on the pixel's surface
    for step_row, step_col in _NEIGHBOURS:
        row, col = rows + step_row, cols + step_col
        inside = (row >= 0) & (row < height) & (col >= 0) & (col < width)
        neighbour = np.where(inside, row * width + col, 0)
        label = np.where(inside, flat_labels[neighbour], 0).astype(np.int64)
        with np.errstate(invalid="ignore"):
            on_surface = (label > 0) & ~depth_jump(
                depth, flat_depth[neighbour], rules.jump_absolute, rules.jump_relative
            )
        lowest = np.where(on_surface, np.minimum(lowest, label), lowest)
        highest = np.where(on_surface, np.maximum(highest, label), highest)
        beside = np.where(on_surface & (beside < 0), neighbour, beside)
    one = (highest > 0) & (lowest == highest)
    if not one.any():
        return labels
    open_, rows, cols, beside = open_[one], rows[one], cols[one], beside[one]
    own = normals_at(points, rows, cols, rules)
    theirs = normals_at(points, beside // width, beside % width, rules)
    with np.errstate(invalid="ignore"):
        smooth = np.einsum("ij,ij->i", own, theirs) >= np.cos(np.radians(rules.smooth_degrees))
    claimed = labels.copy()
    claimed.reshape(-1)[open_[smooth]] = flat_labels[beside[smooth]]
    return claimed
