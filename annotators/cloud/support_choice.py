"""Which of several horizontal surfaces is the support: the one the objects stand on.

The dominant plane of a view is the largest flat surface in it. Looking down at a table it is the table; a
mobile robot's head camera looking at a desk from a few metres away sees more floor than desk, and the dominant
plane is the floor. What a person means by "the table" is the surface the things are on: a raised surface
parallel to the dominant one, with objects standing on it, rather than the floor the table itself stands on.

So the dominant plane is one candidate, and every surface parallel to it raised above it by more than the tallest
graspable object, holding a sizeable share of the view's points (a peak of the heights above the dominant plane,
refitted by RANSAC among the points of that peak), is another: furniture, not the top of a box standing on the
table. Each is scored by what stands on it: the separate object-like clusters rising from it (points from just
above it up to the height of a graspable object, over its surface's convex footprint, split where the depth
jumps, and not going on higher - a chair's column or a table's leg is part of something larger). The highest raised
surface carrying at least one such cluster and at least as many as the dominant plane is the support; else the
dominant plane stays. The search costs one height pass over a coarse grid when there is no raised surface, as on
every view looking down at a table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.plane import (
    MIN_PLANE_POINTS,
    PlaneFit,
    plane_basis,
    plane_distances,
    ransac_support_plane,
    up_in_camera,
)
from annotators.cloud.point_cloud import cloud_problem
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, Plane, PointCloud


@dataclass(frozen=True)
class SupportChoiceRules:
    """How raised candidate surfaces are found and scored.

    ``step``: the coarse grid (every ``step``-th row and column) heights are read on; ``bin``: the width (metres)
    of the height histogram a raised surface shows up as a peak in, holding at least ``min_points`` coarse points;
    ``min_area``: the area (square metres) a raised surface must cover, room for a few objects; ``max_candidates``:
    the raised peaks tried, the fullest first; ``lift``: the height (metres) above a surface from which a point
    belongs to something standing on it (above its noise band); ``object_height``: the tallest graspable object
    (metres) - points higher above a surface belong to something else (the table above the floor, a wall), and a
    raised surface is furniture only above it;
    ``jump_absolute`` and ``jump_relative``: a depth step between coarse neighbours of more than ``jump_absolute +
    jump_relative * depth`` separates clusters; ``min_cluster``: the coarse pixels of an object-like cluster;
    ``cell``: the raster cell (metres) of a surface's footprint."""

    step: int = 2
    bin: float = 0.02
    min_points: int = 50
    min_area: float = 0.1
    max_candidates: int = 3
    lift: float = 0.02
    object_height: float = 0.5
    jump_absolute: float = 0.02
    jump_relative: float = 0.02
    min_cluster: int = 20
    cell: float = 0.02


def raised_peaks(heights: np.ndarray, rules: SupportChoiceRules) -> list[float]:
    """The heights (metres) of the histogram peaks of ``heights`` (finite, above the dominant plane) above
    ``object_height``, each holding at least ``min_points`` of them, at most ``max_candidates`` (the fullest)."""
    raised = heights[heights > rules.object_height]
    if raised.size < rules.min_points:
        return []
    counts = np.bincount((raised / rules.bin).astype(np.int64))
    # a surface fitted with a slight tilt or noise spreads over two neighbouring bins: count them together
    pairs = counts + np.append(counts[1:], 0)
    peaks = [
        int(k)
        for k in np.argsort(-pairs, kind="stable")
        if pairs[k] >= rules.min_points
        and pairs[k] >= (pairs[k - 1] if k > 0 else 0)
        and pairs[k] >= (pairs[k + 1] if k + 1 < pairs.size else 0)
    ]
    return [(k + 1.0) * rules.bin for k in peaks[: rules.max_candidates]]


def surface_area(surface: np.ndarray, normal: np.ndarray, cell: float) -> float:
    """The area (square metres) the Nx3 ``surface`` points cover on a ``cell`` raster of the plane with unit
    ``normal``: their occupied cells."""
    basis = plane_basis(np.asarray(normal, dtype=np.float64)).astype(np.float32)
    cells = np.floor(surface @ basis.T / cell).astype(np.int64)
    if cells.shape[0] == 0:
        return 0.0
    cells -= cells.min(axis=0)
    keys = cells[:, 0] * (int(cells[:, 1].max()) + 1) + cells[:, 1]
    return float(np.unique(keys).size * cell * cell)


