"""The rim of an open container, on the organized grid: the pieces of one container whose rim an object cuts.

Seen from above, the inside of a bowl shows the back of its inner wall over the rim, and the top edge of that
wall is an arc of the rim: a circle on the table plane at one height, curving around a centre nearer the camera
than the arc (the front of a solid object curves the other way). An object standing in the bowl hides the middle
of the inner wall and cuts it into pieces left and right of it that touch little or not at all, and the grouping
keeps the concave wall apart from the front of the outer wall anyway. The rim still tells them together:

* two pieces whose top edges are concave arcs at one height (their 95 % heights within ``tolerance``) that fit
  one circle (:func:`rim_circle`) bending about as each arc does (``curvature``: not the arcs of two rims facing
  one another) and that are cut apart by one neighbour (both touch it; it reaches up to their rim, which it hides
  between them) are the inner wall of one container, on both sides of what stands in it;
* a piece touching that container (directly or through its outer wall's other pieces, never through the
  neighbour that cuts the rim) within its rim circle (its median distance from the centre at most ``hold`` of the
  radius) that stays below the rim and reaches out to the circle (at least ``reach``) or lies in front of the
  centre is its outer wall seen below the front rim.

One inner wall alone tells its container too when nothing cuts its rim (:func:`single_rim_joins`): its top edge runs
around at least a quarter of a rim circle, and a touching piece that is its outer wall (below the rim, within the
circle, reaching out to it) joins it. The inside and the outside of a bowl meet only along the front rim, where
the inside lies behind a depth jump, and their footprints barely overlap, so nothing else joins them.

An object standing in the container and rising above the rim is never joined (:func:`join_rim_pieces`); one
lying in it below the rim, in front of its centre, would be (the convexity grouping keeps most of them apart
before). :func:`stands_inside` tells an object standing in a container from the inner wall around it.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from annotators.geometry.grid_segmentation import join_labels, label_groups, touching_pairs
from annotators.geometry.support_kernels import box_label_points


@dataclass(frozen=True)
class RimRules:
    """Thresholds of :func:`join_rim_pieces` (metres and shares of the rim's radius): the height band below a
    piece's 95 % height holding its top edge (``band``), the median distance of the top edge from the fitted
    circle (``fit``, share of the radius), the agreement of rim heights (``tolerance``), the reach of an outer
    wall toward the circle (``reach``, ``hold``), the reach from the centre of an object standing inside
    (``inside``: its median distance, well within the rim), how much more tightly than their joint rim two pieces' top
    edges may each curve (``curvature``: the joint radius at most this many times each edge's own; a short arc
    fixes its own circle loosely), the fewest top-edge points a circle is fitted to (``min_points``) and the angle
    (radians) around its rim one inner wall's top edge must run to fix the rim alone (``single_turn``: the back half
    of a rim seen over its front shows about half a turn), and the spacing of the grid pixels :func:`single_rim_joins`
    samples (``sample_step``)."""

    band: float = 0.01
    fit: float = 0.1
    tolerance: float = 0.01
    reach: float = 0.9
    hold: float = 1.1
    inside: float = 0.75
    curvature: float = 2.0
    min_points: int = 20
    single_turn: float = math.pi / 2
    sample_step: int = 2


@dataclass(frozen=True)
class Rim:
    """A rim circle on the table plane: ``centre`` (u, v), ``radius`` and ``height`` (metres)."""

    centre: np.ndarray
    radius: float
    height: float


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.rim_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import rim_loops

    return rim_loops


def share_value(values: np.ndarray, share: float) -> float:
    """The value ``share`` (0..1) of the way up a 1-D array's sorted values (nearest rank, by a partial sort; NaN for
    none)."""
    return float(_loops().share_value(np.ascontiguousarray(values), float(share)))


def fit_circle(points: np.ndarray) -> tuple[np.ndarray, float]:
    """The least-squares circle ``(centre, radius)`` through Nx2 points (algebraic fit; radius 0 when the points fix
    no circle)."""
    u, v, radius = _loops().fit_circle(np.ascontiguousarray(points, dtype=np.float64))
    return np.array([u, v]), float(radius)


def top_edge(points: np.ndarray, rules: RimRules) -> tuple[np.ndarray, float]:
    """The (u, v) of a piece's top-edge points (Nx3 ``(u, v, height)``; those not finite left out) within
    ``rules.band`` of its 95 % height, and that height."""
    edge, top = _loops().top_edge(np.ascontiguousarray(points), float(rules.band))
    return edge, float(top)


def curves_like_a_rim(centre: np.ndarray, edge: np.ndarray) -> bool:
    """Could an arc (Nx2 points on the plane, the camera's foot at the origin) around ``centre`` be part of an
    open container's rim? Either it curves around a centre nearer the camera than itself (the back of the rim,
    over which the inner wall is seen), not bulging toward the camera as the front of a solid object does; or it
    runs around the centre over more than half the circle (the rim of a whole container)."""
    edge = np.ascontiguousarray(edge, dtype=np.float64)
    return _rim_shaped(edge, centre, _loops().arc_measures(edge, centre[0], centre[1], 0.0)[1])


def _rim_shaped(edge: np.ndarray, centre: np.ndarray, away: float) -> bool:
    """:func:`curves_like_a_rim` of an edge whose median distance from the camera's foot is ``away``."""
    return bool(np.hypot(*centre) < away or _loops().arc_turn(edge, centre[0], centre[1]) > np.pi)


