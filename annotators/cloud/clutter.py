"""Clutter segmentation: objects as convexly connected surfaces, on the organized grid.

Works like :mod:`annotators.cloud.clusters` on every ``stride``-th pixel of the organized grid, with other cuts:

1. candidates are the points standing on the supporting plane (inside its extent), as for the cluster extractor;
2. they are cut at depth discontinuities and into cells, split where their normals disagree; each cell gets a
   plane fit, cells join into smooth faces and faces into objects where they meet convexly - where a can stands on
   a box or a box leans on another the surfaces fold inward and stay apart
   (:func:`annotators.geometry.convexity.convex_objects`); colour plays no part, so a printed box is one object;
3. the cut pixels are given back, and a container's inside joins its outside (a handle its body): the footprints on
   the plane overlap and the heights nest, which an object standing on another never does
   (:func:`annotators.geometry.grid_segmentation.merge_parts`; with and without the few pixels whose label was
   grown across an object's outline onto another's surface) - nor one standing in a container and rising above its
   rim, whose inner wall's heights lie within its own (:func:`annotators.geometry.rims.one_stands_inside`);
4. an object is split along a hue edge only where a concave crease runs along it (:func:`split_by_color`: a can
   standing flush on a can is one convex surface but two colours with a crease between);
5. pieces that an occluder in front splits apart join when they continue one plane behind it, even where they meet
   at a corner beyond its end (:func:`annotators.geometry.occlusion.join_occluded`);
6. a piece that could not stand by itself - smaller than a neighbour whose footprint holds much of its own, not
   reaching the table and reaching down too far into the neighbour's heights to rest on its top - joins it: the
   inside of a mug seen over its rim, cut off with the rim and the handle along the inner wall's concave fold
   (:func:`annotators.geometry.support.join_unsupported`); such a piece that two neighbours hold only together,
   the three touching one another in 3-D, joins both: a mug cut in three, its inside lying half over its front
   and half over its side with the handle (:func:`annotators.geometry.support.join_jointly_held`); a piece a
   quarter of a neighbour's size or less that touches it in 3-D along most of their shared border and lies within
   its heights joins it too: a drill's chuck cut off at the concave fold where it leaves the body
   (:func:`annotators.geometry.support.join_appendages`); and such a piece touching a neighbour in 3-D whose wall
   is concave toward the camera around an axis inside the two's footprint joins it: the far inner wall of a mug
   seen over its rim, whose footprint is the back arc of the ring the outside's front arc starts
   (:func:`annotators.geometry.inner_walls.join_inner_walls`);
7. the inner wall of an open container that an object standing in it cuts into pieces on both sides joins again
   where the pieces' top edges lie on one rim circle at one height, with the outer wall below the front rim
   within that circle; the object rising above the rim stays apart, and no piece standing inside a container is
   joined to it as unable to stand by itself (:func:`annotators.geometry.rims.join_rim_pieces`);
8. touching pieces that fill one slab - their lowest heights and tops (on the pixels the convexity votes
   labelled, not those grown to them) agree, no depth jump along most of their shared border - join: a drill lying
   on its side, cut where its grip ends behind the battery's raised edge
   (:func:`annotators.geometry.slabs.join_slab_pieces`);
9. the pieces of a tinted transparent object - touching in the image, one saturated hue, and pixels of that hue
   without depth inside their joint outline - join: a blue water bottle the projector's pattern passes, read in
   pieces at the depths of its front, its water and the table
   (:func:`annotators.geometry.transparency.join_see_through`);
10. the floor of an open container seen from above - within ``min_height`` of the plane, so no candidate - joins
   the container whose footprint holds it, that surrounds it in the image on three sides at least and that does
   not hang over it
   (:func:`annotators.geometry.container_floors.claim_container_floors`); the floor's bits that the noise lifted
   above ``min_height`` then touch their container and join it as pieces that cannot stand by themselves;
11. at full resolution, the outline pixels the coarse grid left unlabelled and the foot below the candidates'
   lowest height join the object whose surface they continue
   (:func:`annotators.geometry.border_pixels.claim_border_pixels`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from functools import partial
from typing import ClassVar

import numpy as np

from annotators.cloud.clusters import (
    ClusterParameters,
    Segment,
    full_resolution_segments,
    standing_region,
    supporting_plane,
)
from annotators.cloud.normals import grid_normals
from annotators.cloud.plane import plane_basis, plane_distances
from annotators.geometry.border_pixels import BorderRules, claim_border_pixels, plane_noise
from annotators.geometry.container_floors import FloorRules, claim_container_floors, touches_other_labels
from annotators.geometry.convexity import ConvexityRules, convex_objects, dense_labels, grid_patches, split_by_normals
from annotators.geometry.flat_patches import flat_patches
from annotators.geometry.grid_kernels import groups_unless_apart, object_pieces, plane_coordinates, strided_crop
from annotators.geometry.grid_segmentation import (
    MergeRules,
    boundaries,
    bounding_box,
    chroma_edges,
    chroma_image,
    depth_seams,
    grow_labels_nearby,
    grow_on_surface,
    label_parts,
    merge_parts,
)
from annotators.geometry.inner_walls import InnerWallRules, join_inner_walls
from annotators.geometry.necks import NeckRules, join_necked_pieces
from annotators.geometry.occlusion import OcclusionRules, join_occluded
from annotators.geometry.rims import RimRules, join_rim_pieces, join_single_rims, one_stands_inside
from annotators.geometry.slabs import SlabRules, join_slab_pieces
from annotators.geometry.support import (
    FOOTPRINT_ROWS,
    AppendageRules,
    JointRules,
    SupportRules,
    join_pieces,
    join_pieces_summarized,
    summarize_pieces,
)
from annotators.geometry.support_kernels import pixel_footprint
from annotators.geometry.transparency import TransparencyRules, join_see_through
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ObjectHypothesis, Plane, PointCloud

REFERENCE_FOCAL = 570.0
"""Focal length (pixels) of the camera the segmenter's pixel thresholds are stated for: between a Kinect's (525) and
a RealSense D400's colour camera at 640x480 (613), the cameras it was developed on; both keep the stride of 2."""


