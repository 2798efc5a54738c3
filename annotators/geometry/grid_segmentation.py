"""Segmentation primitives on the organized pixel grid: cuts, labelling, growing and merging of parts.

All functions take HxW (or HxWx3) arrays of one region of the image and work with whole-array operations,
OpenCV and the compiled loops of :mod:`annotators.geometry.grid_kernels`, never with per-point Python loops; labels
are int32 with 0 meaning "no part".
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from annotators.geometry.grid_kernels import (
    boundary_pairs,
    connected_parts,
    footprint_shares,
    groups_unless_apart,
    joined_labels,
    label_pixels,
    nearest_labels_within,
    nearest_seed_labels,
    outside_extents,
    pair_evidence,
    part_hulls,
    sampled_pixels,
    seam_pixels,
    sight_extents,
    surface_growth,
    touching_keys,
    unlabelled_box,
)


def depth_jump(z_a: np.ndarray, z_b: np.ndarray, absolute: float, relative: float) -> np.ndarray:
    """True where two neighbouring depths differ by more than ``absolute + relative * nearer depth``."""
    with np.errstate(invalid="ignore"):
        if np.ndim(z_a) == 0 or np.ndim(z_b) == 0:
            return np.abs(z_a - z_b) > absolute + relative * np.fmin(z_a, z_b)
        difference = np.subtract(z_a, z_b)  # the same arithmetic as above, in place on two temporaries
        np.abs(difference, out=difference)
        limit = np.fmin(z_a, z_b)
        np.multiply(limit, relative, out=limit)
        np.add(limit, absolute, out=limit)
        return np.greater(difference, limit, out=np.empty(difference.shape, dtype=bool))


def depth_seams(depth: np.ndarray, candidates: np.ndarray, absolute: float, relative: float) -> np.ndarray:
    """HxW bool: candidate pixels with a nearer candidate 4-neighbour across a depth discontinuity.

    Only the far pixel of such a pair is marked, so an occluding object keeps its full outline while the
    pixel behind it is cut away; 4-connected labelling then cannot cross the discontinuity.
    """
    return seam_pixels(np.ascontiguousarray(depth, dtype=np.float32), candidates, absolute, relative)


def _read_only(array: np.ndarray) -> np.ndarray:
    """``array``, made read-only (a module-level table)."""
    array.flags.writeable = False
    return array


_HUE_COS = _read_only(np.cos(np.arange(256, dtype=np.float32) * np.float32(2 * np.pi / 256)))
_HUE_SIN = _read_only(np.sin(np.arange(256, dtype=np.float32) * np.float32(2 * np.pi / 256)))
_VALUE_WEIGHT = _read_only(np.clip((np.arange(256, dtype=np.float32) - 25) / 40, 0, 1))
"""Per 8-bit hue and value of :func:`chroma_image`: the cosine and sine of the hue angle and the dark fade-out."""


def chroma_image(colors: np.ndarray) -> np.ndarray:
    """A shading-invariant 2-channel uint8 image: hue as an angle scaled by saturation, faded out on dark pixels.

    The channels are ``128 + 127 * s * w * (cos h, sin h)`` with ``w`` ramping from 0 to 1 between values
    25 and 65, so shading of one surface (same hue and saturation) gives no edge while a change of hue does.
    The trigonometry and the ramp are table look-ups over the 256 hue and value levels.
    """
    hsv = cv2.cvtColor(cv2.GaussianBlur(colors, (5, 5), 0), cv2.COLOR_RGB2HSV_FULL)
    hue, saturation, value = cv2.split(hsv)
    weight = cv2.LUT(value, _VALUE_WEIGHT)
    weight *= saturation
    weight *= np.float32(127 / 255)
    chroma = np.empty((*colors.shape[:2], 2), dtype=np.uint8)
    for channel, table in ((0, _HUE_COS), (1, _HUE_SIN)):
        value = cv2.LUT(hue, table)
        value *= weight
        value += 128
        chroma[..., channel] = np.clip(value, 0, 255, out=value)
    return chroma


def color_edges(colors: np.ndarray, low: float, high: float) -> np.ndarray:
    """HxW bool: Canny edges (thresholds ``low``/``high``) of the :func:`chroma_image` - changes of hue (Canny
    follows, at each pixel, the channel with the larger gradient)."""
    return chroma_edges(chroma_image(np.ascontiguousarray(colors)), low, high)


def chroma_edges(chroma: np.ndarray, low: float, high: float) -> np.ndarray:
    """:func:`color_edges` of the colours whose :func:`chroma_image` is ``chroma``."""
    return cv2.Canny(chroma, low, high) > 0


def label_parts(region: np.ndarray, min_points: int) -> np.ndarray:
    """4-connected components of ``region`` with at least ``min_points`` pixels, labelled 1..n (int32)."""
    return connected_parts(np.ascontiguousarray(region, dtype=bool), min_points)


def grow_labels(labels: np.ndarray, region: np.ndarray, max_distance: float) -> np.ndarray:
    """Give every unlabelled pixel of ``region`` the label of the nearest labelled pixel within ``max_distance`` px.

    The distance transform runs on the box of those pixels grown by the farthest a seed within ``max_distance``
    can lie (its 3x3 chamfer distance is at least 0.955 times the larger coordinate difference), so every pixel
    it gives a label sees the same seeds and paths as on the whole grid.
    """
    return grow_from_seeds(labels, seed_distances(labels, region, max_distance), max_distance)


def grow_labels_nearby(labels: np.ndarray, region: np.ndarray, max_distance: float) -> np.ndarray:
    """:func:`grow_labels` for a short reach, by looking around each unlabelled pixel of ``region`` rather than
    transforming the whole box of them: every such pixel takes the label of the nearest labelled pixel within
    ``max_distance`` px (Euclidean; of pixels at one distance, the first in row-major order of the offsets). Its
    work grows with the unlabelled pixels times the disc's area, not with the box; the labels differ from
    :func:`grow_labels` (a chamfer distance transform) only where two labels' pixels lie about as near."""
    return nearest_labels_within(labels, region, disc_offsets(max_distance))