@dataclass(frozen=True)
class Arc:
    """A piece's top edge that could be part of a rim: its ``edge`` points (Nx2), their ``height`` (the piece's
    95 % height) and the ``radius`` of the circle fitted to them alone."""

    edge: np.ndarray
    height: float
    radius: float


def rim_arc(points: np.ndarray, rules: RimRules) -> Arc | None:
    """The top edge of a piece (Nx3 ``(u, v, height)``; those not finite left out) when it curves like part of a rim
    (:func:`curves_like_a_rim` around the circle fitted to it alone; a short arc fixes that circle loosely, so only
    its curvature is asked here and the fit of a joint circle later); None for fewer than ``rules.min_points``."""
    if points.shape[0] < rules.min_points:
        return None
    edge, height = top_edge(points, rules)
    if edge.shape[0] < rules.min_points:
        return None
    centre, radius = fit_circle(edge)
    return Arc(edge, height, radius) if curves_like_a_rim(centre, edge) else None


def rim_circle(edges: list[np.ndarray], heights: list[float], rules: RimRules) -> Rim | None:
    """The rim that the top edges of one or more pieces (Nx2 each, on the plane with the camera's foot at the
    origin) lie on: one circle they each fit within ``rules.fit`` of its radius, each shaped like part of a rim
    (:func:`curves_like_a_rim`), at heights within ``rules.tolerance``; None otherwise."""
    if any(edge.shape[0] < rules.min_points for edge in edges) or max(heights) - min(heights) > rules.tolerance:
        return None
    centre, radius = fit_circle(edges[0] if len(edges) == 1 else np.concatenate(edges))
    if radius <= 0.0:
        return None
    for edge in edges:
        off, away = _loops().arc_measures(edge, centre[0], centre[1], radius)
        if off > rules.fit * radius or not _rim_shaped(edge, centre, away):
            return None
    return Rim(centre, radius, float(np.mean(heights)))


def stands_inside(wall: np.ndarray, other: np.ndarray, rules: RimRules) -> bool:
    """Does part ``other`` stand inside the container whose inner wall is part ``wall`` (both Nx3 ``(u, v,
    height)``)? The wall's top edge is (part of) a rim (:func:`rim_circle`), the other part lies well within the rim
    (its median distance from the centre at most ``rules.inside`` of the radius) and rises above it: a can standing
    in a bowl."""
    if wall.shape[0] < rules.min_points or other.shape[0] < rules.min_points:
        return False
    if not share_value(other[:, 2], 0.95) > share_value(wall[:, 2], 0.95) + rules.tolerance:
        return False  # the heights first (cheap): most parts rise no higher than the wall beside them
    return _within_rim(wall, other, rules)


def _within_rim(wall: np.ndarray, other: np.ndarray, rules: RimRules) -> bool:
    """The rim test of :func:`stands_inside`, its heights checked already."""
    edge, height = top_edge(wall, rules)
    rim = rim_circle([edge], [height], rules)
    return rim is not None and _distance_share(other, rim.centre, 0.5) <= rules.inside * rim.radius


def _distance_share(points: np.ndarray, centre: np.ndarray, share: float) -> float:
    """The value ``share`` of the way up the sorted (u, v) distances of Nx3 points (those not finite left out) from
    ``centre``."""
    return float(_loops().distance_share(np.ascontiguousarray(points), float(centre[0]), float(centre[1]), share))