CAMERA_ROWS = 16
"""About this many rows of the cloud, evenly spread, tell the angle between its pixels (the camera's, on every row)."""


def nearest_stride(ideal: float) -> int:
    """The whole stride (at least 1) nearest ``ideal`` by ratio: a scale is as far off at half as at twice, so
    between ``k`` and ``k + 1`` the choice turns at their geometric mean."""
    low = max(1, math.floor(ideal))
    return low + 1 if ideal > math.sqrt(low * (low + 1)) else low


@dataclass(frozen=True)
class ClutterParameters(ClusterParameters):
    """Thresholds of :func:`segment_clutter`: those of the cluster extractor (candidates, depth jumps, hue edges,
    merging), the normals (``normal_step`` / ``normal_smoothing`` coarse pixels), the patches (``cell`` x ``cell``
    coarse pixels, split when their normals spread by more than ``normal_spread``; with ``grown_patches`` grown from
    seeds ``patch_spacing`` apart instead, :func:`~annotators.geometry.flat_patches.flat_patches` with the normal
    weight ``patch_weight`` and the height term on the depth-jump scale ``jump_relative``: the same patches wherever
    the crop starts, bench/profiles/seg9-analysis.txt; their patches seen more than ``grazing_degrees`` from the line of
    sight cast no convex vote where they bend inward), the grouping
    (:class:`~annotators.geometry.convexity.ConvexityRules`) and the share of a boundary that must be creased for a
    hue edge to split an object (``creased_share``); ``join_unsupported`` joins the pieces that could not stand by
    themselves to the object that holds them, ``join_jointly_held`` those two touching neighbours hold only
    together, and ``join_appendages`` the small pieces sticking out of a larger one;
    ``join_inner_walls`` joins an open container's inside seen over its rim to its outside;
    ``join_rims`` joins the pieces of one open container's rim that an object standing in it cuts apart, and its
    outer wall below the rim;
    ``join_slabs`` joins touching pieces of one slab (same lowest heights and tops, no depth jump between them);
    ``join_necks`` joins a piece standing on another on a narrow neck to it (one rigid body);
    ``join_see_through`` joins the pieces of a tinted transparent object (one hue, depth holes of that hue inside);
    ``claim_floors`` gives an open container the floor seen over its rim, at table level;
    ``claim_borders`` gives the outline pixels the coarse grid
    left unlabelled and each object's foot (below ``min_height``) to the object they continue. Pixel thresholds are
    stated for a camera of focal length ``reference_focal`` and scaled to the camera seen (:meth:`for_camera`)."""

    jump_relative: float = 0.01
    normal_step: int = 2
    normal_smoothing: int = 3
    cell: int = 6
    normal_spread: float = 0.15
    grown_patches: bool = False
    patch_spacing: int = 5
    patch_weight: float = 8.0
    grazing_degrees: float = 70.0
    smooth_degrees: float = ConvexityRules.smooth_degrees
    concave_bending: float = ConvexityRules.concave_bending
    convex_share: float = ConvexityRules.convex_share
    concave_share: float = ConvexityRules.concave_share
    min_patch: int = ConvexityRules.min_patch
    max_thickness: float = ConvexityRules.max_thickness
    min_width: float = ConvexityRules.min_width
    min_face: int = ConvexityRules.min_face
    min_votes: int = ConvexityRules.min_votes
    gap_width: float = ConvexityRules.gap_width
    close_factor: float = ConvexityRules.close_factor
    crease_degrees: float = ConvexityRules.crease_degrees
    decisive_bending: float = ConvexityRules.decisive_bending
    object_points: float = ConvexityRules.object_points
    creased_share: float = 0.2
    use_color: bool = True
    complete_occluded: bool = True
    join_unsupported: bool = True
    join_appendages: bool = True
    join_jointly_held: bool = True
    join_inner_walls: bool = True
    join_rims: bool = True
    join_slabs: bool = True
    join_necks: bool = True
    join_see_through: bool = True
    claim_floors: bool = True
    claim_borders: bool = True
    reference_focal: float = REFERENCE_FOCAL

    def for_camera(self, pixel_angle: float) -> ClutterParameters:
        """These parameters for a camera whose neighbouring pixels lie ``pixel_angle`` radians apart (1 / its
        focal length in pixels). Every pixel threshold is stated for a camera of focal length ``reference_focal``.
        On a camera that sees finer or coarser, the grid's stride scales with the focal length
        (:func:`nearest_stride`), so the grid sees the same angles, and the pixel counts and distances given at
        full resolution (``min_points``, ``min_part_points``, ``small_part_points``, ``grow_distance``) scale with
        the stride: the same objects, measured in grid pixels, whatever the image's size. Unchanged when
        ``reference_focal`` is 0, the angle unknown (0) or the stride comes out the same."""
        if self.reference_focal <= 0.0 or not pixel_angle > 0.0:
            return self
        reference = max(1, self.stride)
        step = nearest_stride(reference / (pixel_angle * self.reference_focal))
        if step == reference:
            return self
        length = step / reference
        area = length * length
        return replace(
            self,
            stride=step,
            min_points=max(1, round(self.min_points * area)),
            min_part_points=max(1, round(self.min_part_points * area)),
            small_part_points=max(1, round(self.small_part_points * area)),
            grow_distance=self.grow_distance * length,
        )

    def convexity_rules(self) -> ConvexityRules:
        """The thresholds of :func:`annotators.geometry.convexity.convex_objects`. With grown patches two small
        faces join on a weak vote only as one's best neighbour (``small_joins_once``), and a grazing patch's
        inward bend casts no convex vote (``grazing_degrees``): grown patches follow the data, so the stereo depth
        ramp at an occluding edge is a patch of its own, where the grid's cells average it into the faces beside
        it."""
        names = [f.name for f in fields(ConvexityRules) if f.name not in ("small_joins_once", "grazing_degrees")]
        grown = self.grown_patches
        return ConvexityRules(
            **{n: getattr(self, n) for n in names},
            small_joins_once=grown,
            grazing_degrees=self.grazing_degrees if grown else None,
        )

    def appendage_rules(self) -> AppendageRules:
        """The thresholds of :func:`annotators.geometry.support.join_appendages`: the merge rules' share of a
        border that must be close and its length, their height slack, and the depth jumps."""
        rules = self.merge_rules()
        return AppendageRules(
            close_share=rules.continuous,
            boundary_share=rules.boundary_share,
            min_boundary=rules.min_boundary,
            tolerance=rules.nest_tolerance,
            jump_absolute=self.jump_absolute,
            jump_relative=self.jump_relative,
        )

    def joint_rules(self) -> JointRules:
        """The thresholds of :func:`annotators.geometry.support.join_jointly_held`: those of
        ``join_unsupported``, the merge rules' shortest trusted border as the close pixel pairs along which pieces
        must touch in 3-D, and the depth jumps."""
        return JointRules(
            support=SupportRules(),
            min_close=self.merge_rules().min_boundary,
            jump_absolute=self.jump_absolute,
            jump_relative=self.jump_relative,
        )

    def inner_wall_rules(self) -> InnerWallRules:
        """The thresholds of :func:`annotators.geometry.inner_walls.join_inner_walls`: those of
        ``join_unsupported``, the merge rules' share of a border that must touch in 3-D and its length, and the
        depth jumps."""
        rules = self.merge_rules()
        return InnerWallRules(
            support=SupportRules(),
            boundary_share=rules.boundary_share,
            min_boundary=rules.min_boundary,
            jump_absolute=self.jump_absolute,
            jump_relative=self.jump_relative,
        )

    def slab_rules(self) -> SlabRules:
        """The thresholds of :func:`annotators.geometry.slabs.join_slab_pieces`: the merge rules' share of a border
        that must be continuous and its length, and the depth jumps."""
        rules = self.merge_rules()
        return SlabRules(
            continuous=rules.continuous,
            boundary_share=rules.boundary_share,
            min_boundary=rules.min_boundary,
            jump_absolute=self.jump_absolute,
            jump_relative=self.jump_relative,
        )

    def occlusion_rules(self) -> OcclusionRules:
        """The thresholds of :func:`annotators.geometry.occlusion.join_occluded`: pieces touching along a border
        shorter than the merge rules trust (their shortest border and its share) count as apart."""
        rules = self.merge_rules()
        return OcclusionRules(boundary_share=rules.boundary_share, min_boundary=rules.min_boundary)

    def border_rules(self) -> BorderRules:
        """The thresholds of :func:`annotators.geometry.border_pixels.claim_border_pixels` at full resolution: the
        depth jumps, the span of the normals (``normal_step`` coarse pixels), the smoothness angle, the concave
        crease of the merge rules, the candidates' lowest height and the outline the ``stride`` grid loses."""
        step = max(1, self.stride)
        return BorderRules(
            jump_absolute=self.jump_absolute,
            jump_relative=self.jump_relative,
            normal_step=self.normal_step * step,
            smooth_degrees=self.smooth_degrees,
            crease=self.convexity,
            min_height=self.min_height,
            stride=step,
        )

    def merge_rules(self) -> MergeRules:
        """The cluster extractor's merge rules with the footprint rule only for parts whose heights nest (a bowl's
        inside and outside, a mug's handle): stacked objects share footprints too, but one lies above the other."""
        return replace(super().merge_rules(), nested=True, overlap=0.15)


