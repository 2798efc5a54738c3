"""The inside of an open container seen over its rim, on the organized grid: it joins the container's outside.

Seen from above and in front, a mug shows the front of its outer wall and, over the rim, the back of its inner
wall. On the table the two are opposite halves of one ring: the outside's footprint is the front arc, the inside's
the back arc, so the outside's footprint holds little of the inside's and :func:`~annotators.geometry.support.
join_unsupported` leaves the inside alone - which by itself reads as some other object.

The inner wall tells itself apart by its shape: it is concave toward the camera. Its normals (oriented toward the
camera) point at the container's axis, which lies in front of the wall; the front of a solid object curves the other
way, its normals spreading away from an axis behind it. A piece that does not reach the table beside its neighbour
(its lowest heights above the neighbour's; it may be the larger of the two - a wide mug seen from above shows more
inside than outside - and may end high up, where the front rim hides the rest: so not the candidates of
:func:`~annotators.geometry.support.join_unsupported`, which must be smaller and reach down into their holder),
whose surface touches the neighbour's in 3-D along their shared border (the rim; an object hidden behind another is
parted from it by a depth jump), whose wall curves around an axis in front of it, whose axis lies within the
footprint of the two together - the container's floor - and whose neighbour's wall lies no nearer that axis - the
outside surrounds the inside; a can standing in a bowl is nearer the bowl's axis than the bowl's inner wall - is
that container's inside and joins it (:func:`join_inner_walls`). So does a concave piece beside another concave
piece curving around the same axis with the same radius: the inside, cut in two where it bends faster than the
convexity grouping's concave limit (:func:`one_wall`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import join_labels
from annotators.geometry.support import (
    FOOTPRINT_ROWS,
    AppendageRules,
    PieceSummary,
    SupportRules,
    close_borders,
    joint_hull,
    summarize_pieces,
)
from annotators.geometry.support_kernels import kept_labels
from annotators.geometry.support_kernels import pixel_footprint as footprint_angle


@dataclass(frozen=True)
class InnerWallRules:
    """Thresholds of :func:`join_inner_walls`: the height noise by which an inside's lowest heights must lie above
    its holder's and the sampling of heights and footprints (``support.tolerance``, ``support.sample_step``); the
    close border along which piece and holder must touch in 3-D (``boundary_share`` times the square root of the
    piece's size, at least ``min_boundary`` pixel pairs, depth jumps ``jump_absolute + jump_relative * nearer
    depth``); the wall points used (``wall_normal``: the least horizontal component of their unit normals); how much
    the wall's normals must turn (``min_turn``: the smaller eigenvalue of the mean of ``I - n n^T`` over its
    horizontal normals; a flat wall has 0 and no axis), how many must face the axis (``facing``: more than this
    share of the wall points have normals pointing toward it; the rim or a handle in the same piece does not) and how
    close the axes and radii of two concave pieces of one inner wall are (``same_axis``, a share of the radius)."""

    support: SupportRules = field(default_factory=SupportRules)
    boundary_share: float = 0.6
    min_boundary: int = 3
    jump_absolute: float = 0.01
    jump_relative: float = 0.01
    wall_normal: float = 0.5
    min_turn: float = 0.05
    facing: float = 0.5
    same_axis: float = 0.25


_MIN_WALL_POINTS = 10
"""A wall with fewer sampled points has no trustworthy axis."""


def wall_points(
    plane_points: np.ndarray, plane_normals: np.ndarray, rules: InnerWallRules
) -> tuple[np.ndarray, np.ndarray]:
    """The ``(u, v)`` positions and unit horizontal normals of the wall points among Nx3 ``(u, v, height)`` points
    and their normals: those whose normal's horizontal component is at least ``rules.wall_normal``."""
    horizontal = np.linalg.norm(plane_normals[:, :2], axis=1)
    wall = (horizontal >= rules.wall_normal) & np.isfinite(plane_points).all(axis=1)
    normals = plane_normals[wall, :2].astype(np.float64) / horizontal[wall, None]
    return plane_points[wall, :2].astype(np.float64), normals


def _wall_circle(
    points: np.ndarray, normals: np.ndarray, rules: InnerWallRules
) -> tuple[np.ndarray, float, float] | None:
    """For a wall (Nx2 ``points`` and unit ``normals`` of :func:`wall_points`): the least-squares meeting point of
    its normal lines, the share of its points whose normals point toward it and their median distance from it; None
    for a wall too small or too flat (its normals turn less than ``rules.min_turn``)."""
    if points.shape[0] < _MIN_WALL_POINTS:
        return None
    across = np.eye(2)[None] - normals[:, :, None] * normals[:, None, :]  # projections across each normal line
    matrix = across.sum(axis=0)
    if np.linalg.eigvalsh(matrix / points.shape[0])[0] < rules.min_turn:
        return None
    axis = np.linalg.solve(matrix, np.einsum("nij,nj->i", across, points))
    facing = float(np.mean(np.einsum("ni,ni->n", axis - points, normals) > 0))
    return axis, facing, float(np.median(np.linalg.norm(axis - points, axis=1)))


