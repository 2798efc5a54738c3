"""Cluster extraction: the object hypotheses standing on the supporting plane.

Works on the organized pixel grid (no 3-D neighbour search), on every ``stride``-th pixel and inside the bounding
box of the candidates; the clusters found are carried back to full resolution at the end:

1. candidates are the points between ``min_height`` and ``max_height`` above the plane whose foot lies inside
   the plane's extent (the convex hull of its inliers, shrunk by ``hull_margin``);
2. the grid is cut at depth discontinuities (the far pixel of each jump) and at hue edges of the colour image
   (shading-invariant, so a shaded face is not cut but touching objects of different colour are);
3. the 4-connected parts are labelled, small parts dropped and the cut pixels given back: hue-edge pixels to the
   nearest part, depth-seam pixels only to a neighbour on their own surface, so an occluder never touches what it
   hides;
4. touching parts that are pieces of one object (overlapping footprints on the plane, the inside and outside of
   a container, or a surface going on smoothly or over a convex edge across a hue edge, judged with normals on
   the grid) are joined, see :func:`annotators.geometry.grid_segmentation.merge_parts`; clusters of at least
   ``min_points`` remain.

Each hypothesis gets its flat point indices, an image mask and the ROI ``(x0, y0, x1, y1)``, x1/y1 exclusive.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.normals import grid_normals
from annotators.cloud.plane import plane_basis, plane_distances
from annotators.cloud.point_cloud import cloud_problem
from annotators.geometry.grid_kernels import label_masks, label_pixels, standing_candidates, upsampled_labels
from annotators.geometry.grid_segmentation import (
    MergeRules,
    boundaries,
    bounding_box,
    color_edges,
    depth_seams,
    grow_labels,
    grow_on_surface,
    label_parts,
    merge_parts,
)
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ObjectHypothesis, Plane, PointCloud


@dataclass(frozen=True, eq=False)
class Segment:
    """One cluster on the grid: flat point indices, an HxW mask and the ROI (x1/y1 exclusive). The mask may hold
    border pixels beyond the points (see :func:`full_resolution_segments`)."""

    indices: np.ndarray
    mask: np.ndarray
    roi: tuple[int, int, int, int]


@dataclass(frozen=True)
class ClusterParameters:
    """Thresholds of :func:`extract_clusters` (metres, pixels or 8-bit gradient units); the merge thresholds
    default to :class:`~annotators.geometry.grid_segmentation.MergeRules`'s."""

    min_height: float = 0.01
    max_height: float = 0.5
    min_points: int = 300
    hull_margin: float = 0.015
    hull_cell: float = 0.005
    jump_absolute: float = 0.01
    jump_relative: float = 0.02
    edge_low: float = 40.0
    edge_high: float = 100.0
    min_part_points: int = 40
    grow_distance: float = 6.0
    footprint_cell: float = MergeRules.cell
    footprint_overlap: float = MergeRules.overlap
    inside_tolerance: float = MergeRules.inside_tolerance
    inside_depth_ratio: float = MergeRules.inside_depth_ratio
    continuous_share: float = MergeRules.continuous
    smooth_degrees: float = 35.0
    convexity: float = MergeRules.convex
    small_part_points: int = 100
    stride: int = 2

    def merge_rules(self) -> MergeRules:
        """The thresholds of :func:`annotators.geometry.grid_segmentation.merge_parts` on the ``stride`` grid."""
        step = max(1, self.stride)
        return MergeRules(
            overlap=self.footprint_overlap,
            cell=self.footprint_cell,
            inside_tolerance=self.inside_tolerance,
            inside_depth_ratio=self.inside_depth_ratio,
            continuous=self.continuous_share,
            smooth_cosine=float(np.cos(np.radians(self.smooth_degrees))),
            convex=self.convexity,
            small_part=max(1, self.small_part_points // (step * step)),
        )


def plane_extent(plane_feet: np.ndarray, margin: float, cell: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The convex hull of the Nx2 plane coordinates ``plane_feet`` shrunk by ``margin``, rasterized with ``cell``
    metres per pixel and eroded: the raster (uint8, 1 inside; rows along the second coordinate) and the plane
    coordinates of its corner (float32), so the test of a point is one lookup. None for fewer than 3 feet."""
    if plane_feet.shape[0] < 3:
        return None
    hull = cv2.convexHull(plane_feet.astype(np.float32)).reshape(-1, 2)
    pad = round(margin / cell) + 1  # room so that erosion also shrinks the hull where it touches the raster edge
    low = hull.min(axis=0) - pad * cell
    size = np.ceil((hull.max(axis=0) - low) / cell).astype(np.int64) + pad + 1
    raster = np.zeros((int(size[1]), int(size[0])), dtype=np.uint8)
    cv2.fillConvexPoly(raster, np.round((hull - low) / cell).astype(np.int32), 1)
    if pad > 1:
        raster = cv2.erode(raster, np.ones((2 * pad - 1, 2 * pad - 1), np.uint8))
    return raster, low


def extract_clusters(
    points: np.ndarray,
    mask: np.ndarray,
    model: np.ndarray,
    plane_indices: np.ndarray,
    parameters: ClusterParameters | None = None,
    colors: np.ndarray | None = None,
) -> list[Segment]:
    """The clusters standing on the plane ``model`` (unit normal toward the camera) in an organized cloud.

    ``plane_indices`` are the plane's inliers (flat indices) and define its extent; ``colors`` (HxWx3 uint8 RGB)
    adds hue edges as cuts. The segmentation runs on every ``stride``-th pixel; the clusters are then carried
    back to full resolution. Sorted by size, largest first.
    """
    p = parameters or ClusterParameters()
    step = max(1, p.stride)
    basis = plane_basis(np.asarray(model[:3], dtype=np.float64)).T.astype(np.float32)
    coarse_points = points[::step, ::step]
    coarse = standing_region(points, mask, model, plane_indices, p)
    if not coarse.any():
        return []

    x0, y0, x1, y1 = bounding_box(coarse, margin=2)
    region = coarse[y0:y1, x0:x1]
    depth = coarse_points[y0:y1, x0:x1, 2]
    seams = depth_seams(depth, region, p.jump_absolute, p.jump_relative)
    cuts = seams
    if colors is not None:
        cuts = seams | color_edges(colors[::step, ::step][y0:y1, x0:x1], p.edge_low, p.edge_high)
    labels = label_parts(region & ~cuts, max(1, p.min_part_points // (step * step)))
    labels = grow_labels(labels, region & ~seams, p.grow_distance / step)
    labels = grow_on_surface(labels, region, depth, p.jump_absolute, p.jump_relative)
    grid = np.ascontiguousarray(coarse_points[y0:y1, x0:x1])
    surface = boundaries(labels, grid, grid_normals(grid, 1, 3), p.jump_absolute, p.jump_relative)
    crop_points = grid.reshape(-1, 3)
    to_plane = np.column_stack([basis, np.asarray(model[:3], dtype=np.float32)])
    offset = np.array([0.0, 0.0, model[3]], dtype=np.float32)
    labels = merge_parts(
        labels, depth, lambda pixels: crop_points[pixels] @ to_plane + offset, p.merge_rules(), surface
    )

    return full_resolution_segments(labels, depth, (x0, y0, x1, y1), step, points, mask, model, p)


def standing_region(
    points: np.ndarray,
    mask: np.ndarray,
    model: np.ndarray,
    plane_indices: np.ndarray,
    p: ClusterParameters,
    distances: np.ndarray | None = None,
) -> np.ndarray:
    """The candidates on every ``p.stride``-th pixel: points between ``min_height`` and ``max_height`` above the
    plane ``model`` whose foot lies inside the extent of its inliers ``plane_indices`` (shrunk by ``hull_margin``).
    ``distances``, when given, are :func:`plane_distances` of all ``points`` to ``model``, made by the caller."""
    step = max(1, p.stride)
    basis = plane_basis(np.asarray(model[:3], dtype=np.float64)).T.astype(np.float32)
    coarse_points = points[::step, ::step]
    if distances is None:
        distances = plane_distances(points, model)
    # on the whole grid, which needs no copy of strided points (each point's distance is the same either way)
    heights = np.ascontiguousarray(distances[::step, ::step])
    flat = points.reshape(-1, 3)
    plane_points = flat[plane_indices[:: max(1, plane_indices.size // 2000)]]
    plane_points = plane_points[np.isfinite(plane_points).all(axis=1)]
    extent = plane_extent(plane_points @ basis, p.hull_margin, p.hull_cell)
    if extent is None:
        return np.zeros(heights.shape, dtype=bool)
    raster, low = extent
    return standing_candidates(
        heights, mask[::step, ::step], coarse_points, basis, raster, low, p.hull_cell, p.min_height, p.max_height
    )


def full_resolution_segments(
    labels: np.ndarray,
    coarse_depth: np.ndarray,
    box: tuple[int, int, int, int],
    step: int,
    points: np.ndarray,
    mask: np.ndarray,
    model: np.ndarray,
    p: ClusterParameters,
    refine: Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray] | None = None,
    claimed: np.ndarray | None = None,
    distances: np.ndarray | None = None,
) -> list[Segment]:
    """Segments on the full grid from coarse labels of the region ``box`` (coarse pixels, x1/y1 exclusive).

    A pixel takes the label of its coarse cell when it is a candidate itself and lies on the same surface as
    the cell's sample (no depth jump), so silhouettes do not bleed onto what is behind them. ``refine(labels,
    points, heights, candidates)``, when given, revises the full-resolution labels of the region before the segments
    are cut (HxW labels, HxWx3 points, HxW heights above the plane and candidate mask of the region): the pixels
    it adds join the segments' masks and ROIs (their image regions) but not their point indices, so the 3-D experts
    measure the points the segmentation labelled itself, away from the mixed pixels of an outline and the band
    where an object meets the plane. Which segments are large enough (``min_points``) is judged before refining,
    so refining never adds one. ``claimed`` (coarse, the region's shape), when given, marks the cells labelled
    though no candidates (a container's floor at table level): their measured pixels count as candidates.
    ``distances``, when given, are :func:`plane_distances` of all ``points`` to ``model``, made by the caller.
    """
    rows, cols = mask.shape
    x0, y0, x1, y1 = box
    fy0, fx0 = y0 * step, x0 * step
    fy1, fx1 = min(y1 * step, rows), min(x1 * step, cols)
    fine_points = points[fy0:fy1, fx0:fx1]
    if distances is None:
        distances = plane_distances(points, model)  # of the whole grid: no copy of the region's points
    heights = np.ascontiguousarray(distances[fy0:fy1, fx0:fx1])
    candidates = _between_heights(heights, mask[fy0:fy1, fx0:fx1], p)
    if claimed is not None and claimed.any():
        spread = np.repeat(np.repeat(claimed, step, axis=0), step, axis=1)[: fy1 - fy0, : fx1 - fx0]
        candidates |= spread & mask[fy0:fy1, fx0:fx1] & np.isfinite(heights)
    core = upsampled_labels(  # the pixels the segmentation labelled itself: the point indices
        labels, coarse_depth, fine_points[..., 2], candidates, step, p.jump_absolute, p.jump_relative
    )
    # flat indices of the whole grid, sorted by label
    core_indices, core_starts, _ = label_pixels(core, (fy0, fx0), cols)
    sizes = np.diff(core_starts)
    kept = [label for label in range(1, sizes.size) if sizes[label] >= p.min_points]  # judged before refining
    refined = core if refine is None else refine(core, fine_points, heights, candidates)
    masks, boxes = label_masks(refined, kept, (fy0, fx0), (rows, cols))
    segments = []
    for object_mask, label, (left, top, right, bottom) in zip(masks, kept, boxes.tolist(), strict=True):
        indices = core_indices[core_starts[label] : core_starts[label + 1]]
        roi = (left + fx0, top + fy0, right + fx0, bottom + fy0)
        segments.append(Segment(indices=indices, mask=object_mask, roi=roi))
    segments.sort(key=lambda s: -s.indices.size)
    return segments


def _between_heights(heights: np.ndarray, mask: np.ndarray, p: ClusterParameters) -> np.ndarray:
    """The pixels of ``mask`` whose ``heights`` above the plane lie between ``min_height`` and ``max_height``."""
    with np.errstate(invalid="ignore"):
        return mask & (heights > p.min_height) & (heights < p.max_height)


def plane_problem(model: np.ndarray) -> str | None:
    """Why a plane model cannot be used (wrong shape, not finite, no unit normal), or None."""
    model = np.asarray(model, dtype=np.float64)
    if model.shape != (4,) or not np.all(np.isfinite(model)):
        return f"plane model must be 4 finite numbers, got {model!r}"
    if not 0.99 < np.linalg.norm(model[:3]) < 1.01:
        return f"plane normal is not a unit vector: {model[:3]}"
    return None


def supporting_plane(cloud: PointCloud, planes: list[Plane]) -> tuple[np.ndarray, np.ndarray] | str:
    """The model and inlier indices of the largest plane, checked against ``cloud``; or why the cloud or the
    planes cannot be segmented (the shared input checks of the depth segmenters)."""
    problem = cloud_problem(cloud)
    if problem:
        return problem
    if not planes:
        return "no supporting Plane in the CAS"
    plane = max(planes, key=lambda candidate: np.asarray(candidate.inlier_indices).size)
    problem = plane_problem(plane.model)
    if problem:
        return problem
    inliers = np.asarray(plane.inlier_indices)
    if inliers.size < 3 or inliers.min() < 0 or inliers.max() >= cloud.mask.size:
        return f"the plane has {inliers.size} inliers or indices outside the {cloud.shape} grid"
    return np.asarray(plane.model, dtype=np.float64), inliers


class ClusterExtractor(Annotator):
    """Segments the points standing on the supporting plane into object hypotheses (one per cluster)."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis,)
    capability: ClassVar[Capability] = Capability(
        label="cluster extractor",
        preconditions=("NeedsDepth", "NotForTransparentObjects"),
        cost_ms=30.0,
        reliability=0.85,
    )

    def __init__(
        self,
        min_height: float = 0.01,
        max_height: float = 0.5,
        min_points: int = 300,
        use_color: bool = True,
        name: str | None = None,
        **thresholds: float,
    ) -> None:
        """``thresholds`` sets any other field of :class:`ClusterParameters`."""
        super().__init__(name=name)
        self.parameters = ClusterParameters(
            min_height=min_height, max_height=max_height, min_points=min_points, **thresholds
        )
        self.use_color = use_color

    def analyse(self) -> None:
        """Write one ObjectHypothesis per cluster; fail when the inputs are unusable or nothing stands there."""
        cloud = self.view(PointCloud)
        support = supporting_plane(cloud, self.annotations(Plane))
        if isinstance(support, str):
            self.fail(support)
        model, inliers = support
        colors = cloud.colors if self.use_color else None
        if colors is not None and colors.shape[:2] != cloud.shape:
            self.fail(f"the cloud's colours {colors.shape} do not match its grid {cloud.shape}")
        segments = extract_clusters(cloud.points, cloud.mask, model, inliers, self.parameters, colors)
        if not segments:
            self.fail("no object cluster stands on the supporting plane")
        for segment in segments:
            self.write(ObjectHypothesis(point_indices=segment.indices, mask=segment.mask, roi=segment.roi))
