"""The floor of an open container seen from above, on the organized grid: it joins the container.

Only points at least ``min_height`` above the supporting plane are candidates of the segmentation, and the inside
floor of a bowl, a tray or a low pot lies within that band: the floor of a thin-walled bowl is a few millimetres
above the table, within the depth noise of the plane. Seen from above, the floor is left out, the container comes
out as a ring of wall around a hole, and the bits of the floor that the noise lifts above ``min_height`` come out as
small pieces of their own.

Such a floor is told from the table by where it lies, on the plane and in the image:

* within the container's footprint - the convex hull of the feet of the container's points (away from its
  outline, whose mixed pixels fall anywhere) - reached from a part of the floor at least ``margin`` inside it;
  visible table lies within an object's footprint only where it is seen over the object's rim or through it:
  beside a solid object it lies outside but for the band where the object meets the table and the hull's noise,
  which no part well inside reaches, and behind one it is hidden;
* where that part lies, the container surrounds it in the image on three sides at least - its far wall and both
  side walls; the near wall may be out of the frame or lost by the depth sensor (:func:`enclosing_labels`);
* no part of the container hangs over it: where an object hangs over the table (a drill's chuck reaching out
  above the table in front of its battery, a box leaning on another with the table seen under its raised edge)
  the table seen under it is within the footprint too, but every point of the object over it lies more than
  ``min_height`` above the candidates' lowest height, while a container's wall runs down to its floor, to where
  the candidates start (:func:`overhung`).

Each such pixel joins the object whose footprint holds it (:func:`claim_container_floors`); a floor piece lifted
by the noise then touches its container and joins it as a piece that cannot stand by itself
(:func:`annotators.geometry.support.join_unsupported`). Geometry alone cannot tell a floor from the table seen
through an object (a drill's trigger loop, a ring lying flat): such table joins the object too.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import ModuleType

import cv2
import numpy as np

_SQUARE = np.ones((3, 3), dtype=np.uint8)
"""The 8-neighbourhood as a structuring element."""


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.floor_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import floor_loops

    return floor_loops


@dataclass(frozen=True)
class FloorRules:
    """Thresholds of :func:`claim_container_floors` (metres), the segmenter's own: points within ``min_height`` of
    the plane (either side) are at table level (its lowest candidate height); a floor runs on (4-connected in the
    image) from a part at least ``margin`` inside the convex hull of its container's feet (the margin of the
    plane's extent) as far as the hull; an object hangs over the ``cell``-sized cells of the plane (the plane
    raster's cell) whose points all lie more than ``min_height`` above the candidates' lowest height (twice
    ``min_height`` above the plane); the hull's feet read on every ``sample_step``-th pixel."""

    min_height: float = 0.01
    margin: float = 0.015
    cell: float = 0.005
    sample_step: int = 2


class Footprint:
    """A convex polygon on the plane (Kx2 metres) rasterized with ``cell`` metres per pixel, with each cell's
    distance to the polygon's outline: how deep a foot lies inside it is one lookup (to the cell)."""

    def __init__(self, hull: np.ndarray, cell: float) -> None:
        self.cell = cell
        self.origin = hull.min(axis=0) - 2 * cell
        width, height = (np.ceil((hull.max(axis=0) - self.origin) / cell).astype(np.int64) + 3).tolist()
        raster = np.zeros((height, width), dtype=np.uint8)
        cv2.fillConvexPoly(raster, np.round((hull - self.origin) / cell).astype(np.int32), 1)
        self.distances = cv2.distanceTransform(raster, cv2.DIST_L2, 3) * cell

    def depth(self, feet: np.ndarray) -> np.ndarray:
        """N float: how far inside the polygon each of the Nx2 ``feet`` lies (metres, to the cell; 0 outside)."""
        at = np.floor((feet - self.origin) / self.cell).astype(np.int64)
        height, width = self.distances.shape
        within = (at[:, 0] >= 0) & (at[:, 0] < width) & (at[:, 1] >= 0) & (at[:, 1] < height)
        result = np.zeros(feet.shape[0], dtype=np.float32)
        result[within] = self.distances[at[within, 1], at[within, 0]]
        return result


