"""Compiled loops over the organized grid for the segmentation primitives: passes over pixels or pixel pairs that
whole-array numpy would make with many temporaries, and loops over a few pieces that numpy would make call by call.

The kernels give exactly what the numpy or OpenCV expressions they replace give (integer and boolean results,
values picked from the input unchanged, sums added in the same order), except :func:`symmetric_eigen`, which
agrees with ``np.linalg.eigh`` to rounding. They are compiled by numba on first use (numba is imported then, not
with this module) and the machine code is cached on disk next to this file.
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.grid_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import grid_loops

    return grid_loops


def touching_keys(labels: np.ndarray, base: int) -> np.ndarray:
    """``min(a, b) * base + max(a, b)`` (int64) of every horizontally or vertically adjacent pixel pair of
    different non-zero labels ``a``, ``b`` (HxW integer labels), once per pixel pair, in no particular order."""
    return _loops().touching_keys(labels, base)


def near_label_pairs(labels: np.ndarray, reach: int) -> np.ndarray:
    """Kx2 distinct label pairs ``(a, b)``, ``0 < a < b``, in increasing order, of the pixels of different non-zero
    labels (HxW integers) within ``reach`` pixels of each other along both axes (a square window)."""
    return _loops().near_label_pairs(np.ascontiguousarray(labels), int(reach))


def facing_values(
    rows: np.ndarray, cols: np.ndarray, target: np.ndarray, values: np.ndarray, radius: int
) -> np.ndarray:
    """The ``values`` (HxW) of the ``target`` pixels (HxW bool) within ``radius`` pixels (a square window) of any
    of the marked pixels ``rows``, ``cols`` (distinct, at least one), in row-major order: what
    ``values[box][cv2.dilate(marked, ones(2 radius + 1)) & target[box]]`` gives on the box of the marked pixels
    grown by ``radius``."""
    return _loops().facing_values(rows, cols, target, values, radius)


def shadowed_near(occluding: np.ndarray, unmeasured: np.ndarray, shadow_radius: int, near_radius: int) -> np.ndarray:
    """HxW bool: the pixels within ``near_radius`` (a square window) of an occluder (``occluding``, HxW bool) or
    of its shadow - the 4-connected unmeasured regions (``unmeasured``) that touch it (8-neighbours), where they
    lie within ``shadow_radius`` of it. What ``cv2.dilate`` with square kernels of ones and
    ``cv2.connectedComponents`` give."""
    return _loops().shadowed_near(occluding, unmeasured, shadow_radius, near_radius)


def upsampled_labels(
    labels: np.ndarray,
    coarse_depth: np.ndarray,
    depth: np.ndarray,
    keep: np.ndarray,
    step: int,
    absolute: float,
    relative: float,
) -> np.ndarray:
    """HxW int32 (the shape of ``depth``, float32): each pixel's label in ``labels`` (every ``step``-th pixel's)
    where ``keep`` (HxW bool) allows it and no depth jump (:func:`depth_jump`'s float32 arithmetic) parts it from
    its coarse sample's depth ``coarse_depth``; 0 elsewhere."""
    return _loops().upsampled_labels(labels, coarse_depth, depth, keep, step, absolute, relative)


def label_pixels(
    labels: np.ndarray, origin: tuple[int, int] = (0, 0), width: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The flat indices of the labelled pixels of HxW ``labels`` sorted by label (increasing within one), ``starts``
    so label k owns ``pixels[starts[k]:starts[k + 1]]``, and each label's box ``(x0, y0, x1, y1)`` (exclusive;
    row k for label k, zeros for a label without pixels). With ``origin`` ``(row, column)`` and ``width``, the
    labels are a window of a grid that wide at that origin and the indices are flat indices of that grid (the
    boxes stay in the window's coordinates)."""
    top, left = origin
    return _loops().label_pixels(labels, top, left, labels.shape[1] if width is None else width)


def label_masks(
    labels: np.ndarray, kept: list[int], origin: tuple[int, int], shape: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """One bool mask of the grid ``shape`` (HxW) per label of ``kept``, in that order, holding the pixels HxW
    ``labels`` - a window of that grid at ``origin`` ``(row, column)`` - give the label, and each one's box
    ``(x0, y0, x1, y1)`` (exclusive, in the window's coordinates; zeros for a label without pixels): the masks
    :func:`label_pixels`' indices would fill and its boxes, in one pass over the window."""
    slots = np.full(max(kept, default=0) + 1, -1, dtype=np.int64)
    slots[kept] = np.arange(len(kept))
    masks = np.zeros((len(kept), *shape), dtype=bool)  # one allocation for all masks
    boxes = _loops().fill_label_masks(np.ascontiguousarray(labels), slots, masks, origin[0], origin[1])
    return masks, boxes


def label_moments(
    labels: np.ndarray, values: np.ndarray, means: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per label ``0..count-1`` of N ``labels``: the number of values, the sums of the 3xN ``values`` (float64) and
    the sums of the products ``(v_i - m_i) (v_j - m_j)`` for ``i <= j`` in the order 00, 01, 02, 11, 12, 22, with
    ``m`` the label's row of ``means`` (Kx3; zeros for plain second moments). Added up in the order of the values,
    as ``np.bincount`` adds its weights, so the sums are the same."""
    return _loops().label_moments(labels, values, means, count)


def label_centres(labels: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Per label ``0..count-1`` of HxW ``labels`` (label 0 counted too): the number of pixels and the sums of
    their rows and columns (Kx2 float64; exact, they are integers)."""
    return _loops().label_centres(labels, count)


def grouped_pixels(labels: np.ndarray, where: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The flat indices of the ``where`` pixels (HxW bool) with a label 1..count in HxW ``labels``, sorted by label
    (row-major within one), and ``starts`` (count + 2) so label k owns ``pixels[starts[k]:starts[k + 1]]``."""
    return _loops().grouped_pixels(labels, where, count)


def symmetric_eigen(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (Kx3, increasing) and unit eigenvectors (Kx3x3, column i for value i) of K symmetric 3x3
    matrices, by cyclic Jacobi rotations to full double precision: ``np.linalg.eigh`` for many small matrices
    without a LAPACK call each (the values agree to rounding; a vector's sign may differ)."""
    return _loops().symmetric_eigen(matrices)


def organized_normals(points: np.ndarray, step: int, smoothing: int, absolute: float, relative: float) -> np.ndarray:
    """HxWx3 float32 unit normals facing the camera of an organized HxWx3 float32 cloud (NaN where unknown):
    the cross product of the central differences across ``step`` pixels, summed over a ``smoothing`` x
    ``smoothing`` window (each raw normal of unit length; none where a neighbour is missing or across a depth jump
    of more than ``absolute + relative * nearer depth``), then normalised. The grid ``step`` pixels wide along the
    border gets none (see :func:`annotators.cloud.normals.grid_normals`)."""
    return _loops().organized_normals(points, step, smoothing, absolute, relative)


def piece_near(
    own: np.ndarray,
    window: tuple[int, int, int],
    occluding: np.ndarray,
    depth: np.ndarray,
    radius: int,
    points: np.ndarray,
) -> tuple[int, float, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What :func:`annotators.geometry.occlusion.join_occluded` needs of one piece's band near an occluder.

    ``own`` are the band's flat indices in a window of ``window = (width, y0, x0)`` (its width and its corner in
    the HxWx3 ``points`` grid); ``occluding`` and ``depth`` are the window's occluder mask and depths. Gives the
    number of the occluder's pixels within ``radius`` of the band (:func:`facing_values`), the mean finite depth
    of the band and of those occluder pixels (NaN when there is none), the band's flat indices in the grid, its
    finite points (Nx3 float32), their centroid and the band's mean pixel (row, column) in the grid."""
    return _loops().piece_near(own, window, occluding, depth, radius, points)


def boundary_pairs(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    reach: int,
    absolute: float,
    relative: float,
    near_factor: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per 4-neighbour pixel pair of different non-zero labels ``a``, ``b`` (HxW ``labels``; horizontal pairs in
    row-major order, then vertical ones): the key ``min * (max label + 1) + max``, whether a depth jump
    (``absolute + relative * nearer depth``) parts them, whether their points (HxWx3 float32) are at most
    ``near_factor`` times the nearer depth apart, and - where the pixels ``reach`` further out on either side
    still carry ``a`` and ``b`` - the dot product of those pixels' normals and ``(n_a - n_b) . (p_a - p_b) /
    |p_a - p_b|`` (float32, NaN elsewhere): the per-pair values :func:`~annotators.geometry.grid_segmentation.
    boundaries` sums up per label pair."""
    return _loops().boundary_pairs(labels, points, normals, reach, absolute, relative, near_factor)


def standing_candidates(
    heights: np.ndarray,
    mask: np.ndarray,
    points: np.ndarray,
    basis: np.ndarray,
    raster: np.ndarray,
    low: np.ndarray,
    cell: float,
    min_height: float,
    max_height: float,
) -> np.ndarray:
    """HxW bool: the ``mask`` pixels whose height above the plane (``heights``, float32) lies strictly between
    ``min_height`` and ``max_height`` and whose foot on the plane (the point, HxWx3 float32, times the 3x2 float32
    ``basis``) falls in a non-zero cell of ``raster`` (cells of ``cell`` metres, corner ``low``; rows along the
    second coordinate)."""
    return _loops().standing_candidates(heights, mask, points, basis, raster, low, cell, min_height, max_height)


def connected_parts(region: np.ndarray, min_points: int) -> np.ndarray:
    """HxW int32: the 4-connected parts of the HxW bool ``region`` with at least ``min_points`` pixels, labelled
    1..n in the raster order of their first pixels (as ``cv2.connectedComponents`` numbers them); 0 elsewhere."""
    return _loops().connected_parts(region, min_points)


def label_pieces(labels: np.ndarray) -> np.ndarray:
    """HxW int32: the 4-connected pieces of each label of HxW integer ``labels`` (0 = none), neighbours joined only
    where their labels are equal, numbered 1..n in the raster order of their first pixels; 0 elsewhere."""
    return _loops().label_pieces(np.ascontiguousarray(labels))


def object_pieces(labels: np.ndarray, parts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pieces objects are cut into: HxW int32 labels 1..n of the pixels of each (object, part) pair of
    ``labels`` and ``parts`` (HxW; parts lie within objects), numbered in increasing (object, part) order; each
    piece's object (``owner``, index 0 for no piece) and pixel count (index 0 for the pixels of no piece)."""
    return _loops().object_pieces(labels, parts)


def labelled_values(labels: np.ndarray, values: np.ndarray, finite_only: bool) -> tuple[np.ndarray, np.ndarray]:
    """The labels (1-D) and the HxWx3 ``values`` (3xN float64) of the pixels with a label (HxW, > 0) - and a
    finite first value, with ``finite_only`` - in row-major order: ``labels[where]``, ``values[where].T``."""
    return _loops().labelled_values(labels, values, finite_only)


def normal_halves(
    patches: np.ndarray, normals: np.ndarray, mean: np.ndarray, direction: np.ndarray, wide: np.ndarray
) -> np.ndarray:
    """HxW int64: ``2 patch + 1``, plus one where the patch is ``wide`` and the pixel's normal lies on the positive
    side of its patch's ``mean`` normal along the patch's ``direction`` (Kx3 float64 each); 0 for the pixels
    without a patch or a normal."""
    return _loops().normal_halves(patches, normals, mean, direction, wide)


def seam_pixels(depth: np.ndarray, candidates: np.ndarray, absolute: float, relative: float) -> np.ndarray:
    """:func:`~annotators.geometry.grid_segmentation.depth_seams` (HxW float32 ``depth``, HxW bool ``candidates``)
    in one pass over the 4-neighbour pairs."""
    return _loops().seam_pixels(depth, candidates, absolute, relative)


def surface_growth(
    labels: np.ndarray, region: np.ndarray, depth: np.ndarray, absolute: float, relative: float, rounds: int
) -> np.ndarray:
    """:func:`~annotators.geometry.grid_segmentation.grow_on_surface` in one pass per round over the pixels."""
    return _loops().surface_growth(labels, region, depth, absolute, relative, rounds)


def dense_keys(keys: np.ndarray) -> np.ndarray:
    """HxW non-negative integer ``keys`` (0 = none) renumbered 1..n in increasing order, as int32."""
    return _loops().dense_keys(keys)


def cell_patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
    """:func:`~annotators.geometry.convexity.grid_patches`: each labelled surface cut into ``cell`` x ``cell``
    cells, the (surface, cell) pairs numbered 1..n in increasing order of surface, then cell (row-major)."""
    return _loops().cell_patches(surfaces, cell)


def graph_components(pairs: np.ndarray, count: int) -> np.ndarray:
    """The connected component (int64) of each of ``count`` nodes of the undirected graph with the edges ``pairs``
    (Kx2 integer), numbered 0.. in order of each component's smallest node - as
    ``scipy.sparse.csgraph.connected_components`` numbers them."""
    return _loops().graph_components(np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2), count)


def nearest_seed_labels(
    window: np.ndarray,
    unlabelled: np.ndarray,
    distance: np.ndarray,
    nearest: np.ndarray,
    max_distance: float,
    grown: np.ndarray,
) -> None:
    """After ``cv2.distanceTransformWithLabels`` of the unlabelled pixels of the HxW labels ``window`` (one label
    per seed pixel, ``DIST_LABEL_PIXEL``): the ``unlabelled`` pixels within ``max_distance`` (compared in float32,
    as numpy compares the float32 ``distance``) take the label of their nearest seed, written into ``grown`` (HxW,
    may be ``window`` itself or a copy)."""
    _loops().nearest_seed_labels(window, unlabelled, distance, nearest, np.float32(max_distance), grown)


def unlabelled_box(labels: np.ndarray, region: np.ndarray, margin: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """The pixels of ``region`` (HxW bool) that HxW ``labels`` leave at 0, their box ``(x0, y0, x1, y1)``
    (exclusive) grown by ``margin`` and clipped to the grid, and whether there is anything to grow (such a pixel
    and a labelled one): ``region & (labels == 0)`` and its :func:`~annotators.geometry.grid_segmentation.bounding_box`
    in one pass."""
    return _loops().unlabelled_box(labels, np.ascontiguousarray(region, dtype=bool), margin)


def finite_rows(values: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The rows ``indices`` of NxK ``values`` whose entries are all finite, in the order given:
    ``values[indices][np.isfinite(values[indices]).all(axis=1)]`` in one pass."""
    return _loops().finite_rows(values, indices)


def jump_between(z_a: float, z_b: float, absolute: float, relative: float) -> bool:
    """:func:`~annotators.geometry.grid_segmentation.depth_jump` of two depths, both taken as float32 (float32
    arithmetic, as numpy does it for two float32 scalars)."""
    return _loops().jump_between(np.float32(z_a), np.float32(z_b), absolute, relative)


def window_counts(labels: np.ndarray, count: int) -> np.ndarray:
    """The number of pixels of each label ``0..count`` in HxW ``labels`` (any strides, e.g. a window of a larger
    grid; labels at most ``count``): ``np.bincount(labels.reshape(-1), minlength=count + 1)`` without a copy."""
    return _loops().window_counts(labels, count)


def strided_crop(values: np.ndarray, step: int, box: tuple[int, int, int, int]) -> np.ndarray:
    """``np.ascontiguousarray(values[::step, ::step][y0:y1, x0:x1])`` of HxW or HxWxC ``values`` for the ``box``
    ``(x0, y0, x1, y1)`` (exclusive, within the subsampled grid), in one pass."""
    x0, y0, x1, y1 = box
    if values.ndim == 2:
        return _loops().strided_crop(values[..., None], step, x0, y0, x1, y1)[..., 0]
    return _loops().strided_crop(values, step, x0, y0, x1, y1)


def groups_unless_apart(
    count: int,
    pairs: np.ndarray,
    apart: np.ndarray,
    weak: np.ndarray | None = None,
    sizes: np.ndarray | None = None,
    least: float = np.inf,
) -> np.ndarray:
    """The group (its root node, int64) of each of ``count`` nodes: the ``pairs`` (Kx2) joined in the order given,
    the second's group under the first's root, except where that would put the two nodes of an ``apart`` pair (Mx2)
    into one group (direct evidence that two parts are separate outweighs an indirect path between them), or where a
    ``weak`` pair (K bools) would join two groups whose node ``sizes`` (``count``) each sum to ``least`` or more
    (weak evidence may attach a small group to a large one, not join two large ones)."""
    pairs = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
    return _loops().groups_unless_apart(
        count,
        pairs,
        np.ascontiguousarray(apart, dtype=np.int64).reshape(-1, 2),
        np.zeros(pairs.shape[0], dtype=np.bool_) if weak is None else np.ascontiguousarray(weak, dtype=np.bool_),
        np.zeros(count) if sizes is None else np.ascontiguousarray(sizes, dtype=np.float64),
        float(least),
    )


def joined_labels(labels: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """HxW int32: ``labels`` (HxW, non-negative integers) with every connected group of the label ``pairs`` (Kx2)
    joined, renumbered 1..n in order of each group's smallest present label (0 stays 0)."""
    return _loops().joined_labels(labels, np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2))


def plane_coordinates(points: np.ndarray, to_plane: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Nx3 float32: ``points @ to_plane + offset`` of Nx3 float32 ``points``, a 3x3 float32 ``to_plane`` and a
    float32 ``offset`` (3), each product sum rounded as OpenBLAS's float32 matrix product rounds it on machines
    with fused multiply-add (the first product, then the other two fused in row order), in one single-threaded
    pass: numpy's product starts BLAS threads for a few ten thousand rows, which cost far more than the sums."""
    return _loops().plane_coordinates(
        np.ascontiguousarray(points, dtype=np.float32),
        np.ascontiguousarray(to_plane, dtype=np.float32),
        np.ascontiguousarray(offset, dtype=np.float32),
    )


@functools.cache
def _footprint_loops() -> ModuleType:
    """:mod:`annotators.geometry.footprint_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import footprint_loops

    return footprint_loops


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Kx2: the convex hull of Nx2 float ``points`` (counter-clockwise, no collinear vertices; fewer than three
    points are returned as they are), in their dtype. A strided view (two columns of a wider array) is read in
    place."""
    return _footprint_loops().convex_hull(np.asarray(points))


def outside_extents(near: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """The extents of a part seen as a container's outside, from its Nx3 plane coordinates ``(u, v, height)``
    (N >= 1) and its heights sorted: 8 float64, the unit direction ``along`` the line of sight (the centroid's
    horizontal direction from the camera's foot, 2), the 5 % and 95 % positions across it, the 95 % height (the
    rim), the 5 % and 50 % positions along it, and the centroid's distance; NaN everywhere when the centroid lies
    within a micrometre of the camera's foot. Positions are sorted-order quantiles at index ``round(q (n - 1))``."""
    return _footprint_loops().outside_extents(
        np.ascontiguousarray(near, dtype=np.float32), np.ascontiguousarray(heights, dtype=np.float32)
    )


def footprint_shares(
    vertices: np.ndarray, starts: np.ndarray, boxes: np.ndarray, pairs: np.ndarray, count: int
) -> np.ndarray:
    """float64 (``count``): for each of the ``pairs`` (indices k < ``count``) the cells shared by convex polygons
    k and ``count + k`` over the smaller one's cells, 0 for the others. Polygon j has the integer (Nx2) ``vertices
    [starts[j]:starts[j + 1]]`` on the raster of its bounding cells ``boxes[j]`` = ``(x, y, width, height)`` (integer
    cells of one grid, its vertices relative to ``(x, y)``); it covers, in each row, the cells it touches within
    the row's band (a polygon edge-on, a line, still covers one cell per row)."""
    return _footprint_loops().footprint_shares(
        np.ascontiguousarray(vertices, dtype=np.int64),
        np.ascontiguousarray(starts, dtype=np.int64),
        np.ascontiguousarray(boxes, dtype=np.int64),
        np.ascontiguousarray(pairs, dtype=np.int64),
        count,
    )


def nearest_labels_within(labels: np.ndarray, region: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """HxW ``labels`` with each unlabelled pixel of ``region`` (HxW bool) given the label (> 0) of the first
    labelled pixel found at the ``offsets`` (Kx2 int64 row, column offsets, nearest first) from it; unlabelled
    when none is. Only the unlabelled pixels of the region are visited."""
    return _loops().nearest_labels_within(
        np.ascontiguousarray(labels),
        np.ascontiguousarray(region, dtype=bool),
        np.ascontiguousarray(offsets, dtype=np.int64),
    )


def sampled_median(values: np.ndarray, indices: np.ndarray, step: int) -> float:
    """The median of ``values[indices[::step]]`` (1-D float ``values``, int ``indices``), in float64; NaN when
    one of them is NaN or there are none."""
    return _loops().sampled_median(values, indices, step)


def sight_extents(points: np.ndarray, along: np.ndarray) -> np.ndarray:
    """4 float64 of Nx3 plane coordinates ``points`` (N >= 1) seen along the unit horizontal direction ``along``:
    the 5 % and 95 % positions across it (``(-along[1], along[0])``) and the 50 % and 95 % positions along it
    (sorted-order quantiles at index ``round(q (n - 1))``)."""
    return _footprint_loops().sight_extents(
        np.ascontiguousarray(points, dtype=np.float32), float(along[0]), float(along[1])
    )


@functools.cache
def _merge_loops() -> ModuleType:
    """:mod:`annotators.geometry.merge_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import merge_loops

    return merge_loops


def sampled_pixels(
    pixels: np.ndarray, starts: np.ndarray, labels: np.ndarray, most: int
) -> tuple[np.ndarray, np.ndarray]:
    """About ``most`` evenly sampled pixels of each of the ``labels`` (label k owns ``pixels[starts[k]:starts[k +
    1]]``): ``own[::max(1, own.size // most)]`` of each, concatenated, and ``offsets`` (one more than labels in
    ``starts``) so label k's sample is ``sampled[offsets[k]:offsets[k + 1]]`` (empty for the labels not asked)."""
    return _merge_loops().sampled_pixels(
        np.ascontiguousarray(pixels), np.ascontiguousarray(starts, dtype=np.int64), np.asarray(labels, np.int64), most
    )


def part_hulls(coordinates: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The :func:`convex_hull` of the ``(u, v)`` of each part k's plane coordinates ``coordinates[offsets[k]:offsets[k
    + 1]]`` (float32, Nx3), concatenated, and their offsets (the same form; empty for a part without coordinates).
    Raises ValueError for a coordinate that is not finite (the compiled hull would come out wrong, or crash)."""
    coordinates = np.ascontiguousarray(coordinates, dtype=np.float32)
    if not np.isfinite(coordinates[:, :2]).all():
        raise ValueError("part_hulls: plane coordinates must be finite (a labelled pixel without depth?)")
    return _merge_loops().part_hulls(coordinates, np.ascontiguousarray(offsets, dtype=np.int64))


def pair_evidence(
    coordinates: np.ndarray,
    heights: np.ndarray,
    offsets: np.ndarray,
    depth: np.ndarray,
    pixels: np.ndarray,
    starts: np.ndarray,
    pairs: np.ndarray,
    overlapping: np.ndarray,
    unjoined: np.ndarray,
    tolerances: tuple[float, float, float, float, float, float],
    inside: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What merging needs to know of touching pairs of parts (``pairs``, Px2), in one pass.

    Part k has the (float32, Nx3 ``(u, v, height)``) plane ``coordinates[offsets[k]:offsets[k + 1]]`` of its sampled
    pixels, their heights sorted in ``heights`` (the same offsets), and owns ``pixels[starts[k]:starts[k + 1]]``
    (flat indices into the 1-D float ``depth``). ``tolerances`` are the nest tolerance, the inside tolerance, the
    inside depth ratio, the rim band, the floor flatness and the inner spread of
    :mod:`~annotators.geometry.grid_segmentation`. Returns, per pair:

    * for the ``overlapping`` pairs, whether their heights nest (``heights_nest``), and when they do not, whether
      the first (bit 1) or the second (bit 2) passes the height and flatness tests of a floor within the other
      (``is_floor_within`` without its hull test);
    * for the ``unjoined`` pairs (with ``inside``), whether the outside of the nearer (the median depth of every
      ``size // 500``-th pixel) could hold the farther (``ContainerOutside.could_hold``).

    Quantiles are sorted-order quantiles at index ``round(q (n - 1))``; each part's are computed once, when first
    needed.
    """
    return _merge_loops().pair_evidence(
        np.ascontiguousarray(coordinates, dtype=np.float32),
        np.ascontiguousarray(heights, dtype=np.float32),
        np.ascontiguousarray(offsets, dtype=np.int64),
        np.ascontiguousarray(depth).reshape(-1),
        np.ascontiguousarray(pixels),
        np.ascontiguousarray(starts, dtype=np.int64),
        np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2),
        np.ascontiguousarray(overlapping, dtype=bool),
        np.ascontiguousarray(unjoined, dtype=bool),
        np.array(tolerances, dtype=np.float64),
        inside,
    )
