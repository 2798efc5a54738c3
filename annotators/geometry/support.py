"""Pieces that are no object by themselves, on the organized grid: they join the object they belong to.

Every object rests on something: the support plane, or another object it stands on. A piece of a segmentation
that does neither is part of an object it touches. Such a piece is smaller than that neighbour, much of its
footprint lies within the neighbour's (its points over the area the neighbour's convex hull covers on the plane),
its lowest heights are above the neighbour's - it does not reach the table beside the neighbour - and they reach
down into the lower part of the neighbour's heights, so it cannot rest on the neighbour's top either. The inside
of a mug or bowl seen over its rim together with the rim and the handle's top is such a piece: the convexity
grouping cuts it from the outside along the concave fold of the inner wall. Two solid objects standing side by
side have footprints apart, an object standing on another starts at the other's top, and a can standing in a bowl
is larger than the piece of the bowl's outside it touches, and rises above the rim of the whole bowl near its
centre - it rests on the bowl's floor; none of them is joined (:func:`join_unsupported`).

The grouping can also cut a container in three: the inside seen over the rim, the outside's front, and its side
with the handle, the side reaching the table too. The inside then lies half over each outside piece: neither holds
it, their two footprints together do. Such a piece joins both when the three surfaces touch one another in 3-D
along their shared borders - one continuous object, not two standing side by side, which a depth jump parts where
one hides the other (:func:`join_jointly_held`).

A small piece can also stick out of a larger one: a drill's chuck leaves the body's front face at a concave fold,
where the convexity grouping cuts it off. A piece at most a quarter of a neighbour's size whose surface touches the
neighbour's in 3-D along most of their shared border, and whose heights lie within the neighbour's, joins it
(:func:`join_appendages`). An object standing beside another touches it along a line at most; along the rest of
their shared border in the image one hides the other behind a depth jump.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_kernels import boundary_pairs
from annotators.geometry.grid_segmentation import (
    bounding_box,
    distinct_keys,
    join_labels,
    pixel_footprint,
    touching_pairs,
)
from annotators.geometry.rims import RimRules, stands_inside
from annotators.geometry.support_kernels import (
    appendage_candidates,
    box_label_points,
    hull_candidates,
    kept_labels,
    piece_summary,
    principal_span,
    raster_vertices,
    unsupported_candidates,
)
from annotators.geometry.support_kernels import pixel_footprint as footprint_angle


@dataclass(frozen=True)
class SupportRules:
    """Thresholds of :func:`join_unsupported`: the share of a piece's footprint that must lie within its holder's
    hull (``held_share``: most of it; a handle beside the body may take up the rest), the height noise (metres) by
    which its lowest heights must exceed the holder's (``tolerance``), the share of the holder's heights (from its
    5 % to its 95 % height) its lowest heights must lie below (``reach_down``), the raster cell of the footprints
    (metres) and
    the spacing of the grid pixels sampled for heights and footprints (``sample_step``); with ``standing_inside``
    a piece that stands inside a holder that is an open container (:func:`~annotators.geometry.rims.stands_inside`)
    is never held, alone or jointly (:func:`jointly_held`): it rests on the container's floor."""

    held_share: float = 0.5
    tolerance: float = 0.003
    reach_down: float = 0.5
    cell: float = 0.005
    sample_step: int = 2
    standing_inside: bool = True


_FEW_FEET = 16
"""Feet of a piece are handed to the convex hull as they are up to this many; more are thinned to those that can
be corners first."""


