"""A piece standing on another on a narrow neck, on the organized grid: one rigid body, they join.

An object set down on another rests on its base: a can standing on a can touches it with its whole bottom, a box
lying on a box with its whole lower face, and what the camera sees of the lower half of the upper piece spans, at
every height, about as far on the table plane as the whole piece. A piece that starts at a lower piece's top but
narrows in its lower half to a neck spanning under a third of the whole piece (an upright drill's grip
entering the battery, its body and chuck reaching far beyond the grip), could not have been set down there and
stay: it is held by the lower piece, one rigid body cut by the convexity grouping at the concave fold where the
neck meets the lower part. The two then join (:func:`join_necked_pieces`).

Objects stacked on purpose rest on a base about as wide as they are and stay apart: the soup can on the spam can,
stacked boxes, a plate or a box lying across a can (every slice of the box is its whole front edge). An object that
narrows toward its bottom and is balanced on it (a ball, an inverted cone) would be joined: on a table such a thing
rolls or tips, which is why it is rarely seen resting on another object.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import join_labels
from annotators.geometry.support import PieceSummary, span, summarize_pieces
from annotators.geometry.support_kernels import narrowest_slice_span


@dataclass(frozen=True)
class NeckRules:
    """Thresholds of :func:`join_necked_pieces`: the height noise (metres) within which the upper piece's lowest
    heights (5 %) must reach the lower piece's top (95 %) or lie above it (``tolerance``), the clearance (metres)
    by which they stay above the table (``clearance``: the upper piece does not reach down to the table beside the
    lower one), the thickness (metres) of the height slices of the upper piece's lower half (``band``), and the
    largest share of the upper piece's span on the table plane its narrowest slice may span to be a neck
    (``neck_share``: objects set down on purpose rest on a base about as wide as they are; slices of fewer than
    ``min_slice`` sampled points are not measured); the upper piece must be one surface in the image (its largest
    4-connected region holds ``one_surface`` of its pixels); heights sampled on every ``sample_step``-th pixel."""

    tolerance: float = 0.01
    clearance: float = 0.02
    band: float = 0.01
    neck_share: float = 0.33
    min_slice: int = 5
    one_surface: float = 0.9
    sample_step: int = 2


def stacked_candidates(pieces: PieceSummary, labels: np.ndarray, rules: NeckRules) -> np.ndarray:
    """Kx2 touching label pairs ``(upper, lower)`` where the upper piece starts at the lower one's top (within
    ``rules.tolerance``) and stays clear of the table."""
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] == 0:
        return pairs.reshape(0, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    upper = np.where(pieces.low[a] >= pieces.low[b], a, b)
    lower = np.where(upper == a, b, a)
    with np.errstate(invalid="ignore"):
        on_top = pieces.low[upper] >= pieces.high[lower] - rules.tolerance
        clear = pieces.low[upper] >= rules.clearance
    return np.column_stack([upper, lower])[on_top & clear]


def neck_and_body(
    labels: np.ndarray, plane_points: np.ndarray, label: int, rules: NeckRules, box: np.ndarray | None = None
) -> tuple[float, float]:
    """The span on the table plane of a piece's neck - its narrowest ``rules.band`` thick slice of heights from
    its 5 % height up to the middle of its heights, slices of fewer than ``rules.min_slice`` sampled points
    skipped - and of the whole piece, from every ``rules.sample_step``-th pixel (``(inf, 0)`` without a slice);
    ``box`` ``(x0, y0, x1, y1)`` holds the piece's pixels when known (only it is read)."""
    step = max(1, rules.sample_step)
    height, width = labels.shape
    x0, y0, x1, y1 = (0, 0, width, height) if box is None else (int(value) for value in box)
    x0, y0 = x0 - x0 % step, y0 - y0 % step  # the same sampled pixels as on the whole grid
    sampled = plane_points.reshape(height, width, 3)[y0:y1:step, x0:x1:step]
    mine = labels[y0:y1:step, x0:x1:step] == label
    chosen = sampled[mine & np.isfinite(sampled[..., 2])].astype(np.float64)
    if chosen.shape[0] < rules.min_slice:
        return np.inf, 0.0
    low, high = np.percentile(chosen[:, 2], [5, 95])
    bottoms = np.arange(low, low + 0.5 * (high - low), rules.band)
    return narrowest_slice_span(chosen, bottoms, rules.band, rules.min_slice), span(chosen[:, :2])


def one_surface(labels: np.ndarray, label: int, box: np.ndarray, share: float) -> bool:
    """Whether the largest 4-connected region of a label (within its pixel ``box``, ``(x0, y0, x1, y1)``) holds at
    least ``share`` of its pixels: a body seen as one surface, not pieces apart in the image."""
    x0, y0, x1, y1 = (int(value) for value in box)
    mine = (labels[y0:y1, x0:x1] == label).astype(np.uint8)
    count, parts = cv2.connectedComponents(mine, connectivity=4)
    sizes = np.bincount(parts.reshape(-1), minlength=count)[1:]
    return sizes.size > 0 and sizes.max() >= share * sizes.sum()


def neck_partners(
    labels: np.ndarray, plane_points: np.ndarray, rules: NeckRules, pieces: PieceSummary | None = None
) -> list[tuple[int, int]]:
    """The ``(upper, lower)`` label pairs where the upper piece stands on the lower one on a neck (see the module
    docstring); ``plane_points`` the pixels' ``(u, v, height)``, ``pieces`` the labels' summary when already made."""
    pieces = pieces or summarize_pieces(labels, plane_points, rules.sample_step)
    joins = []
    necked: dict[int, bool] = {}  # a piece standing on several lower ones is measured once
    for upper, lower in stacked_candidates(pieces, labels, rules).tolist():
        if upper not in necked:
            box = pieces.boxes[upper]
            if one_surface(labels, upper, box, rules.one_surface):
                neck, body = neck_and_body(labels, plane_points, upper, rules, box)
                necked[upper] = neck < rules.neck_share * body
            else:
                necked[upper] = False
        if necked[upper]:
            joins.append((upper, lower))
    return joins


def join_necked_pieces(
    labels: np.ndarray, plane_points: np.ndarray, rules: NeckRules | None = None, pieces: PieceSummary | None = None
) -> np.ndarray:
    """Labels with each piece that stands on another on a narrow neck joined to it (see :class:`NeckRules`);
    renumbered 1..n when anything joined (``pieces``: the labels' summary when already made, with the rules'
    sample step)."""
    joins = neck_partners(labels, plane_points, rules or NeckRules(), pieces)
    return join_labels(labels, joins) if joins else labels