def disc_offsets(radius: float) -> np.ndarray:
    """Kx2 int64 ``(row, column)`` offsets of the pixels within ``radius`` of the origin (the origin left out),
    nearest first, then row-major."""
    reach = int(np.floor(radius))
    rows, cols = np.mgrid[-reach : reach + 1, -reach : reach + 1]
    squared = rows * rows + cols * cols
    within = (squared > 0) & (squared <= radius * radius)
    order = np.lexsort((cols[within], rows[within], squared[within]))
    return np.column_stack([rows[within][order], cols[within][order]]).astype(np.int64)


@dataclass(frozen=True)
class SeedDistances:
    """The distance transform :func:`grow_labels` runs, kept to grow other labels on the same labelled pixels:
    the unlabelled pixels of the region (HxW bool), the box ``(x0, y0, x1, y1)`` the transform covers, and per
    pixel of the box the distance to and the index of the nearest labelled pixel (OpenCV's pixel labels)."""

    unlabelled: np.ndarray
    box: tuple[int, int, int, int]
    distance: np.ndarray
    nearest: np.ndarray


def seed_distances(labels: np.ndarray, region: np.ndarray, max_distance: float) -> SeedDistances | None:
    """The distance transform :func:`grow_labels` runs to grow ``labels`` into ``region`` by up to ``max_distance``
    px; None when nothing can grow (no unlabelled pixel of the region, or no labelled pixel within its box)."""
    unlabelled, box, growing = unlabelled_box(labels, region, int(np.ceil(max_distance / 0.95)) + 2)
    if not growing:
        return None
    x0, y0, x1, y1 = box.tolist()
    seeds = labels[y0:y1, x0:x1] > 0
    if not seeds.any():
        return None
    distance, nearest = cv2.distanceTransformWithLabels(
        (~seeds).view(np.uint8), cv2.DIST_L2, 3, labelType=cv2.DIST_LABEL_PIXEL
    )
    return SeedDistances(unlabelled, (x0, y0, x1, y1), distance, nearest)


def grow_from_seeds(labels: np.ndarray, seeds: SeedDistances | None, max_distance: float) -> np.ndarray:
    """:func:`grow_labels` from a transform :func:`seed_distances` made for labels with the same labelled pixels
    as ``labels`` (any label values) and a ``max_distance`` at least this one: a box that covers every seed within
    the farther reach covers those within the nearer one, so the labels grow as on the whole grid."""
    if seeds is None:
        return labels
    x0, y0, x1, y1 = seeds.box
    grown = labels.copy()
    nearest_seed_labels(
        labels[y0:y1, x0:x1],
        seeds.unlabelled[y0:y1, x0:x1],
        seeds.distance,
        seeds.nearest,
        max_distance,
        grown[y0:y1, x0:x1],
    )
    return grown


def grow_on_surface(
    labels: np.ndarray, region: np.ndarray, depth: np.ndarray, absolute: float, relative: float, rounds: int = 2
) -> np.ndarray:
    """Give unlabelled pixels of ``region`` the label of a 4-neighbour on the same surface (no depth jump).

    Used for the far pixels of depth discontinuities: they join the surface they belong to, never the occluder
    in front of them, so an occluder and what it hides do not touch in the label image. Each round reads the
    labels of the round before; a pixel takes its left, right, upper or lower neighbour's label, the first that
    qualifies. Only the unlabelled pixels are visited.
    """
    return surface_growth(labels, region, np.asarray(depth, dtype=np.float32), absolute, relative, rounds)