@dataclass(frozen=True)
class PieceSummary:
    """Per label (index 0 unused) of a labelling: its ``sizes`` in grid pixels, its 5 %, 95 % and 99 % heights
    above the plane (``low``, ``high``, ``top``; NaN without a sampled point) and its sampled ``feet`` (Nx2 plane
    coordinates grouped by label: label k owns ``feet[starts[k]:starts[k + 1]]``), its pixel ``boxes``
    (``(x0, y0, x1, y1)``, exclusive; zeros for label 0 and absent labels) and the ``touching`` label pairs
    (:func:`~annotators.geometry.grid_segmentation.touching_pairs`) with the number of 4-neighbour pixel pairs
    along each one's shared ``border`` (both None when not found with the summary)."""

    sizes: np.ndarray
    low: np.ndarray
    high: np.ndarray
    top: np.ndarray
    feet: np.ndarray
    starts: np.ndarray
    boxes: np.ndarray
    touching: np.ndarray | None
    border: np.ndarray | None

    def touching_pairs(self, labels: np.ndarray) -> np.ndarray:
        """The touching label pairs of ``labels`` (the labelling summarized), found now unless known."""
        return self.touching if self.touching is not None else touching_pairs(labels)

    def span(self, label: int) -> float:
        """The extent (metres) of the label's sampled feet along their principal axis (:func:`span`)."""
        return span(self.feet[self.starts[label] : self.starts[label + 1]])

    def hull(self, label: int) -> np.ndarray:
        """The convex hull (Kx2) of the label's sampled feet."""
        feet = self.feet[self.starts[label] : self.starts[label + 1]]
        if feet.shape[0] < 3:
            return feet
        return cv2.convexHull(hull_candidates(feet) if feet.shape[0] >= _FEW_FEET else feet).reshape(-1, 2)


def span(feet: np.ndarray, share: float = 0.05) -> float:
    """The extent (metres) of Nx2 plane coordinates along their principal axis, from their ``share`` to their
    ``1 - share`` quantile there (a few stray readings at a depth edge do not stretch it); one compiled pass."""
    return principal_span(feet, share)


def span_numpy(feet: np.ndarray, share: float = 0.05) -> float:
    """:func:`span` in NumPy (SVD, quantiles): the reference form its compiled pass is tested against."""
    if feet.shape[0] < 2:
        return 0.0
    centred = feet - feet.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    low, high = np.quantile(centred @ axes[0], [share, 1.0 - share])
    return float(high - low)


def summarize_pieces(labels: np.ndarray, plane_points: np.ndarray, sample_step: int) -> PieceSummary:
    """The :class:`PieceSummary` of ``labels`` from the ``(u, v, height)`` plane coordinates of its pixels
    (``plane_points``, HxWx3 or (H*W)x3), heights read on every ``sample_step``-th pixel, in one compiled pass."""
    return PieceSummary(*piece_summary(labels, plane_points.reshape(*labels.shape, 3), sample_step))


def summarize_pieces_numpy(labels: np.ndarray, plane_points: np.ndarray, sample_step: int) -> PieceSummary:
    """:func:`summarize_pieces` in whole-array numpy with one sort (feet ordered by height within a label): the
    reference form its compiled pass is tested against."""
    count = int(labels.max(initial=0)) + 1
    sizes = np.bincount(labels.reshape(-1), minlength=count)
    step = max(1, sample_step)
    sampled = labels[::step, ::step]
    grid = plane_points.reshape(*labels.shape, 3)[::step, ::step]
    where = (sampled > 0) & np.isfinite(grid[..., 2])
    chosen = grid[where]
    # one sort by label, then height: heights (metres, within +-0.49 of the plane) as the fraction of the key
    keys = sampled[where] + (np.clip(chosen[:, 2], -0.49, 0.49) + 0.5)
    order = np.argsort(keys)
    ordered = keys[order]
    starts = np.searchsorted(ordered, np.arange(count + 1, dtype=np.float64))
    counts = np.diff(starts)
    quantiles = []
    for share in (0.05, 0.95, 0.99):
        index = np.minimum(starts[:-1] + np.round(share * np.maximum(counts - 1, 0)).astype(np.intp), ordered.size - 1)
        values = ordered[np.maximum(index, 0)] - np.arange(count) - 0.5 if ordered.size else np.zeros(count)
        quantiles.append(np.where(counts > 0, values, np.nan))
    feet = np.ascontiguousarray(chosen[order, :2], dtype=np.float32)
    boxes = np.zeros((count, 4), dtype=np.int64)
    for label in np.flatnonzero(sizes[1:]) + 1:
        x0, y0, x1, y1 = bounding_box(labels == label)
        boxes[label] = x0, y0, x1, y1
    touching = touching_pairs(labels)
    key = np.minimum(labels[:, 1:], labels[:, :-1]) * count + np.maximum(labels[:, 1:], labels[:, :-1])
    down = np.minimum(labels[1:], labels[:-1]) * count + np.maximum(labels[1:], labels[:-1])
    apart = np.concatenate(
        [
            key[(labels[:, 1:] != labels[:, :-1]) & (labels[:, 1:] > 0) & (labels[:, :-1] > 0)],
            down[(labels[1:] != labels[:-1]) & (labels[1:] > 0) & (labels[:-1] > 0)],
        ]
    )
    border = np.array([np.count_nonzero(apart == a * count + b) for a, b in touching.tolist()], dtype=np.int64)
    return PieceSummary(sizes, *quantiles, feet, starts, boxes, touching, border)