def wall_axis(points: np.ndarray, normals: np.ndarray, rules: InnerWallRules) -> tuple[np.ndarray, float] | None:
    """The ``(u, v)`` point that a wall's horizontal normals (Nx2 ``points`` and unit ``normals`` of
    :func:`wall_points`, normals toward the camera) point at, and the wall's median distance from it, when the wall
    curves around it concavely toward the camera: the least-squares meeting point of the normal lines, in front of
    most of the wall (see :class:`InnerWallRules`); None for a flat, convex or too small wall."""
    found = _wall_circle(points, normals, rules)
    if found is None or found[1] <= rules.facing:
        return None
    return found[0], found[2]


def outer_wall_circle(
    points: np.ndarray, normals: np.ndarray, rules: InnerWallRules
) -> tuple[np.ndarray, float] | None:
    """The ``(u, v)`` axis a wall's horizontal normals point away from, and the wall's median distance from it, when
    the wall curves around it convexly (the outside of a round body: the meeting point of :func:`wall_axis`, behind
    most of the wall); None for a flat, concave or too small wall."""
    found = _wall_circle(points, normals, rules)
    if found is None or 1.0 - found[1] <= rules.facing:
        return None
    return found[0], found[2]


def within_outer_wall(
    inner: np.ndarray, outside: np.ndarray, outside_normals: np.ndarray, floor: np.ndarray, rules: InnerWallRules
) -> bool:
    """Does a round outer wall (Nx2 ``outside`` points and unit normals, :func:`wall_points`) hold the inner wall's
    Mx2 points ``inner``: it curves convexly around an axis (:func:`outer_wall_circle`) inside the Kx1x2 float32
    ``floor`` polygon and the inner wall lies within its circle (their median distance from that axis no more than
    its radius)? Fitted on the back arc of a small inside, the inner wall's own axis may lie a centimetre off, so
    far that the outer wall's front arc comes nearer it than the inside; the outer wall's front arc, wider, places
    the common axis better. An object standing in a bowl does not hold the bowl's inside within its own circle."""
    circle = outer_wall_circle(outside, outside_normals, rules)
    if circle is None or inner.shape[0] == 0:
        return False
    axis, radius = circle
    if cv2.pointPolygonTest(floor, (float(axis[0]), float(axis[1])), False) <= 0:
        return False
    return bool(np.median(np.linalg.norm(inner - axis, axis=1)) <= radius)


def one_wall(first: tuple[np.ndarray, float], second: tuple[np.ndarray, float] | None, share: float) -> bool:
    """Are two concave walls (``wall_axis`` results) pieces of one round inner wall: their axes within ``share`` of
    the first's radius of each other, and their radii within that too? The inside of a bowl seen over its rim is
    cut where it bends faster than the concave limit; each piece curves around the same axis."""
    if second is None:
        return False
    (axis, radius), (other_axis, other_radius) = first, second
    return bool(np.linalg.norm(other_axis - axis) <= share * radius and abs(other_radius - radius) <= share * radius)


def inside_candidates(pairs: np.ndarray, low: np.ndarray, tolerance: float) -> np.ndarray:
    """Mx2 ``(piece, holder)`` of the touching ``pairs`` (Kx2), each way round (all pairs as given, then all
    reversed), whose piece's 5 % height ``low`` lies above the holder's by more than ``tolerance``: it does not
    reach the table beside the holder. Unlike a piece resting on another, an inside seen over the rim may be the
    larger of the two (a wide mug from above) and may end high up (where the front rim hides the rest)."""
    both = np.concatenate([pairs, pairs[:, ::-1]])
    return both[low[both[:, 0]] > low[both[:, 1]] + tolerance]


def bordering_long_enough(
    candidates: np.ndarray, pairs: np.ndarray, pieces: PieceSummary, rules: InnerWallRules
) -> np.ndarray:
    """M bool: which ``(piece, holder)`` candidates (Mx2) share a border of at least as many 4-neighbour pixel pairs
    (``pieces.border`` of the touching ``pairs``, Kx2 in increasing order) as the close border
    :func:`inner_wall_holders` asks of the piece: a close border is part of the shared one, so the others cannot
    qualify and are left out before their walls are measured."""
    base = pieces.sizes.size
    keys = pairs[:, 0] * base + pairs[:, 1]
    low, high = np.minimum(candidates[:, 0], candidates[:, 1]), np.maximum(candidates[:, 0], candidates[:, 1])
    border = pieces.border[np.searchsorted(keys, low * base + high)]
    needed = np.maximum(rules.min_boundary, rules.boundary_share * np.sqrt(pieces.sizes[candidates[:, 0]]))
    return border >= needed