def distinct_keys(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(keys, return_inverse=True)`` of 1-D integer keys: the distinct keys in increasing order and the
    index of each key among them, by a stable sort (which is much faster than numpy's default one on integers that
    come in runs, as the keys of pixel pairs along a boundary do)."""
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]
    first = np.ones(ordered.size, dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    inverse = np.empty(keys.size, dtype=np.intp)
    inverse[order] = np.cumsum(first) - 1
    return ordered[first], inverse


def touching_pairs(labels: np.ndarray) -> np.ndarray:
    """Kx2 int array of the distinct label pairs ``(a, b)``, ``0 < a < b``, that touch as 4-neighbours."""
    base = int(labels.max(initial=0)) + 1
    ordered = np.sort(touching_keys(np.ascontiguousarray(labels), base), kind="stable")  # see distinct_keys
    first = np.ones(ordered.size, dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    keys = ordered[first]
    return np.column_stack([keys // base, keys % base])


def label_groups(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Flat pixel indices sorted by label (increasing within one) and ``starts`` so label k owns
    ``pixels[starts[k]:starts[k + 1]]``."""
    pixels, starts, _ = label_pixels(np.ascontiguousarray(labels))
    return pixels, starts


def footprint_overlap(first: np.ndarray, second: np.ndarray, cell: float) -> float:
    """Area shared by two convex polygons (Nx2, metres) over the smaller one's, measured on a ``cell`` raster.

    The raster gives even a degenerate footprint (a wall seen edge-on is a line) an area of one cell width.
    """
    return float(footprint_overlaps([first], [second], cell)[0])


def footprint_overlaps(firsts: Sequence[np.ndarray], seconds: Sequence[np.ndarray], cell: float) -> np.ndarray:
    """:func:`footprint_overlap` of every pair ``(firsts[k], seconds[k])`` of convex polygons (Nx2, metres).

    The bounds, the test for footprints apart and the raster vertices of all polygons are computed at once, the
    shared cells of the pairs near each other in one compiled pass (:func:`footprint_shares`).
    """
    count = len(firsts)
    if count == 0:
        return np.zeros(0)
    hulls = [*firsts, *seconds]
    sizes = np.array([hull.shape[0] for hull in hulls])
    starts = np.cumsum(sizes) - sizes
    stacked = np.concatenate(hulls)
    lows, highs = np.minimum.reduceat(stacked, starts, axis=0), np.maximum.reduceat(stacked, starts, axis=0)
    first_low, second_low = lows[:count], lows[count:]
    overlap = np.minimum(highs[:count], highs[count:]) - np.maximum(first_low, second_low)
    near = ~np.any(overlap < -cell, axis=1)  # the footprints' bounding boxes are apart: nothing to rasterize
    low = np.minimum(first_low, second_low)
    # each polygon on the raster of its own bounding cells; the shared cells where the two rasters overlap
    vertices = np.round((stacked - np.repeat(np.concatenate([low, low]), sizes, axis=0)) / cell).astype(np.int32)
    corner = np.minimum.reduceat(vertices, starts, axis=0)
    far_corner = np.maximum.reduceat(vertices, starts, axis=0) + 1
    boxes = np.column_stack([corner, far_corner - corner])  # x, y, width, height of the cells spanned
    vertices -= np.repeat(corner, sizes, axis=0)  # each polygon's vertices on its own raster
    return footprint_shares(vertices, np.append(starts, stacked.shape[0]), boxes, np.flatnonzero(near), count)


def join_labels(labels: np.ndarray, pairs: list[tuple[int, int]]) -> np.ndarray:
    """Labels with every connected group of ``pairs`` joined, renumbered 1..n in order of first label."""
    return joined_labels(np.asarray(labels), np.asarray(pairs, dtype=np.int64))


def _sorted_range(ordered: np.ndarray, low: float, high: float) -> tuple[float, float]:
    """The ``low`` and ``high`` quantiles (0..1) of a sorted 1-D array (the values at ``round(q (n - 1))``)."""
    last = ordered.size - 1
    return float(ordered[round(low * last)]), float(ordered[round(high * last)])


RIM_BAND = 0.5
"""A part spanning at most this share of another's heights, or starting above this share of them, lies in the band
of a rim: a handle, an inner wall seen over the rim of a cup or bowl, or the top of its outer wall (the rest hidden
or cut off). It is measured against the other's top (99 %), since the rim is a container's highest point and
reaches above the body's 95 % height. A neighbour standing beside the other on the table does neither."""


def heights_nest(first: np.ndarray, second: np.ndarray, tolerance: float) -> bool:
    """Does the 5 %-95 % range of one set of heights above the plane lie within the other's (``tolerance`` metres
    of slack)? A container's inside or handle lies within its body's heights; an object standing on another lies
    above it. A part in the rim band (:data:`RIM_BAND`) may reach up to the other's top instead of its 95 % height;
    a neighbour of about the same height, standing beside it, never counts as in the rim band, so its top must nest
    strictly.
    """
    return _sorted_heights_nest(np.sort(first), np.sort(second), tolerance)


def _sorted_heights_nest(first: np.ndarray, second: np.ndarray, tolerance: float) -> bool:
    """:func:`heights_nest` of heights already sorted."""
    ranges = [_sorted_range(heights, 0.05, 0.95) for heights in (first, second)]
    tops = [_sorted_range(heights, 0.05, 0.99)[1] for heights in (first, second)]
    for inner, outer in ((0, 1), (1, 0)):
        (low_in, high_in), (low_out, high_out) = ranges[inner], ranges[outer]
        span = high_out - low_out
        in_band = high_in - low_in <= RIM_BAND * span or low_in >= low_out + RIM_BAND * span
        top = tops[outer] if in_band else high_out
        if low_in >= low_out - tolerance and high_in <= top + tolerance:
            return True
    return False


FLOOR_FLATNESS = 0.1
"""A part is a horizontal surface when its heights (5 %-95 %) spread over at most this share of its width."""

FLOOR_INSIDE = 0.9
"""The share of a floor's footprint that must lie within the hull of the part around it."""


def is_floor_within(
    first: np.ndarray, second: np.ndarray, hull_first: np.ndarray, hull_second: np.ndarray, rules: MergeRules
) -> bool:
    """Is one of two parts (Nx3 plane coordinates, hulls Kx2) the floor of a container whose walls are the other?

    A horizontal surface seen from above inside the footprint of a part standing higher is not covered by it -
    what rests on a surface covers it - so the higher part surrounds it: the floor of a bowl or cup seen through
    its opening, below its walls' visible heights, not an object the walls stand on. The floor is flat
    (:data:`FLOOR_FLATNESS`), lies within the other's hull (:data:`FLOOR_INSIDE` of its footprint) and no higher
    than the other's lowest heights (5 %, with ``rules.nest_tolerance``).
    """
    return _sorted_floor_within(np.sort(first, axis=0), np.sort(second, axis=0), hull_first, hull_second, rules)


def _sorted_floor_within(
    first: np.ndarray, second: np.ndarray, hull_first: np.ndarray, hull_second: np.ndarray, rules: MergeRules
) -> bool:
    """:func:`is_floor_within` of plane coordinates whose columns are each sorted."""
    for floor, walls, floor_hull, walls_hull in (
        (first, second, hull_first, hull_second),
        (second, first, hull_second, hull_first),
    ):
        low, high = _sorted_range(floor[:, 2], 0.05, 0.95)
        if high > _sorted_range(walls[:, 2], 0.05, 0.95)[0] + rules.nest_tolerance:
            continue
        width = float(np.max([np.subtract(*_sorted_range(floor[:, axis], 0.95, 0.05)) for axis in (0, 1)]))
        if high - low > FLOOR_FLATNESS * width:
            continue
        if inside_share(floor_hull, walls_hull, rules.cell) >= FLOOR_INSIDE:
            return True
    return False


def inside_share(inner: np.ndarray, outer: np.ndarray, cell: float) -> float:
    """The share of convex polygon ``inner``'s cells (Nx2, metres, on a ``cell`` raster) inside ``outer``."""
    low = np.minimum(inner.min(axis=0), outer.min(axis=0))
    vertices = [np.round((hull - low) / cell).astype(np.int32) for hull in (inner, outer)]
    size = np.maximum(vertices[0].max(axis=0), vertices[1].max(axis=0)) + 1
    rasters = []
    for vertex in vertices:
        raster = np.zeros((int(size[1]), int(size[0])), dtype=np.uint8)
        cv2.fillConvexPoly(raster, vertex, 1)
        rasters.append(raster.view(bool))
    return np.count_nonzero(rasters[0] & rasters[1]) / max(1, np.count_nonzero(rasters[0]))


INNER_SPREAD = 0.1
"""An inner surface of a container falls away from the rim: its 50 %-95 % height spread is at least this share of
the rim height (or it lies in the lower half); the flat top of an object standing behind does not."""


def looks_like_inside(near: np.ndarray, far: np.ndarray, tolerance: float, depth_ratio: float) -> bool:
    """Could part ``far`` be the inside of an open container whose outside is part ``near``?

    Both are Nx3 plane coordinates ``(u, v, height)`` with the camera's foot at ``u = v = 0``. Seen from above,
    the front rim of a cup or bowl hides part of its inside: the inside is then farther along the line of sight,
    within the outside's width across it, no higher than its rim, and no deeper than ``depth_ratio`` times its
    width, and it falls away below the rim (:data:`INNER_SPREAD`). A separate object behind is wider, taller,
    elsewhere or flat on top. Robust 5 % / 95 % quantiles are used.
    """
    outside = container_outside(near, tolerance)
    return outside is not None and outside.could_hold(far, depth_ratio)


@dataclass(frozen=True)
class ContainerOutside:
    """A part seen as the outside of a possible container (see :func:`looks_like_inside`): the horizontal
    directions ``along`` the line of sight and ``across`` it, its 5 %-95 % extent across (``low``, ``high``) with
    the ``margin`` allowed beyond it, its ``rim`` height (95 %), and its front (5 %) and middle along the line."""

    along: np.ndarray
    across: np.ndarray
    low: float
    high: float
    margin: float
    rim: float
    front: float
    middle: float

    def could_hold(self, far: np.ndarray, depth_ratio: float, far_heights: np.ndarray | None = None) -> bool:
        """Could part ``far`` (Nx3 plane coordinates) be the inside of this container? ``far_heights``, when
        given, are ``far``'s heights sorted (then not sorted again). Each test only rules out, so their order does
        not change the answer."""
        if far.shape[0] < 3:
            return False
        far_median, far_top = _sorted_range(np.sort(far[:, 2]) if far_heights is None else far_heights, 0.5, 0.95)
        if far_top > self.rim + self.margin:
            return False
        if not (far_top - far_median >= INNER_SPREAD * self.rim or far_median <= 0.5 * self.rim):
            return False
        far_low, far_high, far_middle, far_back = sight_extents(far, self.along).tolist()
        if far_low < self.low - self.margin or far_high > self.high + self.margin:
            return False
        return not (far_middle <= self.middle or far_back > self.front + depth_ratio * (self.high - self.low))


def container_outside(
    near: np.ndarray, tolerance: float, near_heights: np.ndarray | None = None
) -> ContainerOutside | None:
    """Part ``near`` (Nx3 plane coordinates) as the outside of a possible container (``tolerance`` metres of
    margin at least); None when it has too few points or lies right below the camera. ``near_heights``, when
    given, are ``near``'s heights sorted (then not sorted again)."""
    if near.shape[0] < 3:
        return None
    extents = outside_extents(near, np.sort(near[:, 2]) if near_heights is None else near_heights)
    if not np.isfinite(extents[7]):
        return None
    along = extents[:2]
    across = np.array([-along[1], along[0]])
    near_low, near_high, rim, near_front, near_middle = extents[2:7].tolist()
    margin = max(tolerance, 0.1 * (near_high - near_low))
    return ContainerOutside(along, across, near_low, near_high, margin, rim, near_front, near_middle)


def _median(values: np.ndarray) -> np.floating:
    """``np.median`` of a 1-D array (the same value, NaN when one is NaN) by one partition, without its overhead."""
    if values.size == 0 or np.isnan(values).any():
        return np.median(values)
    low, high = (values.size - 1) // 2, values.size // 2
    ordered = np.partition(values, (low, high))
    return (ordered[low] + ordered[high]) / values.dtype.type(2)


def _without_strays(
    coordinates: np.ndarray, offsets: np.ndarray, spilled: np.ndarray, share: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each part's coordinates (``coordinates[offsets[k]:offsets[k + 1]]``) without those ``spilled`` marks where
    they are strays, at most ``share`` of the part's (more are the shape of a piece cut at an outline, kept) and at
    least three remain; the new offsets, and which parts lost some (bool per part)."""
    counts = np.diff(offsets)
    part = np.repeat(np.arange(counts.size), counts)
    spilled_counts = np.bincount(part[spilled], minlength=counts.size)
    remaining = counts - spilled_counts
    thinned = (spilled_counts > 0) & (spilled_counts <= share * counts) & (remaining >= 3)
    keep = ~(spilled & thinned[part])
    kept_offsets = np.concatenate([[0], np.cumsum(np.where(thinned, remaining, counts))]).astype(offsets.dtype)
    return np.ascontiguousarray(coordinates[keep]), kept_offsets, thinned


class _PartEvidence:
    """What :func:`merge_parts` asks of the touching parts (those of ``pairs``, Kx2): each part's plane coordinates
    (of about 400 of its pixels, evenly sampled), their heights sorted and the footprint hull, computed at once
    (:func:`~annotators.geometry.grid_kernels.part_hulls`); the nesting, floor and container tests of the pairs
    (:meth:`evidence`). Where ``spilled`` (flat bool, or None) marks a few of a part's samples (at most
    ``stray_share`` of them), the part has a second hull without them (:meth:`kept_hull`)."""

    def __init__(
        self,
        labels: np.ndarray,
        depth: np.ndarray,
        plane_coordinates: Callable[[np.ndarray], np.ndarray] | np.ndarray,
        pairs: np.ndarray,
        spilled: np.ndarray | None = None,
        stray_share: float = 0.0,
    ):
        self.pixels, self.starts = label_groups(labels)
        self.depth = depth
        self.pairs = pairs
        sampled, self.offsets = sampled_pixels(self.pixels, self.starts, np.unique(pairs), 400)
        touching = np.flatnonzero(np.diff(self.offsets)).tolist()
        if isinstance(plane_coordinates, np.ndarray):
            self.points = np.asarray(plane_coordinates[sampled], dtype=np.float32)
        else:
            self.points = np.concatenate(
                [plane_coordinates(sampled[self.offsets[k] : self.offsets[k + 1]]) for k in touching],
                dtype=np.float32,
            )
        self.heights = self.points[:, 2].copy()
        for k in touching:
            self.heights[self.offsets[k] : self.offsets[k + 1]].sort()
        self.hulls, self.hull_offsets = part_hulls(self.points, self.offsets)
        self.thinned = np.zeros(self.offsets.size - 1, dtype=bool)
        if spilled is not None and spilled[sampled].any():
            kept, kept_offsets, self.thinned = _without_strays(self.points, self.offsets, spilled[sampled], stray_share)
            self.kept_hulls, self.kept_hull_offsets = part_hulls(kept, kept_offsets)

    def coordinates(self, label: int) -> np.ndarray:
        """Plane coordinates of about 400 of the part's pixels, evenly sampled."""
        return self.points[self.offsets[label] : self.offsets[label + 1]]

    def hull(self, label: int) -> np.ndarray:
        """The convex hull of the part's footprint (Kx2)."""
        return self.hulls[self.hull_offsets[label] : self.hull_offsets[label + 1]]

    def kept_hull(self, label: int) -> np.ndarray:
        """The convex hull of the part's footprint without its spilled pixels (:meth:`hull` when it has none)."""
        if not self.thinned[label]:
            return self.hull(label)
        return self.kept_hulls[self.kept_hull_offsets[label] : self.kept_hull_offsets[label + 1]]

    def evidence(
        self, overlapping: np.ndarray, unjoined: np.ndarray, rules: MergeRules
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per pair: whether the heights of the ``overlapping`` ones nest; if not, which of them may be a floor
        within the other (bits 1, 2: the first, the second; :meth:`floor_within` asks the hulls); whether the nearer
        of the ``unjoined`` ones could hold the farther (:func:`~annotators.geometry.grid_kernels.pair_evidence`)."""
        return pair_evidence(
            self.points,
            self.heights,
            self.offsets,
            self.depth,
            self.pixels,
            self.starts,
            self.pairs,
            overlapping,
            unjoined,
            rules.pair_tolerances(),
            rules.inside,
        )

    def floor_within(self, first: int, second: int, floors: int, cell: float) -> bool:
        """:func:`is_floor_within` of two parts, whose height and flatness tests ``floors`` holds (bit 1: the first
        as the floor, bit 2: the second)."""
        for bit, floor, walls in ((1, first, second), (2, second, first)):
            if floors & bit and inside_share(self.hull(floor), self.hull(walls), cell) >= FLOOR_INSIDE:
                return True
        return False


@dataclass(frozen=True)
class Boundaries:
    """What the shared boundary of each pair of touching parts looks like in 3-D.

    ``pairs`` (Kx2, a < b) are the touching labels; ``length`` counts their 4-neighbour pixel pairs;
    ``continuous`` is the share of those without a depth jump; ``close`` the share whose points are at most
    ``close_factor`` pixel footprints apart in 3-D (one surface going on, not two objects side by side a few
    millimetres apart in depth); over the continuous ones with known normals,
    ``alignment`` is the mean cosine between the two normals and ``convexity`` the mean of
    ``(n_a - n_b) . (p_a - p_b) / |p_a - p_b|`` (positive across a convex edge, negative in a concave crease);
    ``creased`` is the share of those whose convexity is below ``-crease`` (a concave crease along that stretch)
    and ``crease_length`` their number (how many 4-neighbour pixel pairs long the crease runs).
    """

    pairs: np.ndarray
    length: np.ndarray
    continuous: np.ndarray
    close: np.ndarray
    alignment: np.ndarray
    convexity: np.ndarray
    creased: np.ndarray
    crease_length: np.ndarray


def pixel_footprint(points: np.ndarray) -> float:
    """The angle (radians) between horizontally adjacent pixels of an organized cloud: ``step / fx``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = points[..., 0] / points[..., 2]
        steps = np.abs(np.diff(ratio, axis=1))
    steps = steps[np.isfinite(steps) & (steps > 0)]
    return float(_median(steps)) if steps.size else 0.0


def boundaries(
    labels: np.ndarray,
    points: np.ndarray,
    normals: np.ndarray,
    absolute: float,
    relative: float,
    close_factor: float = 2.5,
    reach: int = 2,
    crease: float = 0.15,
    footprint: float | None = None,
) -> Boundaries:
    """The :class:`Boundaries` of every touching pair of parts (``points``/``normals`` HxWx3, camera frame).

    Normals and positions for ``alignment`` and ``convexity`` are taken ``reach`` pixels away from the boundary on
    either side (where those pixels still belong to the two parts), since normals right at a crease are blurred
    across it. Only the boundary pixels and those beside them are read. ``footprint`` is the
    :func:`pixel_footprint` of ``points`` when the caller has measured it.
    """
    if footprint is None:
        footprint = pixel_footprint(points)
    key, jump, near, dot, convexity = boundary_pairs(
        np.ascontiguousarray(labels),
        np.asarray(points, dtype=np.float32),  # a window of a larger grid is read in place, not copied
        np.asarray(normals, dtype=np.float32),
        reach,
        absolute,
        relative,
        close_factor * footprint,
    )
    if key.size == 0:
        empty = np.zeros(0)
        return Boundaries(np.zeros((0, 2), np.int64), empty, empty, empty, empty, empty, empty, empty)
    unique, inverse = distinct_keys(key)
    length = np.bincount(inverse, minlength=unique.size).astype(np.float64)
    smooth = ~jump
    known = smooth & np.isfinite(dot) & np.isfinite(convexity)
    known_count = np.bincount(inverse, weights=known, minlength=unique.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        alignment = np.bincount(inverse, weights=np.where(known, dot, 0.0), minlength=unique.size) / known_count
        mean_convexity = np.bincount(inverse, weights=np.where(known, convexity, 0.0), minlength=unique.size)
        mean_convexity /= known_count
    continuous = np.bincount(inverse, weights=smooth, minlength=unique.size) / length
    close = np.bincount(inverse, weights=near, minlength=unique.size) / length
    base = int(labels.max(initial=0)) + 1
    pairs = np.column_stack([unique // base, unique % base])
    crease_length = np.bincount(inverse, weights=known & (convexity < -crease), minlength=unique.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        creased = crease_length / known_count
    return Boundaries(
        pairs, length, continuous, close, alignment, mean_convexity, np.nan_to_num(creased), crease_length
    )


@dataclass(frozen=True)
class MergeRules:
    """Thresholds of :func:`merge_parts` (metres, raster cells, shares, cosines, pixels)."""

    overlap: float = 0.5
    cell: float = 0.005
    inside_tolerance: float = 0.01
    inside_depth_ratio: float = 1.5
    continuous: float = 0.6
    min_boundary: int = 3
    boundary_share: float = 0.6
    smooth_cosine: float = float(np.cos(np.radians(35.0)))
    convex: float = 0.15
    concave: float = -0.15
    coplanar_cosine: float = float(np.cos(np.radians(18.0)))
    small_part: int = 40
    occlusion: float = 0.5
    creased: float = 1.0
    inside: bool = True
    nested: bool = False
    nest_tolerance: float = 0.003
    stray_share: float = 0.03

    def pair_tolerances(self) -> tuple[float, float, float, float, float, float]:
        """The tolerances :func:`~annotators.geometry.grid_kernels.pair_evidence` takes, in its order."""
        return (
            self.nest_tolerance,
            self.inside_tolerance,
            self.inside_depth_ratio,
            RIM_BAND,
            FLOOR_FLATNESS,
            INNER_SPREAD,
        )


def merge_parts(
    labels: np.ndarray,
    depth: np.ndarray,
    plane_coordinates: Callable[[np.ndarray], np.ndarray] | np.ndarray,
    rules: MergeRules,
    surface: Boundaries | None = None,
    stand_apart: Callable[[np.ndarray, np.ndarray], bool] | None = None,
    spilled: np.ndarray | None = None,
) -> np.ndarray:
    """Join touching parts that are pieces of one object; labels renumbered 1..n (0 = none).

    ``plane_coordinates(pixels)`` gives Nx3 float32 ``(u, v, height)`` on the supporting plane for flat pixel
    indices (or ``plane_coordinates`` is that table of every pixel, HWx3). Two touching parts are pieces of one
    object when

    * their footprints (convex hulls on the plane) share more than ``rules.overlap`` of the smaller one: objects
      standing side by side have (nearly) disjoint footprints, while the pieces one object was cut into by a
      colour edge (a can's label, a box's print) share theirs; or
    * the far one :func:`looks_like_inside` the near one (the inside and outside of a cup or bowl, split by
      the depth jump or the shading edge at the front rim); or
    * (with ``surface``) their shared boundary is mostly close in 3-D (see :class:`Boundaries`), at least
      ``rules.boundary_share`` times the square root of the smaller part's size long, and the surface
      goes on across it smoothly (normals within ~35°) or over a convex edge (a box's top and front face), never
      into a concave crease (a can standing on a box); below ~18° between the normals the surfaces count as one
      plane, whatever the (then noisy) convexity says.

    ``stand_apart(first, second)`` (Nx3 plane coordinates of two parts), when given, vetoes the footprint rule: a
    can standing in a bowl shares the footprint of the bowl's inner wall around it, and the wall's heights lie
    within the can's when the can rises above the rim.

    ``spilled`` (HxW bool, when given) marks labelled pixels that lie on another object's surface
    (:meth:`~annotators.geometry.convexity.ConvexObjects.spilled`). Where they are strays, at most
    ``rules.stray_share`` of a part's pixels, the footprint rule joins only footprints that overlap both with and
    without them, while footprints that overlap with them and whose heights do not nest still stand one on the
    other. A few pixels of the box behind a box that took the front box's label (or the other way round) stretch
    its footprint over the other's, and where they fall depends on where the grid cells start: a join must not rest
    on them.

    A pair whose shared boundary is mostly a depth jump (continuous on less than ``rules.occlusion`` of it) is an
    occluder and what it hides, or a container's rim and its inside: only the inside rule may join it. Parts
    smaller than ``rules.small_part`` pixels join at most one neighbour among those a rule allows, so a crumb
    between two objects cannot glue them together: the one they share the longest boundary with when ``surface``
    measures the boundaries, else the first in label order (counting border pixels instead cut the PCL stereo mug's
    inside off its outside: bench/profiles/segscore-analysis.txt, eighteenth session).
    """
    pairs = touching_pairs(labels)
    if pairs.shape[0] == 0:
        return labels
    flat_spilled = None if spilled is None else spilled.reshape(-1)
    parts = _PartEvidence(labels, depth, plane_coordinates, pairs, flat_spilled, rules.stray_share)
    sizes = np.diff(parts.starts)
    lengths: dict[tuple[int, int], float] = {}
    smooth: set[tuple[int, int]] = set()
    occluding: set[tuple[int, int]] = set()
    creases: list[tuple[int, int]] = []
    if surface is not None:
        for (a, b), length, continuous, close, alignment, convexity, creased in zip(
            surface.pairs.tolist(),
            surface.length,
            surface.continuous,
            surface.close,
            surface.alignment,
            surface.convexity,
            surface.creased,
            strict=True,
        ):
            lengths[(a, b)] = float(length)
            if creased > rules.creased and convexity < rules.concave and alignment < rules.coplanar_cosine:
                creases.append((a, b))
            if continuous < rules.occlusion:
                occluding.add((a, b))
            if (
                close >= rules.continuous
                and close * length >= max(rules.min_boundary, rules.boundary_share * np.sqrt(min(sizes[a], sizes[b])))
                and (convexity >= rules.concave or alignment >= rules.coplanar_cosine)
                and (alignment >= rules.smooth_cosine or convexity >= rules.convex)
            ):
                smooth.add((a, b))
    # the footprints of the pairs the overlap rule may join, all at once
    footprint_pairs = [
        pair
        for pair in map(tuple, pairs.tolist())
        if pair not in smooth and pair not in occluding and rules.overlap < 1.0
    ]
    overlaps = footprint_overlaps(
        [parts.hull(a) for a, _ in footprint_pairs], [parts.hull(b) for _, b in footprint_pairs], rules.cell
    )
    overlapping = {
        pair for pair, share in zip(footprint_pairs, overlaps.tolist(), strict=True) if share > rules.overlap
    }
    # the pairs that overlap without the spilled pixels as well: only those may join by footprint
    overlapping_kept = set(overlapping)
    doubtful = [pair for pair in overlapping if parts.thinned[pair[0]] or parts.thinned[pair[1]]]
    if doubtful:
        kept = footprint_overlaps(
            [parts.kept_hull(a) for a, _ in doubtful], [parts.kept_hull(b) for _, b in doubtful], rules.cell
        )
        overlapping_kept -= {
            pair for pair, share in zip(doubtful, kept.tolist(), strict=True) if share <= rules.overlap
        }
    listed = pairs.tolist()
    nests, floor_tests, holding = parts.evidence(
        np.array([tuple(pair) in overlapping for pair in listed], dtype=bool),
        np.array([tuple(pair) not in smooth for pair in listed], dtype=bool),
        rules,
    )
    allowed: list[tuple[int, int]] = []
    for (first, second), nest, floors, holds in zip(
        listed, nests.tolist(), floor_tests.tolist(), holding.tolist(), strict=True
    ):
        if (first, second) in smooth:
            allowed.append((first, second))
            continue
        stacked = False
        if (first, second) in overlapping:
            joinable = (not rules.nested or nest or parts.floor_within(first, second, floors, rules.cell)) and (
                stand_apart is None or not stand_apart(parts.coordinates(first), parts.coordinates(second))
            )
            if joinable and (first, second) in overlapping_kept:
                allowed.append((first, second))
                continue
            stacked = not joinable
        if holds:
            allowed.append((first, second))
        elif stacked:
            creases.append((first, second))  # one stands on the other: never joined, not even through a third
    joined = [(a, b) for a, b in allowed if sizes[a] >= rules.small_part and sizes[b] >= rules.small_part]
    best: dict[int, tuple[float, int]] = {}
    for a, b in allowed:
        length = lengths.get((a, b), 1.0)
        for small, other in ((a, b), (b, a)):
            if sizes[small] < rules.small_part and length > best.get(small, (-1.0, 0))[0]:
                best[small] = (length, other)
    joined += [(small, other) for small, (_, other) in best.items()]
    if creases:
        # a crease along part of two parts' boundary keeps them apart, also through a third part they both join
        joined.sort(key=lambda pair: -lengths.get((min(pair), max(pair)), 1.0))
        groups = groups_unless_apart(int(labels.max()) + 1, np.array(joined).reshape(-1, 2), np.array(creases))
        joined = [(int(a), int(b)) for a, b in enumerate(groups.tolist()) if a != b]
    return join_labels(labels, joined)


def bounding_box(mask: np.ndarray, margin: int = 0) -> tuple[int, int, int, int]:
    """``(x0, y0, x1, y1)`` (exclusive) of the True pixels, grown by ``margin`` and clipped to the grid."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    height, width = mask.shape
    return (
        max(int(cols[0]) - margin, 0),
        max(int(rows[0]) - margin, 0),
        min(int(cols[-1]) + 1 + margin, width),
        min(int(rows[-1]) + 1 + margin, height),
    )