def held_share(inner: np.ndarray, outer: np.ndarray, cell: float) -> float:
    """:func:`~annotators.geometry.grid_segmentation.inside_share` (the share of convex polygon ``inner``'s cells,
    Nx2 float32 metres on a ``cell`` raster, inside ``outer``) on one raster: ``inner`` filled, then ``outer``
    cleared from it - the cells of ``inner`` it cleared are those inside it."""
    vertices, width, height = raster_vertices(inner, outer, cell)
    raster = np.zeros((height, width), dtype=np.uint8)
    cv2.fillConvexPoly(raster, vertices[: inner.shape[0]], 1)
    filled = cv2.countNonZero(raster)
    cv2.fillConvexPoly(raster, vertices[inner.shape[0] :], 0)
    return (filled - cv2.countNonZero(raster)) / max(1, filled)


def unsupported_holders(
    labels: np.ndarray, plane_points: np.ndarray, rules: SupportRules, pieces: PieceSummary | None = None
) -> list[tuple[int, int]]:
    """``(piece, holder)`` pairs: each piece that cannot stand by itself with the touching neighbour whose hull
    holds the largest share of its footprint (see the module docstring); ``plane_points`` are the ``(u, v,
    height)`` plane coordinates of every pixel of ``labels`` (HxWx3 or (H*W)x3), ``pieces`` their summary when
    already made."""
    pieces = pieces or summarize_pieces(labels, plane_points, rules.sample_step)
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] == 0:
        return []
    # a piece of an object is smaller than the rest; it starts above the holder's foot, below its middle
    candidates = unsupported_candidates(pairs, pieces.sizes, pieces.low, pieces.high, rules.tolerance, rules.reach_down)
    hulls: dict[int, np.ndarray] = {}
    best: dict[int, tuple[float, int]] = {}
    for piece, holder in candidates.tolist():
        if best.get(piece, (-1.0, 0))[0] >= 1.0:
            continue  # held whole already: no later holder can hold more of it
        for label in (piece, holder):
            if label not in hulls:
                hulls[label] = pieces.hull(label)
            if hulls[label].shape[0] < 3:
                break
        else:
            share = held_share(hulls[piece], hulls[holder], rules.cell)
            if share >= rules.held_share and share > best.get(piece, (-1.0, 0))[0]:
                if rules.standing_inside and _stands_inside(labels, plane_points, pieces, piece, holder):
                    continue
                best[piece] = (share, holder)
    return [(piece, holder) for piece, (_, holder) in best.items()]