SAMPLING_PERIOD = math.lcm(
    FOOTPRINT_ROWS,
    SupportRules.sample_step,
    AppendageRules.sample_step,
    SlabRules.sample_step,
    NeckRules.sample_step,
    FloorRules.sample_step,
    RimRules.sample_step,
)
"""Coarse pixels: the later steps read every few pixels or rows counted from the crop's corner; with the corner on a
multiple of all their spacings they read the same pixels of the image wherever the candidates' box starts."""


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
    # the pixels' angle, a property of the camera, sets the grid: the same angles on any image size
    camera_rows = np.ascontiguousarray(points[:: max(1, points.shape[0] // CAMERA_ROWS)])
    p = (parameters or ClutterParameters()).for_camera(pixel_footprint(camera_rows))
    step = max(1, p.stride)
    distances = plane_distances(points, model)  # the heights of all points, for the candidates and the segments
    coarse = standing_region(points, mask, model, plane_indices, p, distances)
    if not coarse.any():
        return []
    x0, y0, x1, y1 = bounding_box(coarse, margin=2)
    if p.grown_patches:  # the sampled rows and pixels on the image's grid, not the crop's: the crop may start anywhere
        x0, y0 = x0 - x0 % SAMPLING_PERIOD, y0 - y0 % SAMPLING_PERIOD
    region = coarse[y0:y1, x0:x1]
    grid = strided_crop(points, step, (x0, y0, x1, y1))
    depth = grid[..., 2]
    seams = depth_seams(depth, region, p.jump_absolute, p.jump_relative)
    normals = grid_normals(grid, p.normal_step, p.normal_smoothing, p.jump_absolute, p.jump_relative)
    surfaces = label_parts(region & ~seams, 1)
    # grown patches take their boundaries from the data: the same patches wherever the crop starts
    if p.grown_patches:
        cut = flat_patches(surfaces, normals, grid, p.patch_spacing, p.patch_weight, p.jump_relative)
    else:
        cut = grid_patches(surfaces, p.cell)
    patches = split_by_normals(cut, normals, p.normal_spread)
    # patches without a trustworthy plane (a face seen edge-on, a few points) go with the object beside them
    reach = max(2.0 * p.cell, p.grow_distance / step)
    # the angle between neighbouring pixels, a property of the camera: measured once, on every few rows
    footprint = pixel_footprint(np.ascontiguousarray(grid[::FOOTPRINT_ROWS]))
    objects = convex_objects(
        patches, grid, p.convexity_rules(), region & ~seams, grow=reach, footprint=footprint, surfaces=surfaces
    )
    labels = grow_on_surface(objects.labels, region, depth, p.jump_absolute, p.jump_relative)
    basis = plane_basis(np.asarray(model[:3], dtype=np.float64)).T.astype(np.float32)
    to_plane = np.column_stack([basis, np.asarray(model[:3], dtype=np.float32)])
    offset = np.array([0.0, 0.0, model[3]], dtype=np.float32)
    # (u, v, height) of every grid point on the plane
    plane_grid = plane_coordinates(grid.reshape(-1, 3), to_plane, offset)
    labels = merge_parts(
        labels,
        depth,
        plane_grid,
        p.merge_rules(),
        stand_apart=one_stands_inside if p.join_rims else None,
        spilled=objects.spilled(surfaces),
    )
    if p.join_rims:  # a bowl's inside and outside, which share no footprint to merge by
        labels = join_single_rims(labels, plane_grid, RimRules())
    # the hue of every grid pixel, for the hue edges and the tints of transparent objects
    chroma = chroma_image(strided_crop(colors, step, (x0, y0, x1, y1))) if colors is not None and p.use_color else None
    if chroma is not None:
        labels = split_by_color(labels, grid, normals, chroma, p, footprint)
    if p.complete_occluded:
        labels = join_occluded(
            labels, grid, normals, plane_grid.reshape(grid.shape), p.jump_absolute, p.jump_relative, p.occlusion_rules()
        )
    support = SupportRules() if p.join_unsupported else None
    appendages = p.appendage_rules() if p.join_appendages else None
    joint = p.joint_rules() if p.join_jointly_held else None
    # each step hands the summary of the labels it leaves to the next while they stay as they are
    labels, pieces, summary_step = join_pieces_summarized(labels, grid, normals, plane_grid, support, appendages, joint)
    if p.join_inner_walls:
        wall_rules = p.inner_wall_rules()
        if pieces is None or summary_step != wall_rules.support.sample_step:  # made here, it serves the slabs too
            summary_step = wall_rules.support.sample_step
            pieces = summarize_pieces(labels, plane_grid, summary_step)
        joined = join_inner_walls(labels, grid, normals, plane_grid, to_plane[:, :3], wall_rules, pieces)
        if joined is not labels:
            pieces, summary_step, labels = None, 0, joined
    if p.join_rims:
        # the heights, touching pairs and boxes of the labels as they are, when summarized
        known = (pieces.high, pieces.touching, pieces.boxes) if pieces is not None else (None, None, None)
        joined = join_rim_pieces(labels, plane_grid.reshape(*labels.shape, 3), RimRules(), *known)
        if joined is not labels:
            pieces, summary_step, labels = None, 0, joined
    if p.join_slabs:
        slab_rules = p.slab_rules()
        if pieces is None or summary_step != slab_rules.sample_step:  # made here, it serves the necks too
            summary_step = slab_rules.sample_step
            pieces = summarize_pieces(labels, plane_grid, summary_step)
        joined = join_slab_pieces(labels, grid, normals, plane_grid, slab_rules, pieces, objects.seeded)
        if joined is not labels:
            pieces, summary_step, labels = None, 0, joined
    if p.join_necks:
        neck_rules = NeckRules()
        known = pieces if summary_step == neck_rules.sample_step else None
        labels = join_necked_pieces(labels, plane_grid, neck_rules, known)
    valid = mask[::step, ::step][y0:y1, x0:x1] & np.isfinite(depth)  # measured, within the range filter's
    if chroma is not None and p.join_see_through:
        labels = join_see_through(labels, valid, chroma, TransparencyRules())
    floors = None
    if p.claim_floors:
        rules = FloorRules(min_height=p.min_height, margin=p.hull_margin, cell=p.hull_cell)
        labels, floors = claim_container_floors(labels, valid, plane_grid, rules)
        if touches_other_labels(labels, floors):  # the floor's pieces the noise lifted now touch their container
            labels = join_pieces(labels, grid, normals, plane_grid, support, appendages, joint)
    refine = None
    if p.claim_borders:
        floor = plane_noise(points, model, plane_indices)
        refine = partial(claim_border_pixels, plane=model, floor=floor, coarse_normals=normals, rules=p.border_rules())
    return full_resolution_segments(
        labels, depth, (x0, y0, x1, y1), step, points, mask, model, p, refine, floors, distances
    )


def split_by_color(
    labels: np.ndarray,
    grid: np.ndarray,
    normals: np.ndarray,
    chroma: np.ndarray,
    p: ClutterParameters,
    footprint: float | None = None,
) -> np.ndarray:
    """Objects split where a hue edge and a concave crease coincide: two objects whose surfaces continue one
    another (a can standing on a can with its side flush with the lower one's front, boxes stacked flush) are one
    convex group, but the colour changes between them and their boundary folds inward along part of its length.

    Each object is cut at hue edges into pieces; pieces whose shared boundary is creased (the surfaces meet - their
    points along it are close in 3-D - and a share of at least ``p.creased_share`` of it is concave, the surfaces
    not coplanar) must stay apart. The crease must also run as long as a joint :func:`merge_parts` trusts
    (``boundary_share`` times the square root of the smaller piece's size, at least ``min_boundary``): a few
    creased pixel pairs between a large piece and a crumb are noise, not two objects meeting. Everything else of
    the object joins again - longest shared boundaries first, so a piece goes with the side it shares most with. A
    print on a box (no crease) or the pieces of one object seen on both sides of an occluder never split.
    ``chroma`` is the :func:`~annotators.geometry.grid_segmentation.chroma_image` of the grid's colours;
    ``footprint`` the :func:`~annotators.geometry.grid_segmentation.pixel_footprint` of ``grid`` when the caller
    has measured it.
    """
    step = max(1, p.stride)
    objects = labels > 0
    edges = chroma_edges(chroma, p.edge_low, p.edge_high) & objects
    parts = label_parts(objects & ~edges, max(1, p.min_part_points // (step * step)))
    pieces, owner, piece_sizes = object_pieces(np.ascontiguousarray(labels), parts)
    # only an object with two pieces that could each be an object (min_points) can split
    large = piece_sizes * step * step >= p.min_points
    pieces_of = np.bincount(owner[1:], weights=large[1:], minlength=int(labels.max()) + 1)
    if pieces_of.max(initial=0) < 2:
        return labels
    pieces = grow_labels_nearby(pieces, objects, p.grow_distance / step)
    pieces[owner[pieces] != labels] = 0
    several = pieces_of[labels] >= 2  # only objects of several pieces can split: their boundaries are measured
    x0, y0, x1, y1 = bounding_box(several, margin=3)
    window = np.where(several[y0:y1, x0:x1], pieces[y0:y1, x0:x1], 0)
    surface = boundaries(
        window, grid[y0:y1, x0:x1], normals[y0:y1, x0:x1], p.jump_absolute, p.jump_relative, footprint=footprint
    )
    rules = p.merge_rules()
    sizes = np.bincount(window.reshape(-1), minlength=owner.size)
    smaller = np.minimum(sizes[surface.pairs[:, 0]], sizes[surface.pairs[:, 1]])
    creased = (
        (surface.creased > p.creased_share)
        & (surface.crease_length >= np.maximum(rules.min_boundary, rules.boundary_share * np.sqrt(smaller)))
        & (surface.close >= rules.continuous)
        & (surface.convexity < rules.concave)
        & (surface.alignment < rules.coplanar_cosine)
        & (owner[surface.pairs[:, 0]] == owner[surface.pairs[:, 1]])
    )
    if not creased.any():
        return labels
    same_object = owner[surface.pairs[:, 0]] == owner[surface.pairs[:, 1]]
    touching = surface.pairs[same_object][np.argsort(-surface.length[same_object], kind="stable")]
    first_piece = np.full(owner.size, -1, dtype=np.int64)
    for piece in range(owner.size - 1, 0, -1):
        first_piece[owner[piece]] = piece
    rest = np.arange(1, owner.size)
    chained = np.column_stack([first_piece[owner[rest]], rest])
    groups = groups_unless_apart(owner.size, np.concatenate([touching, chained]), surface.pairs[creased])
    result = dense_labels(np.where(pieces > 0, groups[pieces] + 1, 0))
    return grow_labels_nearby(result, objects, p.grow_distance / step)


class ClutterSegmenter(Annotator):
    """Segments touching, stacked and occluding objects on the supporting plane into object hypotheses: convexly
    connected surfaces, cut at depth jumps and concave creases (model-free; colour only where a crease runs along
    a hue edge)."""

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
        support = supporting_plane(cloud, self.annotations(Plane))
        if isinstance(support, str):
            self.fail(support)
        model, inliers = support
        segments = segment_clutter(cloud.points, cloud.mask, model, inliers, self.parameters, cloud.colors)
        if not segments:
            self.fail("no object stands on the supporting plane")
        for segment in segments:
            self.write(ObjectHypothesis(point_indices=segment.indices, mask=segment.mask, roi=segment.roi))
