"""Convexity-based grouping of surface patches on the organized grid (the LCCP idea on grid cells).

Objects are, to a first approximation, convex: the faces of one object meet at convex edges, while where two
objects meet - a can standing on a box, a box leaning on another - their surfaces form a concave crease
(Stein et al., "Object partitioning using local convexity", CVPR 2014). Here the surface is cut into small patches
(:func:`grid_patches`: cells of the grid, split where depth jumps, and in two where their normals disagree,
:func:`split_by_normals`), each with a plane fit - a centroid and a normal, robust to sensor noise where per-pixel
normals are not. How fast the surface turns between two touching patches, ``(n_a - n_b) . (c_a - c_b) /
|c_a - c_b|^2`` (1/m), is about 0 on a plane, positive across a convex edge and negative in a concave crease;
:func:`convex_objects` joins patches into faces and faces into objects by it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from annotators.geometry.grid_kernels import (
    cell_patches,
    dense_keys,
    graph_components,
    groups_unless_apart,
    label_centres,
    label_moments,
    label_pieces,
    labelled_values,
    normal_halves,
    symmetric_eigen,
)
from annotators.geometry.grid_segmentation import (
    SeedDistances,
    distinct_keys,
    grow_from_seeds,
    label_parts,
    pixel_footprint,
    seed_distances,
    touching_pairs,
)


def grid_patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
    """Patch labels (int32, 0 = none, 1..n): each labelled surface of ``surfaces`` cut into ``cell`` x ``cell``
    grid cells; a cell that two surfaces share gives one patch to each, and so does a cell holding two pieces of one
    surface that meet only outside it - the two sides of a depth seam the surface runs around at its end, a step
    between two parallel faces: two strips, one on either side, always fit one plane, tilted between the faces."""
    patches = cell_patches(np.ascontiguousarray(surfaces), cell)
    pieces = label_pieces(patches)
    count = int(pieces.max(initial=0))
    if count == int(patches.max(initial=0)):
        return patches  # no cell holds two pieces
    owner = np.zeros(count + 1, dtype=np.int64)
    owner[pieces.reshape(-1)] = patches.reshape(-1)
    # numbered by patch, a patch's pieces in the raster order of their first pixels
    number = np.zeros(count + 1, dtype=np.int32)
    number[1 + np.argsort(owner[1:], kind="stable")] = np.arange(1, count + 1, dtype=np.int32)
    return number[pieces]


def dense_labels(keys: np.ndarray) -> np.ndarray:
    """Non-negative integer keys (0 = none) renumbered 1..n in increasing order, as int32; by a lookup table over
    the key range (linear time) rather than by sorting."""
    if keys.ndim != 2:
        return dense_keys(keys.reshape(1, -1)).reshape(keys.shape)
    return dense_keys(keys)


def split_by_normals(patches: np.ndarray, normals: np.ndarray, spread: float) -> np.ndarray:
    """Patches whose pixel normals spread (RMS distance from their mean normal) by more than ``spread`` cut in two:
    the pixels on either side of the mean along the direction the normals vary most. A cell lying across the edge
    of a box or across the crease between two objects so becomes two patches, one per surface. Pixels without a
    normal are left out (0). Labels 1..n."""
    count = int(patches.max(initial=0)) + 1
    labels, unit = labelled_values(patches, normals, True)  # 3xN: each component's values contiguous
    pixels, sums, _ = label_moments(labels, unit, np.zeros((count, 3)), count)
    sizes = np.maximum(pixels, 1).astype(np.float64)
    mean = sums / sizes[:, None]
    second = _symmetric(label_moments(labels, unit, mean, count)[2] / sizes[:, None])
    # the spread is the root of the trace (the sum of the eigenvalues); the direction is needed in wide patches
    wide = np.sqrt(np.clip(second[:, 0, 0] + second[:, 1, 1] + second[:, 2, 2], 0, None)) > spread
    direction = np.zeros((count, 3))
    direction[wide] = symmetric_eigen(second[wide])[1][:, :, 2]
    return dense_labels(normal_halves(patches, normals, mean, direction, wide))


@dataclass(frozen=True)
class ConvexityRules:
    """Thresholds of :func:`convex_objects`: ``smooth_degrees`` between the normals (and of the centroid line off
    both planes) of a smooth connection; ``concave_bending`` (1/m, a turn tighter than a 5 cm radius) makes a
    connection concave; two faces join when more than ``convex_share`` of their votes are convex, at least
    ``min_votes`` when both faces are large, and not when more than ``concave_share`` are concave; a patch needs
    ``min_patch`` points, at most ``max_thickness`` (smallest / middle eigenvalue) and at least ``min_width``
    (middle / largest) for a plane; faces of fewer than
    ``min_face`` points are slivers; patches touch across up to ``gap_width`` pixels, and only when their centroids
    are at most ``close_factor`` times their grid distance apart in 3-D; with ``small_joins_once`` two faces of
    fewer than ``min_face`` points join on fewer than ``min_votes`` convex votes only where one is the other's best
    neighbour (the one it agrees with most), so a string of small faces cannot carry a join from one object to the
    next; a small face still joins every large face it agrees with (a sliver along a box's edge); with
    ``grazing_degrees`` a connection touching a patch whose normal lies more than that many degrees from its line of
    sight votes convex only where it bends outward (:func:`grazing_patches`); between two large faces, a connection
    across a crease (normals at least ``crease_degrees`` apart) votes convex only where it bends outward
    (:func:`inward_creases`); two large faces without a convex majority are kept apart on ``min_votes`` votes, or
    on one connection bending inward faster than ``decisive_bending`` (1/m, a turn tighter than a 1 cm radius: the
    normals of neighbouring patches are not that noisy); a weak agreement (fewer than ``min_votes`` convex votes,
    none bending outward faster than ``concave_bending``: no rim or edge turning) may attach faces to a group of
    ``object_points`` points or more (four large faces' worth: an object's surface) but does not join two such
    groups: along the seam where two objects touch, small faces agree with both on single votes."""

    smooth_degrees: float = 20.0
    concave_bending: float = 20.0
    convex_share: float = 0.5
    min_patch: int = 6
    max_thickness: float = 0.5
    min_width: float = 0.04
    min_face: int = 72
    min_votes: int = 2
    concave_share: float = 0.25
    gap_width: float = 2.0
    close_factor: float = 3.0
    small_joins_once: bool = False
    grazing_degrees: float | None = None
    crease_degrees: float = 45.0
    decisive_bending: float = 100.0
    object_points: float = 288.0


@dataclass(frozen=True, eq=False)
class PatchPlanes:
    """Per patch (index = label - 1): point count, centroid (Nx3), unit normal facing the camera (Nx3) and
    ``thickness``, the ratio of the smallest to the middle covariance eigenvalue: near 0 for a patch much wider
    than its noise, near 1 when its points lie along a line or a strip hardly wider than the noise (a sliver of a
    face seen edge-on), whose plane - and normal - is then undetermined; and ``width``, the middle over the largest
    eigenvalue (near 0 for points along a line)."""

    counts: np.ndarray
    centroids: np.ndarray
    normals: np.ndarray
    thickness: np.ndarray
    width: np.ndarray


def patch_planes(patches: np.ndarray, points: np.ndarray) -> PatchPlanes:
    """Plane fits of all patches at once (sums by ``bincount``, one batched 3x3 eigen-decomposition)."""
    count = int(patches.max(initial=0))
    labels, xyz = labelled_values(patches, points, False)  # 3xN: each coordinate's values contiguous
    labels -= 1
    shift = xyz.mean(axis=1) if xyz.size else np.zeros(3)
    xyz -= shift[:, None]
    pixels, sums, products = label_moments(labels, xyz, np.zeros((count, 3)), count)
    counts = pixels.astype(np.float64)
    safe = np.maximum(counts, 1.0)
    means = sums / safe[:, None]
    second = _symmetric(products / safe[:, None])
    covariance = second - means[:, :, None] * means[:, None, :]
    values, vectors = symmetric_eigen(covariance)
    normals = vectors[:, :, 0]
    centroids = means + shift
    normals *= np.where(np.einsum("ij,ij->i", normals, centroids) > 0, -1.0, 1.0)[:, None]
    thickness = np.clip(values[:, 0], 0, None) / np.maximum(values[:, 1], 1e-12)
    width = np.clip(values[:, 1], 0, None) / np.maximum(values[:, 2], 1e-12)
    return PatchPlanes(counts.astype(np.int64), centroids, normals, thickness, width)


def _symmetric(products: np.ndarray) -> np.ndarray:
    """Kx3x3 symmetric matrices from their Kx6 entries 00, 01, 02, 11, 12, 22."""
    matrices = np.empty((products.shape[0], 3, 3))
    for k, (i, j) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
        matrices[:, i, j] = matrices[:, j, i] = products[:, k]
    return matrices


def connection_bending(planes: PatchPlanes, pairs: np.ndarray) -> np.ndarray:
    """For Kx2 patch labels: ``(n_a - n_b) . (c_a - c_b) / |c_a - c_b|^2``, how fast the surface turns between the
    two patches (1/m; about 1/radius on a cylinder): positive convex, negative concave."""
    a, b = pairs[:, 0] - 1, pairs[:, 1] - 1
    offset = planes.centroids[a] - planes.centroids[b]
    length = np.einsum("ij,ij->i", offset, offset)
    with np.errstate(invalid="ignore", divide="ignore"):
        value = np.einsum("ij,ij->i", planes.normals[a] - planes.normals[b], offset) / length
    return np.nan_to_num(value)


def close_in_space(
    patches: np.ndarray, planes: PatchPlanes, pairs: np.ndarray, footprint: float, close_factor: float
) -> np.ndarray:
    """For Kx2 patch labels: are the two centroids at most ``close_factor`` times as far apart in 3-D as their
    distance on the grid (pixels times the pixel ``footprint`` times depth) would be on a surface facing the camera?
    Patches touching on the grid across a depth jump (an object and what is behind it) are not."""
    if pairs.size == 0:
        return np.zeros(0, dtype=bool)
    counts, pixel = label_centres(np.ascontiguousarray(patches), planes.counts.size + 1)
    pixel /= np.maximum(counts, 1)[:, None]
    a, b = pairs[:, 0], pairs[:, 1]
    on_grid = np.linalg.norm(pixel[a] - pixel[b], axis=1)
    depth = np.minimum(planes.centroids[a - 1, 2], planes.centroids[b - 1, 2])
    in_space = np.linalg.norm(planes.centroids[a - 1] - planes.centroids[b - 1], axis=1)
    return in_space <= close_factor * np.maximum(on_grid, 1.0) * footprint * depth


@dataclass(frozen=True, eq=False)
class ConvexObjects:
    """What :func:`convex_objects` found: the object ``labels`` (int32 HxW, 0 = none, 1..n) and which pixels were
    ``seeded`` (bool HxW: those of trusted patches, whose labels the convexity votes decided; the other labelled
    pixels were grown from them)."""

    labels: np.ndarray
    seeded: np.ndarray

    def spilled(self, surfaces: np.ndarray) -> np.ndarray:
        """The grown pixels (bool HxW) that lie on a surface of ``surfaces`` (labels of depth-continuous parts,
        0 = none) holding seeded pixels of other objects but none of their own: growth that looks only at distances
        in the image carries an object's label over its outline, onto the object behind it or in front of it."""
        labels = self.labels
        seeds = self.seeded & (labels > 0) & (surfaces > 0)
        grown = (labels > 0) & ~self.seeded & (surfaces > 0)
        if not grown.any() or not seeds.any():
            return np.zeros(labels.shape, dtype=bool)
        span = np.int64(labels.max()) + 1
        seed_keys = surfaces[seeds].astype(np.int64) * span + labels[seeds]
        seeded_surfaces = np.zeros(int(surfaces.max()) + 1, dtype=bool)
        seeded_surfaces[surfaces[seeds]] = True
        grown_surfaces = surfaces[grown]
        own = np.isin(grown_surfaces.astype(np.int64) * span + labels[grown], seed_keys)
        spilled = np.zeros(labels.shape, dtype=bool)
        spilled[grown] = seeded_surfaces[grown_surfaces] & ~own
        return spilled


def convex_objects(
    patches: np.ndarray,
    points: np.ndarray,
    rules: ConvexityRules,
    between: np.ndarray | None = None,
    grow: float = 0.0,
    footprint: float | None = None,
    surfaces: np.ndarray | None = None,
) -> ConvexObjects:
    """Objects (:class:`ConvexObjects`) from surface patches in two steps.

    1. *Faces*: patches joined along smooth connections - normals within ``rules.smooth_degrees``, the line between
       the centroids within that angle of both tangent planes (one surface going on, flat or gently curved, not a
       step between parallel surfaces) and no concave bend.
    2. *Objects*: faces joined where they meet convexly. Every connection between two faces votes (convex, or
       concave when it bends inward faster than ``rules.concave_bending``; a step votes neither; between two large
       faces, a connection across a crease that bends inward votes no convex, :func:`inward_creases`); two faces
       join when more than ``rules.convex_share`` of the votes are convex and at most ``rules.concave_share`` concave.
       Joins are made strongest first, the weak agreements (see :class:`ConvexityRules`) after all others, and two
       large faces that do not agree are kept apart: a sliver along a crease that agrees with both sides cannot
       join them; nor can a weak agreement join two groups that each hold ``rules.object_points`` points.

    Patches touch when they are 4-neighbours once grown by up to ``rules.gap_width`` pixels into the unlabelled
    pixels between them that ``between`` allows (HxW bool; default: every pixel with a point), each on its own
    surface (:func:`bridge_gaps`; ``surfaces``: the 4-connected parts of ``between``, when the caller has them), and
    their centroids are close in 3-D (:func:`close_in_space`). Patches without a trustworthy plane (fewer than
    ``rules.min_patch`` points, thicker than ``rules.max_thickness`` or narrower than ``rules.min_width``) are left
    out (0).
    With ``grow`` > 0 the object labels are grown by up to ``grow`` pixels into the unlabelled pixels of ``between``
    (what :func:`~annotators.geometry.grid_segmentation.grow_labels` gives), from the distance transform of the
    gap growth (the objects cover the kept patches' pixels). ``footprint`` is the
    :func:`~annotators.geometry.grid_segmentation.pixel_footprint` of ``points`` when the caller has measured it.
    """
    planes = patch_planes(patches, points)
    count = planes.counts.size + 1
    trusted = (planes.thickness <= rules.max_thickness) & (planes.width >= rules.min_width)
    usable = np.concatenate([[False], (planes.counts >= rules.min_patch) & trusted])
    kept = np.where(usable[patches], patches, 0)
    between = np.isfinite(points[..., 2]) if between is None else between
    surfaces = label_parts(between | (kept > 0), 1) if surfaces is None else surfaces
    seeds = seed_distances(kept, between | (kept > 0), max(rules.gap_width, grow))
    pairs = touching_pairs(bridge_gaps(kept, seeds, rules.gap_width, surfaces))
    if footprint is None:
        footprint = pixel_footprint(points)
    pairs = pairs[close_in_space(patches, planes, pairs, footprint, rules.close_factor)]
    bending = connection_bending(planes, pairs)  # the votes and the creases read it
    continuous, convex, concave = connection_votes(planes, pairs, rules, bending)
    faces = _components(pairs[continuous], count)
    objects = join_faces(faces, pairs, convex, concave, planes, rules, bending)
    labels = _dense(objects[faces], usable)[kept]
    seeded = kept > 0
    if grow > 0:
        labels = grow_from_seeds(labels, seeds, grow)
    return ConvexObjects(labels, seeded)


def bridge_gaps(kept: np.ndarray, seeds: SeedDistances | None, gap: float, surfaces: np.ndarray) -> np.ndarray:
    """The patch labels ``kept`` grown by up to ``gap`` pixels into the gaps between them (``seeds`` from
    :func:`~annotators.geometry.grid_segmentation.seed_distances`), a grown pixel keeping its label only on the
    surface (``surfaces``: labels of depth-continuous parts holding every patch) its patch lies on. The growth goes by
    distance in the image: a pixel in front of a depth jump as far from a patch behind as from one of its own would
    otherwise go to either by the order the image is scanned in, and the two objects would touch or not as the camera
    is rolled (mOSD learn21 turned by 180 degrees)."""
    grown = grow_from_seeds(kept, seeds, gap)
    surface_of = np.zeros(int(kept.max()) + 1, dtype=surfaces.dtype)
    surface_of[kept[kept > 0]] = surfaces[kept > 0]
    return np.where(surfaces == surface_of[grown], grown, 0)


def connection_votes(
    planes: PatchPlanes, pairs: np.ndarray, rules: ConvexityRules, bending: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For Kx2 touching patch labels: is each connection continuous (one face: normals and the centroid line within
    ``rules.smooth_degrees``, no concave bend), and does it vote convex or concave (see :func:`convex_objects`)?
    ``bending`` is the pairs' :func:`connection_bending` when the caller has it."""
    parallel, in_planes = _alignment(planes, pairs, rules.smooth_degrees)
    bending = connection_bending(planes, pairs) if bending is None else bending
    concave = bending < -rules.concave_bending
    continuous = parallel & in_planes & ~concave
    convex = ~concave & (continuous | ~parallel)
    if rules.grazing_degrees is not None:
        grazing = grazing_patches(planes, rules.grazing_degrees)
        convex &= ~((grazing[pairs[:, 0]] | grazing[pairs[:, 1]]) & (bending < 0) & ~continuous)
    return continuous, convex, concave


def grazing_patches(planes: PatchPlanes, degrees: float) -> np.ndarray:
    """Per patch label (index 0, no patch, False): is the patch's normal more than ``degrees`` from its line of
    sight (the ray to its centroid)?

    A surface seen that nearly edge-on is either the limb of a round object, bending on outward from the face
    beside it, or the wall of a step down to a surface farther away - a box's side, or the stereo depth ramp that
    smears an occluding edge over a few pixels to the surface behind it - which meets that far surface bending
    inward, gently enough to pass as a convex vote. Such an inward connection is no evidence of one object."""
    centroids = planes.centroids
    distances = np.maximum(np.linalg.norm(centroids, axis=1), 1e-12)
    facing = np.abs(np.einsum("ij,ij->i", planes.normals, centroids)) / distances
    return np.concatenate([[False], facing < np.cos(np.radians(degrees))])


def inward_creases(
    planes: PatchPlanes, pairs: np.ndarray, degrees: float, bending: np.ndarray | None = None
) -> np.ndarray:
    """For Kx2 touching patch labels: does the connection cross a crease (normals at least ``degrees`` apart) bending
    inward, however gently?

    One object's faces meet at a crease bending outward (a box's edge). Two objects meet there bending inward: a
    box's side and the face of a box behind it, at right angles across the depth gap between them. Across that gap
    the bending (:func:`connection_bending`) is weak - the centroids lie far apart for the turn - and may not reach
    the concave limit, but its sign still tells the two apart. ``bending`` is the pairs' :func:`connection_bending`
    when the caller has it."""
    a, b = pairs[:, 0] - 1, pairs[:, 1] - 1
    crease = np.einsum("ij,ij->i", planes.normals[a], planes.normals[b]) < np.cos(np.radians(degrees))
    return crease & ((connection_bending(planes, pairs) if bending is None else bending) < 0)


def _alignment(planes: PatchPlanes, pairs: np.ndarray, degrees: float) -> tuple[np.ndarray, np.ndarray]:
    """For Kx2 patch labels: normals within ``degrees``; the centroid line within ``degrees`` of both planes."""
    a, b = pairs[:, 0] - 1, pairs[:, 1] - 1
    offset = planes.centroids[a] - planes.centroids[b]
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = np.nan_to_num(offset / np.linalg.norm(offset, axis=1, keepdims=True))
    parallel = np.einsum("ij,ij->i", planes.normals[a], planes.normals[b]) >= np.cos(np.radians(degrees))
    across = np.sin(np.radians(degrees))
    in_planes = (np.abs(np.einsum("ij,ij->i", direction, planes.normals[a])) <= across) & (
        np.abs(np.einsum("ij,ij->i", direction, planes.normals[b])) <= across
    )
    return parallel, in_planes


def join_faces(
    faces: np.ndarray,
    pairs: np.ndarray,
    convex: np.ndarray,
    concave: np.ndarray,
    planes: PatchPlanes,
    rules: ConvexityRules,
    bending: np.ndarray | None = None,
) -> np.ndarray:
    """The object of each face (indexed by face label; ``faces`` gives each patch label's face, index 0 no patch):
    faces joined by the votes of the patch connections ``pairs`` (Kx2 patch labels, :func:`connection_votes`' verdicts
    ``convex`` and ``concave``; see :func:`convex_objects`; ``bending`` their :func:`connection_bending` when the
    caller has it)."""
    count = faces.size
    face_a, face_b = faces[pairs[:, 0]], faces[pairs[:, 1]]
    apart = face_a != face_b
    low, high = np.minimum(face_a, face_b)[apart], np.maximum(face_a, face_b)[apart]
    keys, inverse = distinct_keys(low * count + high)
    votes = np.maximum(np.bincount(inverse, minlength=keys.size), 1)
    face_sizes = np.bincount(faces, weights=planes_sizes(planes, count), minlength=count)
    large = face_sizes >= rules.min_face
    between_large = large[face_a] & large[face_b]
    bending = connection_bending(planes, pairs) if bending is None else bending
    convex = convex & ~(between_large & inward_creases(planes, pairs, rules.crease_degrees, bending))
    share = np.bincount(inverse, weights=convex[apart], minlength=keys.size) / votes
    concave_votes = np.bincount(inverse, weights=concave[apart], minlength=keys.size)
    sharpest, steepest = np.full(keys.size, np.inf), np.full(keys.size, -np.inf)
    np.minimum.at(sharpest, inverse, bending[apart])
    np.maximum.at(steepest, inverse, bending[apart])
    share = np.where((concave_votes > rules.concave_share * votes) & (concave_votes >= rules.min_votes), 0.0, share)
    first, second = keys // count, keys % count
    both_large = large[first] & large[second]
    strength = share * votes
    agree = (share > rules.convex_share) & ((strength >= rules.min_votes) | ~both_large)
    # one vote decides nothing - a single noisy connection neither joins two large faces nor keeps them apart -
    # unless it bends inward far beyond the noise: a can standing in a bowl, its side against the inner wall
    decisive = (votes >= rules.min_votes) | (sharpest < -rules.decisive_bending)
    kept_apart = np.column_stack([first, second])[(share <= rules.convex_share) & both_large & decisive]
    if rules.small_joins_once:
        # a small face joins a large one on its convex majority, another small face only as its best neighbour
        small_pair = ~large[first] & ~large[second]
        agree &= (strength >= rules.min_votes) | ~small_pair | _best_of_small(first, second, strength, agree, large)
    weak = (strength < rules.min_votes) & (steepest < rules.concave_bending)
    # strongest first, and the weak agreements after all others: a seam face goes with the object its other
    # agreements tie it to before a weak one can take it to the object beside
    order = np.lexsort((-strength[agree], weak[agree]))
    joins = np.column_stack([first, second])[agree][order]
    return groups_unless_apart(count, joins, kept_apart, weak[agree][order], face_sizes, rules.object_points)


def _best_of_small(
    first: np.ndarray, second: np.ndarray, strength: np.ndarray, agree: np.ndarray, large: np.ndarray
) -> np.ndarray:
    """Per face pair: is it, among the agreeing pairs, the strongest of a small face in it (the first in pair order
    on ties)?"""
    ends = np.concatenate([first, second])
    index = np.concatenate([np.arange(first.size)] * 2)
    pick = np.concatenate([agree, agree]) & ~large[ends]
    ends, index = ends[pick], index[pick]
    order = np.lexsort((index, -strength[index], ends))
    ends, index = ends[order], index[order]
    lead = np.ones(ends.size, dtype=bool)
    lead[1:] = ends[1:] != ends[:-1]
    best = np.zeros(first.size, dtype=bool)
    best[index[lead]] = True
    return best


def _dense(groups: np.ndarray, usable: np.ndarray) -> np.ndarray:
    """Per patch label: its group renumbered 1..n over the usable patches (0 for the others)."""
    present = np.flatnonzero(usable)
    renumber = np.zeros(groups.size, dtype=np.int32)
    _, dense = np.unique(groups[present], return_inverse=True)
    renumber[present] = dense.reshape(-1).astype(np.int32) + 1
    return renumber


def planes_sizes(planes: PatchPlanes, count: int) -> np.ndarray:
    """Point counts of patches 0..count-1 (patch 0, no patch, has none)."""
    sizes = np.zeros(count)
    sizes[1 : planes.counts.size + 1] = planes.counts
    return sizes


def _components(pairs: np.ndarray, count: int) -> np.ndarray:
    """The connected component of each of ``count`` nodes of the graph with the edges ``pairs`` (Kx2)."""
    return graph_components(pairs, count)