def _stands_inside(labels: np.ndarray, plane_points: np.ndarray, pieces: PieceSummary, piece: int, holder: int) -> bool:
    """:func:`~annotators.geometry.rims.stands_inside` of two labels, read in their boxes."""
    grid = plane_points.reshape(*labels.shape, 3)
    holder_points = box_label_points(labels, grid, holder, pieces.boxes[holder])
    return stands_inside(holder_points, box_label_points(labels, grid, piece, pieces.boxes[piece]), RimRules())


def join_unsupported(labels: np.ndarray, plane_points: np.ndarray, rules: SupportRules | None = None) -> np.ndarray:
    """Labels with every piece that cannot stand by itself joined to the neighbour that holds it, repeated while
    a join makes another piece held (a mug's inside first joins its outside, whose footprint then holds the rim
    and handle); renumbered 1..n when anything joined."""
    return _join_unsupported(labels, plane_points, rules or SupportRules())[0]


def _join_unsupported(
    labels: np.ndarray, plane_points: np.ndarray, rules: SupportRules
) -> tuple[np.ndarray, PieceSummary]:
    """:func:`join_unsupported` and the summary of the labels it returns."""
    pieces = summarize_pieces(labels, plane_points, rules.sample_step)
    for _ in range(int(labels.max(initial=0))):
        joins = unsupported_holders(labels, plane_points, rules, pieces)
        if not joins:
            break
        labels = join_labels(labels, joins)
        pieces = summarize_pieces(labels, plane_points, rules.sample_step)
    return labels, pieces


@dataclass(frozen=True)
class AppendageRules:
    """Thresholds of :func:`join_appendages`: a piece at most ``small_share`` of its neighbour's size, touching it
    in 3-D (close, see :class:`~annotators.geometry.grid_segmentation.Boundaries`) along at least ``close_share``
    of their shared border and ``boundary_share`` times the square root of its size (at least ``min_boundary``
    pixel pairs), its heights (5 %-95 %) within the neighbour's (5 %-99 %, ``tolerance`` metres of slack) - or
    reaching below the neighbour's 5 % height with the middle of its heights above it: the lower part of a tub
    cut off with the neighbour's lowest points, not a support under it, which lies below; depth
    jumps as the segmenter's (``jump_absolute + jump_relative * nearer depth``); heights sampled on every
    ``sample_step``-th pixel."""

    small_share: float = 0.25
    close_share: float = 0.6
    boundary_share: float = 0.6
    min_boundary: int = 3
    tolerance: float = 0.003
    jump_absolute: float = 0.01
    jump_relative: float = 0.01
    sample_step: int = 2


BORDER_REACH = 2
"""Pixels beside a border that :func:`~annotators.geometry.grid_segmentation.boundaries` reads on either side."""

_CLOSE_FACTOR = 2.5
"""Points at most this many pixel footprints apart are close (the default of
:func:`~annotators.geometry.grid_segmentation.boundaries`)."""

FOOTPRINT_ROWS = 8
"""The pixel footprint (the angle between neighbouring pixels) is measured on every this many rows of the grid."""


