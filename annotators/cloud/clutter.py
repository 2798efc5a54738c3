"""Clutter segmentation: objects as convexly connected surfaces, cut at depth jumps and concave creases.

Works like :mod:`annotators.cloud.clusters` on every ``stride``-th pixel of the organized grid, with different cuts:

1. candidates are the points standing on the supporting plane (inside its extent), as for the cluster extractor;
2. the grid is cut at depth discontinuities and at concave creases (:func:`annotators.geometry.convexity.
   concave_creases`): where a can stands on a box or a box leans on another, the surfaces fold inward, while the
   faces of one object meet at convex edges and need no cut. Colour is not used, so a printed box is one part;
3. the parts are labelled and the cut pixels given back, then touching parts are joined when the surface goes on
   smoothly or over a convex edge across their boundary, or when one is the inside of the other (a bowl), see
   :func:`annotators.geometry.grid_segmentation.merge_parts` (without its footprint rule, which would join
   stacked objects);
4. parts that an occluder in front splits apart are joined when they continue one surface behind it
   (:func:`annotators.geometry.occlusion.join_occluded`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from annotators.cloud.clusters import (
    ClusterParameters,
    Segment,
    full_resolution_segments,
    plane_problem,
    standing_region,
)
from annotators.cloud.normals import grid_normals
from annotators.cloud.plane import plane_basis
from annotators.cloud.point_cloud import cloud_problem
from annotators.geometry.convexity import ConvexityRules, convex_groups, grid_patches, split_by_normals
from annotators.geometry.grid_segmentation import (
    MergeRules,
    bounding_box,
    color_edges,
    depth_seams,
    grow_labels,
    grow_on_surface,
    label_parts,
    merge_parts,
)
from annotators.geometry.occlusion import OcclusionRules, join_occluded
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ObjectHypothesis, Plane, PointCloud


@dataclass(frozen=True)
class ClutterParameters(ClusterParameters):
    """Thresholds of :func:`segment_clutter`: those of the cluster extractor (candidates, depth jumps, merging)
    plus the patches (``cell`` x ``cell`` coarse pixels, at least ``min_patch`` points for a plane) and the
    concavity at which two patches are cut apart."""

    cell: int = 6
    min_patch: int = 6
    concavity: float = 0.17
    use_color_edges: bool = False
    normal_step: int = 2
    normal_smoothing: int = 3
    normal_spread: float = 0.15
    smooth_degrees: float = 20.0
    convex_share: float = 0.5
    complete_occluded: bool = True
    gap_width: float = 2.0
    close_factor: float = 3.0

    def convexity_rules(self) -> ConvexityRules:
        """The thresholds of :func:`annotators.geometry.convexity.convex_groups`."""
        return ConvexityRules(
            smooth_degrees=self.smooth_degrees,
            concavity=self.concavity,
            convex_share=self.convex_share,
            min_patch=self.min_patch,
            gap_width=self.gap_width,
            close_factor=self.close_factor,
        )

    def merge_rules(self) -> MergeRules:
        """The cluster extractor's merge rules without the footprint rule (stacked objects share footprints)."""
        return replace(super().merge_rules(), overlap=2.0)


def segment_clutter(
    points: np.ndarray,
    mask: np.ndarray,
    model: np.ndarray,
    plane_indices: np.ndarray,
    parameters: ClutterParameters | None = None,
    colors: np.ndarray | None = None,
) -> list[Segment]:
    """The objects standing on the plane ``model`` (unit normal toward the camera) in an organized cloud, largest
    first; ``plane_indices`` are the plane's inliers (flat indices) and define its extent."""
    p = parameters or ClutterParameters()
    step = max(1, p.stride)
    coarse = standing_region(points, mask, model, plane_indices, p)
    if not coarse.any():
        return []
    x0, y0, x1, y1 = bounding_box(coarse, margin=2)
    region = coarse[y0:y1, x0:x1]
    grid = np.ascontiguousarray(points[::step, ::step][y0:y1, x0:x1])
    depth = grid[..., 2]
    seams = depth_seams(depth, region, p.jump_absolute, p.jump_relative)
    cuts = seams
    if colors is not None and p.use_color_edges:
        cuts = cuts | color_edges(colors[::step, ::step][y0:y1, x0:x1], p.edge_low, p.edge_high)
    normals = grid_normals(grid, p.normal_step, p.normal_smoothing, p.jump_absolute, p.jump_relative)
    surfaces = label_parts(region & ~cuts, 1)
    patches = split_by_normals(grid_patches(surfaces, p.cell), normals, p.normal_spread)
    labels, faces = convex_groups(patches, grid, p.convexity_rules(), region & ~seams)
    labels = grow_labels(labels, region & ~seams, p.grow_distance / step)
    labels = grow_on_surface(labels, region, depth, p.jump_absolute, p.jump_relative)
    basis = plane_basis(np.asarray(model[:3], dtype=np.float64)).T.astype(np.float32)
    to_plane = np.column_stack([basis, np.asarray(model[:3], dtype=np.float32)])
    offset = np.array([0.0, 0.0, model[3]], dtype=np.float32)
    crop_points = grid.reshape(-1, 3)
    labels = merge_parts(labels, depth, lambda pixels: crop_points[pixels] @ to_plane + offset, p.merge_rules())
    if p.complete_occluded:
        labels = join_occluded(labels, faces, grid, p.jump_absolute, p.jump_relative, OcclusionRules())
    return full_resolution_segments(labels, depth, (x0, y0, x1, y1), step, points, mask, model, p)


class ClutterSegmenter(Annotator):
    """Segments touching, stacked and occluding objects on the supporting plane into object hypotheses: convexly
    connected surfaces, cut at depth jumps and concave creases (model-free, geometry only)."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis,)
    capability: ClassVar[Capability] = Capability(
        label="clutter segmenter",
        synonyms=("convexity segmenter",),
        preconditions=("NeedsDepth", "NotForTransparentObjects"),
        cost_ms=30.0,
        reliability=0.9,
    )

    def __init__(self, name: str | None = None, **thresholds: float) -> None:
        """``thresholds`` sets any field of :class:`ClutterParameters`."""
        super().__init__(name=name)
        self.parameters = ClutterParameters(**thresholds)

    def analyse(self) -> None:
        """Write one ObjectHypothesis per object; fail when the inputs are unusable or nothing stands there."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        planes = self.annotations(Plane)
        if not planes:
            self.fail("no supporting Plane in the CAS")
        plane = max(planes, key=lambda candidate: np.asarray(candidate.inlier_indices).size)
        problem = plane_problem(plane.model)
        if problem:
            self.fail(problem)
        inliers = np.asarray(plane.inlier_indices)
        if inliers.size < 3 or inliers.min() < 0 or inliers.max() >= cloud.mask.size:
            self.fail(f"the plane has {inliers.size} inliers or indices outside the {cloud.shape} grid")
        model = np.asarray(plane.model, dtype=np.float64)
        segments = segment_clutter(cloud.points, cloud.mask, model, inliers, self.parameters, cloud.colors)
        if not segments:
            self.fail("no object stands on the supporting plane")
        for segment in segments:
            self.write(ObjectHypothesis(point_indices=segment.indices, mask=segment.mask, roi=segment.roi))