def grid_points(points: np.ndarray, indices: np.ndarray, shape: tuple[int, int], step: int) -> np.ndarray:
    """The points (Nx3) of the coarse grid ``points`` (every ``step``-th row and column of a grid of ``shape``) at
    those of the flat full-grid ``indices`` that lie on it."""
    rows, cols = indices // shape[1], indices % shape[1]
    on_grid = (rows % step == 0) & (cols % step == 0)
    return points[rows[on_grid] // step, cols[on_grid] // step]


def standing_clusters(
    points: np.ndarray, valid: np.ndarray, model: np.ndarray, surface: np.ndarray, rules: SupportChoiceRules
) -> tuple[np.ndarray, list[int]]:
    """The object-like clusters standing on the plane ``model`` whose visible surface is ``surface`` (Nx3), as a
    label image of the (coarse) grid ``points`` and the labels that count: connected pieces of the ``valid``
    points from ``lift`` to ``object_height`` above the plane, over the convex footprint of ``surface``, split at
    depth jumps, of at least ``min_cluster`` pixels, that do not go on above ``object_height`` (a table's leg, a
    chair's column, a wall)."""
    if surface.shape[0] < 3:
        return np.zeros(points.shape[:2], dtype=np.int32), []
    heights = plane_distances(points, model)
    with np.errstate(invalid="ignore"):
        standing = valid & (heights > rules.lift) & (heights <= rules.object_height)
    basis = plane_basis(np.asarray(model[:3], dtype=np.float64)).astype(np.float32)
    feet = surface @ basis.T
    low = feet.min(axis=0)
    hull = np.round((cv2.convexHull(feet.astype(np.float32)).reshape(-1, 2) - low) / rules.cell).astype(np.int64)
    over = points[standing] @ basis.T
    cells = np.round((over - low) / rules.cell).astype(np.int64)
    # the footprint is drawn only where standing points fall (a stray inlier far off spans no raster)
    inside = np.zeros(cells.shape[0], dtype=bool)
    if cells.shape[0]:
        start = np.maximum(hull.min(axis=0), cells.min(axis=0))
        end = np.minimum(hull.max(axis=0), cells.max(axis=0)) + 1
        inside = np.all((cells >= start) & (cells < end), axis=1)
    if inside.any():
        size = end - start
        raster = np.zeros((int(size[1]), int(size[0])), dtype=np.uint8)
        cv2.fillConvexPoly(raster, (hull - start).astype(np.int32), 1)
        inside[inside] = raster[cells[inside, 1] - start[1], cells[inside, 0] - start[0]] > 0
    standing[standing] = inside
    depth = points[..., 2]
    with np.errstate(invalid="ignore"):
        limit = rules.jump_absolute + rules.jump_relative * depth
        jump_right = np.abs(np.diff(depth, axis=1)) > limit[:, 1:]
        jump_down = np.abs(np.diff(depth, axis=0)) > limit[1:]
    edges = np.zeros_like(standing)
    edges[:, :-1] |= jump_right
    edges[:, 1:] |= jump_right
    edges[:-1] |= jump_down
    edges[1:] |= jump_down
    _, labels, stats, _ = cv2.connectedComponentsWithStats((standing & ~edges).view(np.uint8), connectivity=4)
    large = stats[:, cv2.CC_STAT_AREA] >= rules.min_cluster
    large[0] = False
    # a cluster that goes on above the tallest object without a depth jump is part of something larger
    with np.errstate(invalid="ignore"):
        tall = (valid & (heights > rules.object_height) & ~edges).view(np.uint8)
    capped = labels[cv2.dilate(tall, np.ones((3, 3), np.uint8)) > 0]
    large[capped] = False
    return labels, np.flatnonzero(large).tolist()


def choose_support(
    points: np.ndarray,
    mask: np.ndarray,
    dominant: PlaneFit,
    distance: float = 0.01,
    max_tilt_degrees: float = 20.0,
    seed: int = 0,
    rules: SupportChoiceRules | None = None,
) -> PlaneFit:
    """The support among ``dominant`` (the dominant plane of the HxWx3 ``points`` under ``mask``) and the surfaces
    parallel to it raised above it by more than ``object_height`` (furniture, not the top of an object standing on
    it): the highest raised one with at least one object-like cluster on it and at least as many as ``dominant``
    has, else ``dominant``. Candidates are fitted on the coarse grid, the chosen one again on the whole grid."""
    rules = rules or SupportChoiceRules()
    step = rules.step
    # first on a grid twice as coarse: a view looking down at a table has next to nothing that high above it
    sparse = np.ascontiguousarray(points[:: 2 * step, :: 2 * step], dtype=np.float32)
    with np.errstate(invalid="ignore"):
        high = mask[:: 2 * step, :: 2 * step] & (plane_distances(sparse, dominant.model) > rules.object_height)
    if np.count_nonzero(high) < rules.min_points // 4:
        return dominant
    coarse = np.ascontiguousarray(points[::step, ::step], dtype=np.float32)
    with np.errstate(invalid="ignore"):
        valid = mask[::step, ::step] & np.isfinite(coarse[..., 2])
    heights = plane_distances(coarse, dominant.model)
    peaks = raised_peaks(heights[valid], rules)
    if not peaks:
        return dominant
    surface = grid_points(coarse, dominant.inlier_indices, mask.shape, step)
    needed = max(1, len(standing_clusters(coarse, valid, dominant.model, surface, rules)[1]))
    up = np.asarray(dominant.model[:3], dtype=np.float64)
    for peak in sorted(peaks, reverse=True):
        with np.errstate(invalid="ignore"):
            band = valid & (np.abs(heights - peak) <= 2 * rules.bin)
        fit = ransac_support_plane(coarse, band, distance=distance, seed=seed, up=up, max_tilt_degrees=max_tilt_degrees)
        if fit is None:
            continue
        raised = coarse.reshape(-1, 3)[fit.inlier_indices]
        if surface_area(raised, fit.model[:3], rules.cell) < rules.min_area:
            continue
        if len(standing_clusters(coarse, valid, fit.model, raised, rules)[1]) < needed:
            continue
        with np.errstate(invalid="ignore"):
            full_band = mask & (np.abs(plane_distances(points, fit.model)) <= 2 * rules.bin)
        chosen = ransac_support_plane(
            points, full_band, distance=distance, seed=seed, up=up, max_tilt_degrees=max_tilt_degrees
        )
        if chosen is not None:
            return chosen
    return dominant


def find_support_plane(
    points: np.ndarray,
    mask: np.ndarray,
    distance: float = 0.01,
    iterations: int = 400,
    seed: int = 0,
    up: np.ndarray | None = None,
    max_tilt_degrees: float = 20.0,
    rules: SupportChoiceRules | None = None,
) -> PlaneFit | None:
    """The support plane of the organized cloud's masked points: the dominant (upward, when ``up`` is given)
    plane of :func:`~annotators.cloud.plane.ransac_support_plane`, or a raised surface parallel to it that the
    objects stand on (:func:`choose_support`); None when there is no plane."""
    dominant = ransac_support_plane(
        points, mask, distance=distance, iterations=iterations, seed=seed, up=up, max_tilt_degrees=max_tilt_degrees
    )
    if dominant is None:
        return None
    return choose_support(points, mask, dominant, distance, max_tilt_degrees, seed, rules)


class SupportPlaneSegmenter(Annotator):
    """Finds the supporting plane (table, shelf): the dominant roughly horizontal plane when the camera pose is
    known, else the dominant plane, or a raised surface parallel to it that carries the objects (a desk above the
    floor, :mod:`~annotators.cloud.support_choice`); its normal points toward the camera."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Plane,)
    capability: ClassVar[Capability] = Capability(
        label="support plane segmenter",
        cost_ms=25.0,
        reliability=0.9,
    )

    def __init__(
        self,
        distance: float = 0.01,
        iterations: int = 400,
        seed: int = 0,
        max_tilt_degrees: float = 20.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.distance = distance
        self.iterations = iterations
        self.seed = seed
        self.max_tilt_degrees = max_tilt_degrees

    def analyse(self) -> None:
        """Fit the plane and write it; fail when no plane is supported by enough points."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        up = up_in_camera(self.optional_view(CameraInfo))
        fit = find_support_plane(
            cloud.points,
            cloud.mask,
            distance=self.distance,
            iterations=self.iterations,
            seed=self.seed,
            up=up,
            max_tilt_degrees=self.max_tilt_degrees,
        )
        if fit is None:
            kind = "roughly horizontal plane" if up is not None else "plane"
            self.fail(f"no {kind} with at least {MIN_PLANE_POINTS} inliers within {self.distance} m")
        self.write(Plane(model=fit.model, inlier_indices=fit.inlier_indices, source=self.name))