def border_tallies(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    jump_absolute: float,
    jump_relative: float,
    close_distance: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per touching label pair (Kx2, a < b) of ``labels``: the number of its 4-neighbour pixel pairs (read
    :data:`BORDER_REACH` pixels to either side), of those without a depth jump (``jump_absolute + jump_relative *
    nearer depth``) and of those whose points lie within ``close_distance`` in 3-D."""
    key, jump, near, _, _ = boundary_pairs(
        np.ascontiguousarray(labels),
        np.asarray(points, dtype=np.float32),
        np.asarray(normals, dtype=np.float32),
        BORDER_REACH,
        jump_absolute,
        jump_relative,
        close_distance,
    )
    if key.size == 0:
        return np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(0), np.zeros(0)
    unique, inverse = distinct_keys(key)
    length = np.bincount(inverse, minlength=unique.size).astype(np.float64)
    smooth = np.bincount(inverse, weights=~jump, minlength=unique.size)
    close = np.bincount(inverse, weights=near, minlength=unique.size)
    base = int(labels.max(initial=0)) + 1
    return np.column_stack([unique // base, unique % base]), length, smooth, close


def close_borders(
    labels: np.ndarray, points: np.ndarray, normals: np.ndarray, rules: AppendageRules, footprint: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``pairs``, ``close`` and ``length`` of :func:`~annotators.geometry.grid_segmentation.boundaries` (its
    default close factor, :data:`BORDER_REACH`, the depth jumps of ``rules``), without its other measures."""
    pairs, length, _, close = border_tallies(
        labels, points, normals, rules.jump_absolute, rules.jump_relative, _CLOSE_FACTOR * footprint
    )
    return pairs, close / length, length


def _footprint(points: np.ndarray) -> float:
    """:func:`~annotators.geometry.grid_segmentation.pixel_footprint`, compiled for float32 points."""
    return footprint_angle(points) if points.dtype == np.float32 else pixel_footprint(points)


def appendage_owners(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: AppendageRules,
    pieces: PieceSummary | None = None,
) -> list[tuple[int, int]]:
    """``(piece, owner)`` pairs of :func:`join_appendages`: each small piece with the neighbour it touches along
    the longest close border among those that qualify (``pieces``: the labels' summary when already made). Sizes
    and heights are checked first; the borders are measured only in the window around the pieces that pass."""
    pieces = pieces or summarize_pieces(labels, plane_points, rules.sample_step)
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] == 0:
        return []
    # a close border at least as long as asked needs as many pixel pairs
    border = pieces.border if pieces.border is not None else np.full(pairs.shape[0], np.inf)
    fitting_pairs = appendage_candidates(
        pairs,
        border,
        pieces.sizes,
        pieces.low,
        pieces.high,
        pieces.top,
        rules.small_share,
        rules.tolerance,
        rules.min_boundary,
        rules.boundary_share,
    )
    if fitting_pairs.shape[0] == 0:
        return []
    involved = np.zeros(pieces.sizes.size, dtype=bool)
    involved[fitting_pairs.reshape(-1)] = True
    boxes = pieces.boxes[fitting_pairs[:, 0]]  # those of the small pieces, grown by the border reach
    margin = BORDER_REACH + 1
    x0, y0 = max(int(boxes[:, 0].min()) - margin, 0), max(int(boxes[:, 1].min()) - margin, 0)
    x1, y1 = (
        min(int(boxes[:, 2].max()) + margin, labels.shape[1]),
        min(int(boxes[:, 3].max()) + margin, labels.shape[0]),
    )
    window = labels[y0:y1, x0:x1]
    pairs, close_shares, lengths = close_borders(
        kept_labels(window, involved),  # only the borders of the small pieces and their owners
        points[y0:y1, x0:x1],
        normals[y0:y1, x0:x1],
        rules,
        _footprint(points[::FOOTPRINT_ROWS]),
    )
    fitting = set(map(tuple, fitting_pairs.tolist()))
    best: dict[int, tuple[float, int]] = {}
    for (a, b), close, length in zip(pairs.tolist(), close_shares, lengths, strict=True):
        along = float(close * length)
        for piece, owner in ((a, b), (b, a)):
            if (
                (piece, owner) in fitting
                and close >= rules.close_share
                and along >= max(rules.min_boundary, rules.boundary_share * np.sqrt(pieces.sizes[piece]))
                and along > best.get(piece, (-1.0, 0))[0]
            ):
                best[piece] = (along, owner)
    return [(piece, owner) for piece, (_, owner) in best.items()]


def join_appendages(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: AppendageRules | None = None,
) -> np.ndarray:
    """Labels with every small piece joined to the larger neighbour it sticks out of (see :class:`AppendageRules`;
    ``points`` and ``normals`` HxWx3 in the camera frame, ``plane_points`` the pixels' ``(u, v, height)``): a piece
    a quarter of a neighbour's size or less whose surface touches the neighbour's in 3-D along most of their shared
    border, and which lies within the neighbour's heights - a drill's chuck cut off at the concave fold where it
    leaves the body, a cup's far inner wall. Objects standing side by side touch along a line at most; along the
    rest of their shared border in the image one hides the other (a depth jump)."""
    joins = appendage_owners(labels, points, normals, plane_points, rules or AppendageRules())
    return join_labels(labels, joins) if joins else labels


