"""A tinted transparent object, on the organized grid: its pieces join where the depth camera sees through it.

A clear plastic or glass body passes the depth camera's projected pattern. What is measured inside its outline is
partly its front surface, partly the liquid or its back wall, partly the table behind it, and in many places
nothing at all. The convexity grouping then cuts it at depth jumps of several centimetres into pieces that look
like objects standing behind one another. The colour, though, stays the object's own tint across all of it.

Two cues hold for a tinted transparent object in general and for no opaque one:

* its pieces touch in the image and share one clearly saturated hue (the tint);
* inside the image outline (convex hull) of those pieces, a share of the pixels of that same hue has no depth
  reading at all (``hole_share``). An opaque surface within the camera's range returns depth almost everywhere
  inside its outline. Its holes lie along its edges (the projector's shadow), and the pixels there show the
  background's colour, not the object's.

Pieces that pass both cues join (:func:`join_see_through`). Identical opaque boxes stacked on one another share a
hue but leave no holes of it, so they stay apart. A blue can standing behind a blue box shares the hue, but the
holes inside their joint outline, if any, show the table between them. Known limits: a colourless object (clear
glass, water in a clear bottle) has no tint to follow and is not found here. A tinted transparent object touching
an opaque one of the same hue in the image would join it.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.ndimage import find_objects

from annotators.geometry.grid_kernels import graph_components, near_label_pairs
from annotators.geometry.grid_segmentation import join_labels


@dataclass(frozen=True)
class TransparencyRules:
    """Thresholds of :func:`join_see_through`: pieces touch when their pixels come within ``reach`` grid pixels
    of each other (a depth seam between them is unlabelled). Their mean
    :func:`~annotators.geometry.grid_segmentation.chroma_image` vectors must lie within ``hue_distance`` of each
    other, and each must be at least ``min_chroma`` from grey (a tint: shadows and white, grey or black surfaces
    have no hue to follow). The pixels without depth inside the group's convex hull whose
    chroma lies within ``hue_distance`` of the group's must number at least ``hole_share`` of the group's pixels."""

    reach: int = 2
    hue_distance: float = 30.0
    min_chroma: float = 50.0
    hole_share: float = 0.1


def label_chroma(labels: np.ndarray, chroma: np.ndarray) -> np.ndarray:
    """(n + 1)x2 mean chroma of each label 0..n (row 0: the unlabelled pixels'; an empty label's: 0)."""
    count = int(labels.max()) + 1
    flat = labels.reshape(-1)
    sizes = np.maximum(np.bincount(flat, minlength=count), 1)
    return np.column_stack(
        [np.bincount(flat, weights=chroma[..., axis].reshape(-1), minlength=count) / sizes for axis in (0, 1)]
    )


def tinted_neighbours(labels: np.ndarray, tints: np.ndarray, rules: TransparencyRules) -> list[tuple[int, int]]:
    """The label pairs whose pixels come within ``rules.reach`` grid pixels and whose tints agree (both at least
    ``rules.min_chroma`` from grey, within ``rules.hue_distance`` of each other)."""
    tinted = np.hypot(tints[:, 0], tints[:, 1]) >= rules.min_chroma
    tinted[0] = False
    if np.count_nonzero(tinted) < 2:
        return []
    pairs = near_label_pairs(np.where(tinted[labels], labels, 0), rules.reach)
    return [
        (int(a), int(b)) for a, b in pairs.tolist() if float(np.hypot(*(tints[a] - tints[b]))) <= rules.hue_distance
    ]


def tint_groups(pairs: list[tuple[int, int]], count: int) -> list[list[int]]:
    """The connected groups of labels (below ``count``) the ``pairs`` link, each sorted, in order of smallest label."""
    components = graph_components(np.asarray(pairs, dtype=np.int64), count)
    linked = np.unique(np.asarray(pairs, dtype=np.int64))
    groups: dict[int, list[int]] = {}
    for label in linked.tolist():
        groups.setdefault(int(components[label]), []).append(label)
    return list(groups.values())


def hole_share(
    labels: np.ndarray,
    group: list[int],
    holes: np.ndarray,
    chroma: np.ndarray,
    rules: TransparencyRules,
    box: tuple[slice, slice] | None = None,
) -> float:
    """The ``holes`` (unlabelled pixels without depth) inside the convex hull of ``group``'s pixels whose chroma
    lies within ``rules.hue_distance`` of the group's mean, as a share of the group's pixels; ``box`` (row and
    column slices) holds the group's pixels when known."""
    rows, cols = box or (slice(0, labels.shape[0]), slice(0, labels.shape[1]))
    members = np.isin(labels[rows, cols], group)
    ys, xs = np.nonzero(members)
    hull = np.zeros(members.shape, dtype=np.uint8)
    cv2.fillConvexPoly(hull, cv2.convexHull(np.column_stack([xs, ys]).astype(np.int32)), 1)
    window = chroma[rows, cols]
    inside = (hull > 0) & holes[rows, cols]
    distance = np.hypot(*(window[inside] - window[members].mean(axis=0)).T)
    return float(np.count_nonzero(distance <= rules.hue_distance)) / float(ys.size)


def group_box(boxes: list[tuple[slice, slice] | None], group: list[int]) -> tuple[slice, slice]:
    """The row and column slices holding every label of ``group`` (``boxes[label - 1]``: each label's box)."""
    parts = [boxes[label - 1] for label in group if boxes[label - 1] is not None]
    return (
        slice(min(part[0].start for part in parts), max(part[0].stop for part in parts)),
        slice(min(part[1].start for part in parts), max(part[1].stop for part in parts)),
    )


def see_through_groups(
    labels: np.ndarray, valid: np.ndarray, chroma: np.ndarray, rules: TransparencyRules | None = None
) -> list[list[int]]:
    """The groups of labels (two or more) that are one tinted transparent object (see the module docstring);
    ``valid`` marks the grid pixels with a depth reading, ``chroma`` is the
    :func:`~annotators.geometry.grid_segmentation.chroma_image` of the grid's colours."""
    rules = rules or TransparencyRules()
    if labels.max(initial=0) < 2:
        return []
    chroma = chroma.astype(np.float32) - 128.0
    tints = label_chroma(labels, chroma)
    pairs = tinted_neighbours(labels, tints, rules)
    if not pairs:
        return []
    holes = ~valid & (labels == 0)
    sizes = np.bincount(labels.reshape(-1), minlength=tints.shape[0])
    boxes = find_objects(labels)
    found = []
    for group in tint_groups(pairs, tints.shape[0]):
        box = group_box(boxes, group)
        # a group with too few holes in its whole box cannot have enough of its tint inside its hull
        if np.count_nonzero(holes[box]) < rules.hole_share * sizes[group].sum():
            continue
        if hole_share(labels, group, holes, chroma, rules, box) >= rules.hole_share:
            found.append(group)
    return found


def join_see_through(
    labels: np.ndarray, valid: np.ndarray, chroma: np.ndarray, rules: TransparencyRules | None = None
) -> np.ndarray:
    """Labels with the pieces of each tinted transparent object joined (:func:`see_through_groups`; ``chroma`` the
    :func:`~annotators.geometry.grid_segmentation.chroma_image` of the grid's colours), renumbered 1..n when
    anything joined."""
    groups = see_through_groups(labels, valid, chroma, rules)
    pairs = [(group[0], other) for group in groups for other in group[1:]]
    return join_labels(labels, pairs) if pairs else labels
