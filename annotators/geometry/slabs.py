"""Pieces of one slab, on the organized grid: they join.

An object lying on the table (a drill on its side, a tool, a flat case) fills a slab above it: its parts rest on
the same table and reach the same top height. The convexity grouping can still cut it where a thinner part meets
a thicker one - a drill's grip ends behind the battery's raised edge, a small step without a crease the grouping
trusts - and the parts come out as pieces side by side. Two such pieces touch without a depth jump along their
shared border, and their lowest heights and their tops agree within the height noise.

Separate objects rarely do all of this: objects standing side by side show a depth jump along most of their
shared border in the image (one hides the other, or a gap parts them), an object standing on another starts at
the other's top, and objects of different heights do not share a top. Two objects standing side by side as tall as
each other - a mug and a can - can touch without a depth jump where the one's rim meets the other's side; but a
slab lies flat, each of its pieces spanning more on the table than it is high, while a mug or a can is taller than
wide. Those pieces stay apart (:func:`join_slab_pieces`).

The heights are read from the pixels the convexity votes labelled (``trusted``), not from those grown to them:
growth goes by distance in the image, so where another object's edge touches a piece without a depth seam (a
bowl's rim beside the drill's battery), a strip of that edge takes the piece's label and lifts its top by the
other object's height. Where that strip falls depends on where the grid cells start.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from annotators.geometry.grid_segmentation import join_labels
from annotators.geometry.support import BORDER_REACH, PieceSummary, border_tallies, summarize_pieces


@dataclass(frozen=True)
class SlabRules:
    """Thresholds of :func:`join_slab_pieces`: the height noise (metres) within which two pieces' lowest heights
    (5 %) and tops (99 %) must agree (``tolerance``); the share of their shared border without a depth jump
    (``continuous``, depth jumps as the segmenter's: ``jump_absolute + jump_relative * nearer depth``) and its
    length, at least ``boundary_share`` times the square root of the smaller piece's size and ``min_boundary``
    pixel pairs (a joint :func:`~annotators.geometry.grid_segmentation.merge_parts` trusts); each piece's span on
    the table plane (:meth:`~annotators.geometry.support.PieceSummary.span`) at least ``flatness`` times its top
    height; heights sampled on every ``sample_step``-th pixel."""

    tolerance: float = 0.005
    continuous: float = 0.6
    boundary_share: float = 0.6
    min_boundary: int = 3
    jump_absolute: float = 0.01
    jump_relative: float = 0.01
    flatness: float = 1.0
    sample_step: int = 2


def slab_candidates(pieces: PieceSummary, labels: np.ndarray, rules: SlabRules) -> np.ndarray:
    """Kx2 touching label pairs whose lowest heights and tops agree within ``rules.tolerance``, whose shared
    border is long enough to carry a joint, and each of which lies flat (``rules.flatness``)."""
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] == 0:
        return pairs
    a, b = pairs[:, 0], pairs[:, 1]
    border = pieces.border if pieces.border is not None else np.full(pairs.shape[0], np.inf)
    smaller = np.minimum(pieces.sizes[a], pieces.sizes[b])
    with np.errstate(invalid="ignore"):
        level = (np.abs(pieces.low[a] - pieces.low[b]) <= rules.tolerance) & (
            np.abs(pieces.top[a] - pieces.top[b]) <= rules.tolerance
        )
    long_enough = border >= np.maximum(rules.min_boundary, rules.boundary_share * np.sqrt(smaller))
    pairs = pairs[level & long_enough]
    if pairs.shape[0] == 0:
        return pairs
    flat = {label: pieces.span(label) >= rules.flatness * pieces.top[label] for label in np.unique(pairs).tolist()}
    return pairs[[flat[a] and flat[b] for a, b in pairs.tolist()]]


def continuous_borders(
    labels: np.ndarray, points: np.ndarray, normals: np.ndarray, rules: SlabRules
) -> tuple[np.ndarray, np.ndarray]:
    """Per touching label pair (Kx2, a < b) of ``labels``: the number of its 4-neighbour pixel pairs without a
    depth jump, and their share of the border."""
    pairs, length, smooth, _ = border_tallies(labels, points, normals, rules.jump_absolute, rules.jump_relative, 0.0)
    if length.size == 0:
        return pairs, np.zeros(0)
    return pairs, np.column_stack([smooth, smooth / length])


def trusted_heights(
    pieces: PieceSummary, labels: np.ndarray, plane_points: np.ndarray, trusted: np.ndarray, sample_step: int
) -> PieceSummary:
    """``pieces`` (the summary of ``labels``) with each label's lowest heights and top read from its ``trusted``
    pixels (HxW bool) alone; a label without a sampled trusted pixel keeps those of all its pixels."""
    own = summarize_pieces(np.where(trusted, labels, 0), plane_points, sample_step)
    count = pieces.low.size
    low, top = np.full(count, np.nan), np.full(count, np.nan)
    low[: own.low.size], top[: own.top.size] = own.low[:count], own.top[:count]
    missing = np.isnan(low)
    return replace(pieces, low=np.where(missing, pieces.low, low), top=np.where(missing, pieces.top, top))


def slab_partners(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: SlabRules,
    pieces: PieceSummary | None = None,
    trusted: np.ndarray | None = None,
) -> list[tuple[int, int]]:
    """The touching label pairs of one slab (see the module docstring); ``points`` and ``normals`` HxWx3 in the
    camera frame, ``plane_points`` the pixels' ``(u, v, height)``, ``pieces`` their summary when already made,
    ``trusted`` (HxW bool, or None: all) the pixels whose heights count.
    Heights are checked first; the borders are measured only in the window around the pairs that pass."""
    pieces = pieces or summarize_pieces(labels, plane_points, rules.sample_step)
    if trusted is not None:
        pieces = trusted_heights(pieces, labels, plane_points, trusted, rules.sample_step)
    candidates = slab_candidates(pieces, labels, rules)
    if candidates.shape[0] == 0:
        return []
    boxes = pieces.boxes[candidates.reshape(-1)]
    margin = BORDER_REACH + 1
    x0, y0 = max(int(boxes[:, 0].min()) - margin, 0), max(int(boxes[:, 1].min()) - margin, 0)
    x1 = min(int(boxes[:, 2].max()) + margin, labels.shape[1])
    y1 = min(int(boxes[:, 3].max()) + margin, labels.shape[0])
    involved = np.zeros(pieces.sizes.size, dtype=bool)
    involved[candidates.reshape(-1)] = True
    window = labels[y0:y1, x0:x1]
    pairs, measures = continuous_borders(
        np.where(involved[window], window, 0), points[y0:y1, x0:x1], normals[y0:y1, x0:x1], rules
    )
    wanted = set(map(tuple, candidates.tolist()))
    joins = []
    for (a, b), (smooth, share) in zip(pairs.tolist(), measures.tolist(), strict=True):
        needed = max(rules.min_boundary, rules.boundary_share * np.sqrt(min(pieces.sizes[a], pieces.sizes[b])))
        if (a, b) in wanted and share >= rules.continuous and smooth >= needed:
            joins.append((a, b))
    return joins


def join_slab_pieces(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: SlabRules | None = None,
    pieces: PieceSummary | None = None,
    trusted: np.ndarray | None = None,
) -> np.ndarray:
    """Labels with the pieces of one slab joined: touching pieces whose lowest heights and tops (on their
    ``trusted`` pixels, HxW bool, when given) agree within the height noise and whose shared border has no depth
    jump along most of it (see :class:`SlabRules`); renumbered 1..n when anything joined (``pieces``: the labels'
    summary when already made, with the rules' sample step)."""
    joins = slab_partners(labels, points, normals, plane_points, rules or SlabRules(), pieces, trusted)
    return join_labels(labels, joins) if joins else labels