@dataclass(frozen=True)
class JointRules:
    """Thresholds of :func:`join_jointly_held`: those of :func:`join_unsupported` (``support``: a piece that cannot
    stand by itself, and the share of its footprint its holders' hull must hold), the pixel pairs along which two
    pieces' surfaces must touch in 3-D (``min_close``; see :func:`close_borders`) and the depth jumps
    (``jump_absolute + jump_relative * nearer depth``)."""

    support: SupportRules = SupportRules()
    min_close: int = 3
    jump_absolute: float = 0.01
    jump_relative: float = 0.01


def jointly_held(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: JointRules,
    pieces: PieceSummary | None = None,
) -> list[tuple[int, int, int]]:
    """``(piece, first, second)`` triples of :func:`join_jointly_held`: each piece that cannot stand by itself (as
    for :func:`join_unsupported`) beside both holders, held by neither alone but by the hull of the two together,
    where the piece and its two holders touch one another in 3-D, each pair along at least ``min_close`` close
    pixel pairs; the pair whose joint hull holds the largest share of the piece (``pieces``: the labels' summary
    when already made)."""
    support = rules.support
    pieces = pieces or summarize_pieces(labels, plane_points, support.sample_step)
    pairs = pieces.touching_pairs(labels)
    if pairs.shape[0] < 3:
        return []
    candidates = unsupported_candidates(
        pairs, pieces.sizes, pieces.low, pieces.high, support.tolerance, support.reach_down
    )
    holders: dict[int, list[int]] = {}
    for piece, holder in candidates.tolist():
        holders.setdefault(piece, []).append(holder)
    touching = set(map(tuple, pairs.tolist()))
    triples = [
        (piece, first, second)
        for piece, around in holders.items()
        for k, first in enumerate(around)
        for second in around[k + 1 :]
        if (min(first, second), max(first, second)) in touching
    ]
    if not triples:
        return []
    involved = np.zeros(pieces.sizes.size, dtype=bool)
    involved[np.array(triples).reshape(-1)] = True
    boxes = pieces.boxes[involved]
    margin = BORDER_REACH + 1
    x0, y0 = max(int(boxes[:, 0].min()) - margin, 0), max(int(boxes[:, 1].min()) - margin, 0)
    x1 = min(int(boxes[:, 2].max()) + margin, labels.shape[1])
    y1 = min(int(boxes[:, 3].max()) + margin, labels.shape[0])
    touch_rules = AppendageRules(jump_absolute=rules.jump_absolute, jump_relative=rules.jump_relative)
    border_pairs, close_shares, lengths = close_borders(
        kept_labels(labels[y0:y1, x0:x1], involved),
        points[y0:y1, x0:x1],
        normals[y0:y1, x0:x1],
        touch_rules,
        _footprint(points[::FOOTPRINT_ROWS]),
    )
    attached = {
        tuple(pair)
        for pair, close, length in zip(border_pairs.tolist(), close_shares, lengths, strict=True)
        if close * length >= rules.min_close
    }

    def touch(a: int, b: int) -> bool:
        return (min(a, b), max(a, b)) in attached

    best: dict[int, tuple[float, int, int]] = {}
    for piece, first, second in triples:
        if not (touch(piece, first) and touch(piece, second) and touch(first, second)):
            continue
        hull = pieces.hull(piece)
        if hull.shape[0] < 3:
            continue
        alone = max(held_share(hull, pieces.hull(holder), support.cell) for holder in (first, second))
        if alone >= support.held_share:
            continue  # one holder holds it: join_unsupported's case
        if support.standing_inside and any(
            _stands_inside(labels, plane_points, pieces, piece, holder) for holder in (first, second)
        ):
            continue  # it rests on a container's floor, as in join_unsupported
        share = held_share(hull, joint_hull(pieces, first, second), support.cell)
        if share >= support.held_share and share > best.get(piece, (-1.0, 0, 0))[0]:
            best[piece] = (share, first, second)
    return [(piece, first, second) for piece, (_, first, second) in best.items()]