def claim_container_floors(
    labels: np.ndarray,
    valid: np.ndarray,
    plane_points: np.ndarray,
    rules: FloorRules | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Labels with each container's floor joined to the container (see the module docstring), and the HxW mask
    of the pixels claimed. ``labels`` HxW (0 unlabelled), ``valid`` the measured pixels, ``plane_points`` the
    pixels' ``(u, v, height)`` on the plane (HxWx3 or (H*W)x3)."""
    rules = rules or FloorRules()
    claimed = np.zeros(labels.shape, dtype=bool)
    plane_points = np.ascontiguousarray(plane_points.reshape(*labels.shape, 3), dtype=np.float32)
    loops = _loops()
    grid_labels = np.ascontiguousarray(labels, dtype=np.int32)
    # one compiled pass: the table-level pixels, the label enclosing each, the labels' boxes
    level, enclosing, boxes, enclosed = loops.floor_seeds(
        grid_labels, valid, plane_points[..., 2], np.float32(rules.min_height)
    )
    if not enclosed.any():
        return labels, claimed  # no table-level pixel with an object on three sides: no floor to seed from
    result = labels.copy()
    box_decides = box_rules_out(rules.margin, rules.cell)
    cell = np.float32(rules.cell)
    # the labels with too few core feet, or whose box rules out every enclosed foot, screened out all at once
    counts, possible = loops.candidate_screen(
        grid_labels, enclosing, plane_points, boxes, enclosed, rules.sample_step, cell
    )
    promising = enclosed & (counts >= 3) & (possible | (not box_decides))
    for label in np.flatnonzero(promising).tolist():
        y0, y1, x0, x1 = boxes[label].tolist()
        core, rows, cols, seed_feet, possible = loops.floor_candidate(
            grid_labels, enclosing, plane_points, label, boxes[label], rules.sample_step, cell
        )
        if core.shape[0] < 3 or (box_decides and not possible):
            continue  # no part of the floor can lie margin inside the footprint: no hull needed to tell
        hull = cv2.convexHull(core).reshape(-1, 2)
        if hull.shape[0] < 3:
            continue
        footprint = Footprint(hull, rules.cell)
        seeds = footprint.depth(seed_feet) >= rules.margin
        if not seeds.any():
            continue
        seed_rows, seed_cols = rows[seeds], cols[seeds]
        rows, cols = np.nonzero(level[y0:y1, x0:x1])
        feet = plane_points[rows + y0, cols + x0, :2]
        inside = footprint.depth(feet) > 0
        rows, cols, feet = rows[inside], cols[inside], feet[inside]
        clearance = np.float32(2 * rules.min_height)
        free = ~loops.overhung(feet, grid_labels, plane_points, label, boxes[label], clearance, cell)
        floor = np.zeros((y1 - y0, x1 - x0), dtype=bool)
        floor[rows[free], cols[free]] = True
        # the floor reaches as far as the footprint where it runs on from a part well inside it
        count, parts = cv2.connectedComponents(floor.view(np.uint8), connectivity=4)
        seeded = np.zeros(count, dtype=bool)  # the parts holding a seed, looked up per pixel
        seeded[parts[seed_rows, seed_cols]] = True
        seeded[0] = False
        floor = seeded[parts]
        result[y0:y1, x0:x1][floor] = label
        claimed[y0:y1, x0:x1] |= floor
    return result, claimed


def touches_other_labels(labels: np.ndarray, marked: np.ndarray) -> bool:
    """Whether a ``marked`` pixel (HxW bool) has a 4-neighbour with another non-zero label than its own, in one
    compiled pass that stops at the first (:func:`touches_other_labels_numpy` is its reference form)."""
    return bool(_loops().touches_other_labels(np.ascontiguousarray(labels), np.ascontiguousarray(marked)))


def touches_other_labels_numpy(labels: np.ndarray, marked: np.ndarray) -> bool:
    """:func:`touches_other_labels` in whole-array numpy: the reference form its compiled pass is tested against."""
    for a, b in (
        (np.s_[:, :-1], np.s_[:, 1:]),
        (np.s_[:, 1:], np.s_[:, :-1]),
        (np.s_[:-1, :], np.s_[1:, :]),
        (np.s_[1:, :], np.s_[:-1, :]),
    ):
        other = labels[b]
        if np.any(marked[a] & (other > 0) & (other != labels[a])):
            return True
    return False


def core_feet(mask: np.ndarray, plane_points: np.ndarray, step: int = 1) -> np.ndarray:
    """The feet (Nx2 float32) of the object's pixels ``mask`` (HxW) away from its outline (eroded by one pixel),
    read on every ``step``-th pixel: the outline's mixed pixels, between the object and what lies behind it, fall
    anywhere."""
    eroded = cv2.erode(mask.view(np.uint8), _SQUARE, borderType=cv2.BORDER_CONSTANT, borderValue=0)
    core = eroded[::step, ::step] > 0
    feet = plane_points[::step, ::step][core][:, :2]
    return feet[np.isfinite(feet).all(axis=1)].astype(np.float32)


def core_hull(mask: np.ndarray, plane_points: np.ndarray, step: int = 1) -> np.ndarray:
    """The convex hull (Kx2) of :func:`core_feet` (the feet themselves when fewer than three)."""
    feet = core_feet(mask, plane_points, step)
    if feet.shape[0] < 3:
        return feet
    return cv2.convexHull(feet).reshape(-1, 2)


_DIAGONAL_STEP = 1.3694
"""The distance transform's (L2, 3x3 mask) diagonal step in cells, rounded up: no step is longer."""


def box_rules_out(margin: float, cell: float) -> bool:
    """Whether a ``margin`` is deep enough in a :class:`Footprint` of ``cell`` metres for :func:`may_lie_within` to
    rule feet out: more than two of the distance transform's longest steps."""
    return margin > 2 * _DIAGONAL_STEP * cell


def may_lie_within(feet: np.ndarray, corners: np.ndarray, margin: float, cell: float) -> bool:
    """Whether any of the Nx2 ``feet`` can lie at least ``margin`` inside the :class:`Footprint` (``cell``) of the
    convex hull of the Kx2 ``corners``, told from the corners' bounding box alone: False only where no foot can.

    A cell of the footprint's raster lies ``margin`` (more than two of the distance transform's longest steps, see
    :func:`box_rules_out`) inside only where every cell within two steps is filled, so at least two cells inside the
    box of the rounded corners: its foot lies at least 1.5 cells above the corners' least ``u`` and ``v`` and 0.5
    cells below their greatest; the test leaves half a cell of slack on either side. The segmenter runs it compiled
    (:mod:`annotators.geometry.floor_loops`)."""
    if not box_rules_out(margin, cell):
        return bool(feet.shape[0])  # too thin a margin for the box to rule anything out
    low, high = corners.min(axis=0) + cell, corners.max(axis=0)
    return bool(((feet >= low) & (feet <= high)).all(axis=1).any())


def nearest_labels(labels: np.ndarray, axis: int, reverse: bool) -> np.ndarray:
    """HxW: for every pixel the label of the nearest labelled pixel (itself included) along ``axis`` - toward
    lower indices, or higher ones with ``reverse`` - or 0 when there is none."""
    view = np.flip(labels, axis=axis) if reverse else labels
    size = view.shape[axis]
    positions = np.arange(size).reshape((-1, 1) if axis == 0 else (1, -1))
    last = np.maximum.accumulate(np.where(view > 0, positions, -1), axis=axis)
    nearest = np.take_along_axis(view, np.maximum(last, 0), axis=axis)
    nearest = np.where(last >= 0, nearest, 0)
    return np.flip(nearest, axis=axis) if reverse else nearest


def enclosing_labels(labels: np.ndarray) -> np.ndarray:
    """HxW (the reference form of the segmenter's compiled pass): for every pixel the label that is the nearest
    one on at least three of its four sides - to the left and right in its row, above and below in its column -
    or 0: a floor seen over a container's rim meets its wall first on three sides at least (the near wall may be
    out of sight), the table beside a solid object meets it on one or two."""
    left, right = nearest_labels(labels, 1, False), nearest_labels(labels, 1, True)
    up, down = nearest_labels(labels, 0, False), nearest_labels(labels, 0, True)
    across = (left == right) & ((left == up) | (left == down))
    along = (up == down) & ((up == left) | (up == right))
    return np.where(across, left, np.where(along, up, 0))


def overhung(feet: np.ndarray, object_points: np.ndarray, clearance: float, cell: float) -> np.ndarray:
    """N bool: which of the Nx2 ``feet`` lie in a ``cell``-metre raster cell of the plane where the object hangs
    over the table - every point of the object (Mx3 ``(u, v, height)``) whose foot falls in the cell lies higher
    than ``clearance`` (a drill's chuck above the table in front of its battery); the raster is closed (3x3) so
    that the gaps between sparse feet count too. A wall that runs down to a floor has points low in its cells. The
    reference form of the segmenter's compiled pass (:func:`annotators.geometry.floor_loops.overhung`)."""
    object_points = object_points[np.isfinite(object_points).all(axis=1)]
    if object_points.shape[0] == 0:
        return np.zeros(feet.shape[0], dtype=bool)
    low = np.minimum(object_points[:, :2].min(axis=0), feet.min(axis=0)) - 2 * cell
    high = np.maximum(object_points[:, :2].max(axis=0), feet.max(axis=0)) + 2 * cell
    width, height = (np.ceil((high - low) / cell).astype(np.int64) + 1).tolist()
    cells = ((object_points[:, :2] - low) / cell).astype(np.int64)
    occupied = np.zeros((height, width), dtype=bool)
    occupied[cells[:, 1], cells[:, 0]] = True
    reaching = cells[object_points[:, 2] <= clearance]
    reached = np.zeros((height, width), dtype=bool)
    reached[reaching[:, 1], reaching[:, 0]] = True
    over = occupied & ~reached
    over = cv2.morphologyEx(over.view(np.uint8), cv2.MORPH_CLOSE, _SQUARE) > 0
    at = ((feet - low) / cell).astype(np.int64)
    return over[at[:, 1], at[:, 0]]