def one_stands_inside(first: np.ndarray, second: np.ndarray, rules: RimRules | None = None) -> bool:
    """Does either of two parts (Nx3 ``(u, v, height)``) stand inside the container whose inner wall the other is
    (:func:`stands_inside`)? Only the one rising above the other's heights can."""
    rules = rules or RimRules()
    if first.shape[0] < rules.min_points or second.shape[0] < rules.min_points:
        return False
    first_top = _loops().top_height(np.ascontiguousarray(first))
    second_top = _loops().top_height(np.ascontiguousarray(second))
    if second_top > first_top + rules.tolerance:
        return _within_rim(first, second, rules)
    if first_top > second_top + rules.tolerance:
        return _within_rim(second, first, rules)
    return False


def rim_joins(
    labels: np.ndarray,
    plane_points: np.ndarray,
    rules: RimRules,
    tops: np.ndarray | None = None,
    touching: np.ndarray | None = None,
    boxes: np.ndarray | None = None,
) -> list[tuple[int, int]]:
    """Label pairs of :func:`join_rim_pieces` (``plane_points``: the ``(u, v, height)`` of every pixel, HxWx3;
    ``tops`` each label's 95 % height, ``touching`` the touching label pairs and ``boxes`` each label's pixel box
    ``(x0, y0, x1, y1)`` when known)."""
    pairs = touching_pairs(labels) if touching is None else touching
    if pairs.shape[0] < 2:
        return []
    neighbours: dict[int, set[int]] = {}
    for a, b in pairs.tolist():
        neighbours.setdefault(a, set()).add(b)
        neighbours.setdefault(b, set()).add(a)
    coordinates: dict[int, np.ndarray] = {}
    if boxes is None:
        pixels, starts = label_groups(labels)
        flat = plane_points.reshape(-1, 3)

    def points_of(label: int) -> np.ndarray:
        if label not in coordinates:
            if boxes is None:
                coordinates[label] = flat[pixels[starts[label] : starts[label + 1]]]
            else:
                coordinates[label] = box_label_points(labels, plane_points, label, boxes[label])
        return coordinates[label]

    heights: dict[int, float] = {}  # each piece's 95 % height, NaN when too small to have an edge

    def height_of(label: int) -> float:
        if tops is not None:
            return float(tops[label])
        if label not in heights:
            own = points_of(label)
            heights[label] = _loops().top_height(own) if own.shape[0] >= rules.min_points else np.nan
        return heights[label]

    arcs: dict[int, Arc | None] = {}

    def arc_of(label: int) -> Arc | None:
        if label not in arcs:
            arcs[label] = rim_arc(points_of(label), rules)
        return arcs[label]

    joins: list[tuple[int, int]] = []
    tried: set[tuple[int, int]] = set()
    for cut, around in neighbours.items():  # the pieces one neighbour cuts apart
        # to cut the rim, the neighbour reaches up to it in front of it; the pieces' rims are at one height
        candidates = sorted(label for label in around if height_of(cut) >= height_of(label) - rules.tolerance)
        for k, first in enumerate(candidates):
            for second in candidates[k + 1 :]:
                if (first, second) in tried or abs(height_of(first) - height_of(second)) > rules.tolerance:
                    continue
                tried.add((first, second))
                pair = (arc_of(first), arc_of(second))
                if pair[0] is None or pair[1] is None:
                    continue
                rim = rim_circle([arc.edge for arc in pair], [arc.height for arc in pair], rules)
                if rim is None or rim.radius > rules.curvature * min(arc.radius for arc in pair):
                    continue  # arcs of two smaller rims facing one another
                joins.append((first, second))
                # the outer wall, piece by piece from the inner wall on, never through what stands inside
                container, frontier = {first, second}, [first, second]
                while frontier:
                    for piece in sorted(neighbours[frontier.pop()] - container - {cut}):
                        if is_outer_wall(points_of(piece), rim, rules):
                            container.add(piece)
                            frontier.append(piece)
                            joins.append((first, piece))
    return joins