def inner_wall_holders(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    to_plane: np.ndarray,
    rules: InnerWallRules,
    pieces: PieceSummary | None = None,
) -> list[tuple[int, int]]:
    """``(piece, holder)`` pairs of :func:`join_inner_walls`: each piece that is the inside of the neighbour it
    touches along the longest close border among those that qualify (``to_plane``: the 3x3 rotation taking camera
    directions to ``(u, v, height)``; ``pieces``: the labels' summary when already made)."""
    support = rules.support
    pieces = pieces or summarize_pieces(labels, plane_points, support.sample_step)
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] == 0:
        return []
    candidates = inside_candidates(pairs, pieces.low, support.tolerance)
    if pieces.border is not None:
        candidates = candidates[bordering_long_enough(candidates, pairs, pieces, rules)]
    if candidates.shape[0] == 0:
        return []
    grid_plane = plane_points.reshape(*labels.shape, 3)

    step = max(1, support.sample_step)

    measured: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def walls(label: int) -> tuple[np.ndarray, np.ndarray]:
        """The wall points of a label, on every ``step``-th pixel of its box (measured once per label)."""
        if label not in measured:
            bx0, by0, bx1, by1 = pieces.boxes[label]
            window = (slice(by0, by1, step), slice(bx0, bx1, step))
            inside = labels[window] == label
            measured[label] = wall_points(grid_plane[window][inside], normals[window][inside] @ to_plane, rules)
        return measured[label]

    # the shape first (cheap, and few pieces are concave), the borders in 3-D only for the pairs it leaves
    axes: dict[int, tuple[np.ndarray, float] | None] = {}
    shaped: list[tuple[int, int]] = []
    for piece, holder in candidates.tolist():
        if piece not in axes:
            axes[piece] = wall_axis(*walls(piece), rules)
        found = axes[piece]
        if found is None:
            continue
        axis, radius = found
        floor = joint_hull(pieces, piece, holder).reshape(-1, 1, 2).astype(np.float32)
        if floor.shape[0] < 3 or cv2.pointPolygonTest(floor, (float(axis[0]), float(axis[1])), False) <= 0:
            continue
        outside, outside_normals = walls(holder)  # the outer wall surrounds the inner one: no nearer the axis
        if outside.shape[0] >= _MIN_WALL_POINTS and np.median(np.linalg.norm(outside - axis, axis=1)) >= radius:
            shaped.append((piece, holder))
            continue
        if within_outer_wall(walls(piece)[0], outside, outside_normals, floor, rules):
            shaped.append((piece, holder))
            continue
        if holder not in axes:
            axes[holder] = wall_axis(outside, outside_normals, rules)
        if one_wall((axis, radius), axes[holder], rules.same_axis):  # the holder is the rest of the inner wall
            shaped.append((piece, holder))
    if not shaped:
        return []
    involved = np.zeros(pieces.sizes.size, dtype=bool)
    involved[np.array(shaped).reshape(-1)] = True
    boxes = pieces.boxes[involved]
    x0, y0 = max(int(boxes[:, 0].min()) - 3, 0), max(int(boxes[:, 1].min()) - 3, 0)
    x1, y1 = min(int(boxes[:, 2].max()) + 3, labels.shape[1]), min(int(boxes[:, 3].max()) + 3, labels.shape[0])
    touch_rules = AppendageRules(jump_absolute=rules.jump_absolute, jump_relative=rules.jump_relative)
    border_pairs, close_shares, lengths = close_borders(
        kept_labels(labels[y0:y1, x0:x1], involved),
        points[y0:y1, x0:x1],
        normals[y0:y1, x0:x1],
        touch_rules,
        footprint_angle(np.ascontiguousarray(points[::FOOTPRINT_ROWS], dtype=np.float32)),
    )
    along = {
        (a, b): close * length
        for (a, b), close, length in zip(border_pairs.tolist(), close_shares, lengths, strict=True)
    }
    best: dict[int, tuple[float, int]] = {}
    for piece, holder in shaped:
        touching = along.get((min(piece, holder), max(piece, holder)), 0.0)
        needed = max(rules.min_boundary, rules.boundary_share * np.sqrt(pieces.sizes[piece]))
        if touching >= needed and touching > best.get(piece, (-1.0, 0))[0]:
            best[piece] = (touching, holder)
    return [(piece, holder) for piece, (_, holder) in best.items()]


def join_inner_walls(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    to_plane: np.ndarray,
    rules: InnerWallRules | None = None,
    pieces: PieceSummary | None = None,
) -> np.ndarray:
    """Labels with the inside of every open container seen over its rim joined to the container's outside (see
    the module docstring; ``points`` and ``normals`` HxWx3 in the camera frame, normals toward the camera,
    ``plane_points`` the pixels' ``(u, v, height)``, ``to_plane`` the 3x3 rotation from camera directions to
    ``(u, v, height)``; ``pieces`` the labels' summary when already made, with the rules' sample step); the same
    array when nothing joined.

    Rounds repeat while anything joins: each piece joins one holder per round (the one it shares the longest close
    border with), so an inside cut in two may join its other half first and, as one piece, the outside in the next
    round."""
    rules = rules or InnerWallRules()
    joined = labels
    while joins := inner_wall_holders(joined, points, normals, plane_points, to_plane, rules, pieces):
        joined, pieces = join_labels(joined, joins), None
    return joined