def joint_hull(pieces: PieceSummary, first: int, second: int) -> np.ndarray:
    """The convex hull (Kx2) of the sampled feet of two labels together."""
    feet = np.concatenate([pieces.feet[pieces.starts[label] : pieces.starts[label + 1]] for label in (first, second)])
    if feet.shape[0] < 3:
        return feet
    return cv2.convexHull(hull_candidates(feet) if feet.shape[0] >= _FEW_FEET else feet).reshape(-1, 2)


def join_jointly_held(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: JointRules | None = None,
) -> np.ndarray:
    """Labels with every piece that cannot stand by itself, and that two touching neighbours hold only together,
    joined with both (see :func:`jointly_held`; ``points`` and ``normals`` HxWx3 in the camera frame,
    ``plane_points`` the pixels' ``(u, v, height)``): an open container cut along its inner wall's concave fold
    into three - the inside seen over the rim hangs between the outside's front and its side with the handle, and
    lies half over each. The three surfaces meet in 3-D along their shared borders, one continuous object; two
    objects standing side by side are parted by a depth jump where one hides the other, and an object standing on
    others starts at their tops."""
    return _join_jointly_held(labels, points, normals, plane_points, rules or JointRules())[0]


def _join_jointly_held(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    rules: JointRules,
    pieces: PieceSummary | None = None,
) -> tuple[np.ndarray, bool]:
    """:func:`join_jointly_held` and whether anything joined."""
    triples = jointly_held(labels, points, normals, plane_points, rules, pieces)
    if not triples:
        return labels, False
    joins = [(piece, holder) for piece, first, second in triples for holder in (first, second)]
    return join_labels(labels, joins), True


def join_pieces(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    support: SupportRules | None,
    appendages: AppendageRules | None,
    joint: JointRules | None = None,
) -> np.ndarray:
    """:func:`join_unsupported` (unless ``support`` is None), :func:`join_jointly_held` (unless ``joint`` is None;
    then :func:`join_unsupported` again where it joined), then :func:`join_appendages` (unless ``appendages`` is
    None), summarizing the pieces once where a step joined nothing."""
    return join_pieces_summarized(labels, points, normals, plane_points, support, appendages, joint)[0]


def join_pieces_summarized(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    plane_points: np.ndarray,
    support: SupportRules | None,
    appendages: AppendageRules | None,
    joint: JointRules | None = None,
) -> tuple[np.ndarray, PieceSummary | None, int]:
    """:func:`join_pieces`, with the summary of the labels it returns and the sample step it was made with, for the
    next step to read (None and 0 when the last join left none)."""
    pieces, step = None, 0
    if support is not None:
        labels, pieces = _join_unsupported(labels, plane_points, support)
        step = support.sample_step
    if joint is not None:
        if joint.support.sample_step != step:
            pieces, step = None, 0
        labels, joined = _join_jointly_held(labels, points, normals, plane_points, joint, pieces)
        if joined:
            labels, pieces = _join_unsupported(labels, plane_points, support or joint.support)
            step = (support or joint.support).sample_step
    if appendages is None:
        return labels, pieces, step
    if appendages.sample_step != step or pieces is None:
        pieces, step = summarize_pieces(labels, plane_points, appendages.sample_step), appendages.sample_step
    joins = appendage_owners(labels, points, normals, plane_points, appendages, pieces)
    return (join_labels(labels, joins), None, 0) if joins else (labels, pieces, step)
