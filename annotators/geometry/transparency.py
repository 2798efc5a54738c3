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

from annotators.geometry.grid_segmentation import chroma_image, join_labels


@dataclass(frozen=True)
class TransparencyRules:
    """Thresholds of :func:`join_see_through`: pieces touch when their pixels come within ``reach`` grid pixels
    of each other (a depth seam between them is unlabelled). Their mean :func:`chroma_image` vectors must lie within
    ``hue_distance`` of each other, and each must be at least ``min_chroma`` from grey (a tint: shadows and white,
    grey or black surfaces have no hue to follow). The pixels without depth inside the group's convex hull whose
    chroma lies within ``hue_distance`` of the group's must number at least ``hole_share`` of the group's pixels."""

    reach: int = 2
    hue_distance: float = 30.0
    min_chroma: float = 50.0
    hole_share: float = 0.1


def label_chroma(labels: np.ndarray, chroma: np.ndarray) -> np.ndarray:
    """(n + 1)x2 mean chroma of each label 0..n (label 0 and empty labels: 0)."""
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
    kept = np.where(tinted[labels], labels, 0)
    rows, cols = kept.shape
    found: set[tuple[int, int]] = set()
    for dy in range(0, rules.reach + 1):
        for dx in range(-rules.reach, rules.reach + 1):
            if dy == 0 and dx <= 0:
                continue
            a = kept[: rows - dy, max(0, -dx) : cols - max(0, dx)]
            b = kept[dy:, max(0, dx) : cols - max(0, -dx)]
            touching = (a > 0) & (b > 0) & (a != b)
            if touching.any():
                pairs = np.unique(np.sort(np.column_stack([a[touching], b[touching]]), axis=1), axis=0)
                found.update(map(tuple, pairs.tolist()))
    return [(a, b) for a, b in sorted(found) if float(np.hypot(*(tints[a] - tints[b]))) <= rules.hue_distance]


def hole_share(
    labels: np.ndarray, group: list[int], valid: np.ndarray, chroma: np.ndarray, rules: TransparencyRules
) -> float:
    """The unlabelled pixels without depth inside the convex hull of ``group``'s pixels whose chroma lies within
    ``rules.hue_distance`` of the group's mean, as a share of the group's pixels."""
    members = np.isin(labels, group)
    ys, xs = np.nonzero(members)
    hull = np.zeros(labels.shape, dtype=np.uint8)
    cv2.fillConvexPoly(hull, cv2.convexHull(np.column_stack([xs, ys]).astype(np.int32)), 1)
    tint = chroma[members].mean(axis=0)
    holes = (hull > 0) & ~valid & (labels == 0)
    distance = np.hypot(*(chroma[holes] - tint).T)
    return float(np.count_nonzero(distance <= rules.hue_distance)) / float(ys.size)


def see_through_groups(
    labels: np.ndarray, valid: np.ndarray, colors: np.ndarray, rules: TransparencyRules | None = None
) -> list[list[int]]:
    """The groups of labels (two or more) that are one tinted transparent object (see the module docstring);
    ``valid`` marks the grid pixels with a depth reading, ``colors`` the grid's RGB (uint8)."""
    rules = rules or TransparencyRules()
    if labels.max(initial=0) < 2:
        return []
    chroma = chroma_image(np.ascontiguousarray(colors)).astype(np.float32) - 128.0
    tints = label_chroma(labels, chroma)
    pairs = tinted_neighbours(labels, tints, rules)
    if not pairs:
        return []
    # each label's group (a 1 x (n + 1) row of the labels 0..n, joined; 0 stays 0)
    grouped = join_labels(np.arange(int(labels.max()) + 1, dtype=np.int32)[None, :], pairs)[0]
    groups: dict[int, list[int]] = {}
    for label in np.unique(np.asarray(pairs)).tolist():
        groups.setdefault(int(grouped[label]), []).append(label)
    return [group for group in groups.values() if hole_share(labels, group, valid, chroma, rules) >= rules.hole_share]


def join_see_through(
    labels: np.ndarray, valid: np.ndarray, colors: np.ndarray, rules: TransparencyRules | None = None
) -> np.ndarray:
    """Labels with the pieces of each tinted transparent object joined (:func:`see_through_groups`), renumbered
    1..n when anything joined."""
    groups = see_through_groups(labels, valid, colors, rules)
    pairs = [(group[0], other) for group in groups for other in group[1:]]
    return join_labels(labels, pairs) if pairs else labels