def single_rim_joins(labels: np.ndarray, plane_points: np.ndarray, rules: RimRules) -> list[tuple[int, int]]:
    """Label pairs ``(inner wall, outer wall)`` of one open container whose rim one inner wall shows alone (see
    the module docstring; ``plane_points``: the ``(u, v, height)`` of every pixel, HxWx3, of which every
    ``rules.sample_step``-th row and column is read). The outer wall must reach out to the rim circle
    (``rules.reach`` of its radius): a piece in front of the centre but well within the circle may be something
    standing in the container, below its rim."""
    pairs = touching_pairs(labels)
    if pairs.shape[0] == 0:
        return []
    step = max(1, rules.sample_step)
    pixels, starts = label_groups(np.ascontiguousarray(labels[::step, ::step]))
    # a small piece may have no pixel on the sampled rows and columns (above the sampled labels): it owns none
    starts = np.pad(starts, (0, max(0, int(labels.max()) + 2 - starts.size)), mode="edge")
    flat = np.ascontiguousarray(plane_points[::step, ::step]).reshape(-1, 3)
    coordinates: dict[int, np.ndarray] = {}

    def points_of(label: int) -> np.ndarray:
        if label not in coordinates:
            own = flat[pixels[starts[label] : starts[label + 1]]]
            coordinates[label] = own[np.isfinite(own).all(axis=1)]
        return coordinates[label]

    rims: dict[int, Rim | None] = {}

    def rim_of(label: int) -> Rim | None:
        if label not in rims:
            rims[label] = None
            arc = rim_arc(points_of(label), rules)
            rim = rim_circle([arc.edge], [arc.height], rules) if arc is not None else None
            if rim is not None and _loops().arc_turn(arc.edge, rim.centre[0], rim.centre[1]) >= rules.single_turn:
                rims[label] = rim
        return rims[label]

    joins = []
    for first, second in pairs.tolist():
        for wall, piece in ((first, second), (second, first)):
            rim = rim_of(wall)
            if rim is None or one_stands_inside(points_of(wall), points_of(piece), rules):
                continue
            other = points_of(piece)
            reaches_out = _distance_share(other, rim.centre, 0.95) >= rules.reach * rim.radius
            if reaches_out and is_outer_wall(other, rim, rules):
                joins.append((wall, piece))
                break
    return joins


def join_single_rims(labels: np.ndarray, plane_points: np.ndarray, rules: RimRules | None = None) -> np.ndarray:
    """Labels with each inner wall that shows a rim alone joined to its outer wall (:func:`single_rim_joins`); the
    same array when nothing joined."""
    joins = single_rim_joins(labels, plane_points.reshape(*labels.shape, 3), rules or RimRules())
    return join_labels(labels, joins) if joins else labels


def is_outer_wall(points: np.ndarray, rim: Rim, rules: RimRules) -> bool:
    """Is a piece (Nx3 ``(u, v, height)``, the camera's foot at the origin) the container's outer wall below its
    rim: within the rim circle (its median distance from the centre at most ``rules.hold`` of the radius; a pot's
    handles stick out of the circle, and the fitted centre errs along the line of sight), no higher than the rim (95 %
    height), and reaching out to the circle (at least ``rules.reach`` of the radius) or lying in front of the centre,
    nearer the camera (the front of a tapering wall, toward the foot)?"""
    points = points[np.isfinite(points).all(axis=1)]
    if points.shape[0] < rules.min_points:
        return False
    if share_value(points[:, 2], 0.95) > rim.height + rules.tolerance:
        return False
    if _distance_share(points, rim.centre, 0.5) > rules.hold * rim.radius:
        return False
    reach = _distance_share(points, rim.centre, 0.95)
    in_front = _distance_share(points, np.zeros(2), 0.5) < float(np.hypot(*rim.centre))
    return reach >= rules.reach * rim.radius or in_front


def join_rim_pieces(
    labels: np.ndarray,
    plane_points: np.ndarray,
    rules: RimRules | None = None,
    tops: np.ndarray | None = None,
    touching: np.ndarray | None = None,
    boxes: np.ndarray | None = None,
) -> np.ndarray:
    """Labels with the pieces of one open container's rim joined (see the module docstring; ``plane_points`` the
    ``(u, v, height)`` of every pixel, HxWx3 or (H*W)x3; ``tops`` each label's 95 % height, ``touching`` the
    touching label pairs and ``boxes`` the labels' pixel boxes, when a summary of the labels has them); the same
    array when nothing joined."""
    joins = rim_joins(labels, plane_points.reshape(*labels.shape, 3), rules or RimRules(), tops, touching, boxes)
    return join_labels(labels, joins) if joins else labels
