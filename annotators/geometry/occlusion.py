"""Occlusion completion on the organized grid: the pieces of one object that a nearer object cuts apart.

A box lying across another splits the view of the lower one into two disjoint pieces. They are one object when
(the Gestalt rule of good continuation behind an occluder):

* both border a common occluder across depth jumps, on the far side of the jump;
* they do not touch each other;
* near the occluder each piece is flat, and the two surfaces continue one another: their normals agree and the
  line between them lies in both planes (within ``rules.degrees``);
* the straight image line between them runs mostly through the occluder (they face each other across it), and
  the occluder is nearer there than the surface joining them would be.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import depth_jump, join_labels


@dataclass(frozen=True)
class OcclusionRules:
    """Thresholds of :func:`join_occluded` (pixels, shares, degrees)."""

    band: int = 6
    occluded_share: float = 0.5
    degrees: float = 20.0
    flatness: float = 0.05
    through_occluder: float = 0.5
    min_points: int = 20


def occluded_pairs(
    labels: np.ndarray, depth: np.ndarray, absolute: float, relative: float, share: float
) -> set[tuple[int, int]]:
    """``(far, near)`` label pairs that touch as 4-neighbours, across depth jumps on at least ``share`` of their
    shared boundary, with ``near`` in front."""
    base = int(labels.max(initial=0)) + 1
    keys, jumps = [], []
    for first, second, z_first, z_second in (
        (labels[:, :-1], labels[:, 1:], depth[:, :-1], depth[:, 1:]),
        (labels[:-1, :], labels[1:, :], depth[:-1, :], depth[1:, :]),
    ):
        touching = (first != second) & (first > 0) & (second > 0)
        a, b = first[touching].astype(np.int64), second[touching].astype(np.int64)
        za, zb = z_first[touching], z_second[touching]
        a_farther = za > zb
        keys.append(np.where(a_farther, a * base + b, b * base + a))
        jumps.append(depth_jump(za, zb, absolute, relative))
    key = np.concatenate(keys)
    if key.size == 0:
        return set()
    unique, inverse = np.unique(key, return_inverse=True)
    total = np.bincount(inverse, minlength=unique.size)
    jumped = np.bincount(inverse, weights=np.concatenate(jumps), minlength=unique.size)
    found = unique[jumped >= share * total]
    return set(zip((found // base).tolist(), (found % base).tolist(), strict=True))


def join_occluded(
    labels: np.ndarray,
    faces: np.ndarray,
    points: np.ndarray,
    absolute: float,
    relative: float,
    rules: OcclusionRules,
) -> np.ndarray:
    """Labels with the pieces of occluded objects joined (see the module docstring), renumbered 1..n.

    ``faces`` labels the smooth surfaces the pieces are made of; the surfaces of two pieces that border the
    occluder are compared face by face (near the occluder), so a piece showing a box's top and side continues
    the other piece's top.
    """
    depth = points[..., 2]
    behind = occluded_pairs(labels, depth, absolute, relative, rules.occluded_share)
    hidden_by: dict[int, list[int]] = {}
    for far, near in behind:
        hidden_by.setdefault(near, []).append(far)
    touching = _touching(labels)
    kernel = np.ones((2 * rules.band + 1, 2 * rules.band + 1), np.uint8)
    joined: list[tuple[int, int]] = []
    for occluder, pieces in hidden_by.items():
        if len(pieces) < 2:
            continue
        near_occluder = cv2.dilate((labels == occluder).view(np.uint8), kernel) > 0
        planes = {piece: _face_planes(points, faces, near_occluder & (labels == piece), rules) for piece in pieces}
        for index, first in enumerate(pieces):
            for second in pieces[index + 1 :]:
                if (min(first, second), max(first, second)) in touching:
                    continue
                if any(
                    _continues(a, b, rules.degrees)
                    and _across(labels, points, occluder, first, second, a.band, b.band, a.centre, b.centre)
                    >= rules.through_occluder
                    for a in planes[first]
                    for b in planes[second]
                ):
                    joined.append((first, second))
    return join_labels(labels, joined) if joined else labels


@dataclass(frozen=True, eq=False)
class _BandPlane:
    """A flat face of a piece near the occluder: its pixels there, their centroid and unit normal."""

    band: np.ndarray
    centre: np.ndarray
    normal: np.ndarray


def _face_planes(points: np.ndarray, faces: np.ndarray, band: np.ndarray, rules: OcclusionRules) -> list[_BandPlane]:
    """The flat faces (flatness <= ``rules.flatness``) with at least ``rules.min_points`` pixels in ``band``."""
    found = []
    for face in np.unique(faces[band]).tolist():
        if face == 0:
            continue
        own = band & (faces == face)
        xyz = points[own]
        xyz = xyz[np.isfinite(xyz).all(axis=1)].astype(np.float64)
        if xyz.shape[0] < rules.min_points:
            continue
        centre = xyz.mean(axis=0)
        values, vectors = np.linalg.eigh(np.cov((xyz - centre).T))
        if values[0] / max(values.sum(), 1e-12) > rules.flatness:
            continue
        normal = vectors[:, 0] * (-1.0 if vectors[:, 0] @ centre > 0 else 1.0)
        found.append(_BandPlane(own, centre, normal))
    return found


def _continues(first: _BandPlane, second: _BandPlane, degrees: float) -> bool:
    """Do the two faces continue one surface: normals within ``degrees``, the line between their centroids within
    ``degrees`` of both planes?"""
    offset = second.centre - first.centre
    direction = offset / max(float(np.linalg.norm(offset)), 1e-9)
    sine = np.sin(np.radians(degrees))
    return bool(
        first.normal @ second.normal >= np.cos(np.radians(degrees))
        and abs(direction @ first.normal) <= sine
        and abs(direction @ second.normal) <= sine
    )


def _touching(labels: np.ndarray) -> set[tuple[int, int]]:
    found = set()
    for first, second in ((labels[:, :-1], labels[:, 1:]), (labels[:-1, :], labels[1:, :])):
        touching = (first != second) & (first > 0) & (second > 0)
        a, b = first[touching], second[touching]
        found.update(zip(np.minimum(a, b).tolist(), np.maximum(a, b).tolist(), strict=True))
    return found


def _across(
    labels: np.ndarray,
    points: np.ndarray,
    occluder: int,
    first: int,
    second: int,
    first_band: np.ndarray,
    second_band: np.ndarray,
    start: np.ndarray,
    end: np.ndarray,
) -> float:
    """The share of the image line between the two bands (their pixel centroids), outside the two pieces, that the
    occluder covers in front of the straight 3-D line from ``start`` to ``end`` (the hidden surface)."""
    (r0, c0), (r1, c1) = (np.argwhere(band).mean(axis=0) for band in (first_band, second_band))
    steps = int(max(abs(r1 - r0), abs(c1 - c0))) + 1
    t = np.linspace(0.0, 1.0, steps)
    rows = np.round(r0 + t * (r1 - r0)).astype(int)
    cols = np.round(c0 + t * (c1 - c0)).astype(int)
    hidden_depth = start[2] + t * (end[2] - start[2])
    on_line = labels[rows, cols]
    with np.errstate(invalid="ignore"):
        covered = (on_line == occluder) & (points[rows, cols, 2] < hidden_depth)
    between = (on_line != first) & (on_line != second)
    return float(np.count_nonzero(covered) / max(np.count_nonzero(between), 1))
