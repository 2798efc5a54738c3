"""The compiled grid kernels give what the numpy and OpenCV expressions they replace give."""

from __future__ import annotations

from fractions import Fraction

import cv2
import numpy as np
import pytest
from scipy import sparse
from scipy.sparse import csgraph

from annotators.geometry.grid_kernels import (
    connected_parts,
    facing_values,
    finite_rows,
    graph_components,
    grouped_pixels,
    groups_unless_apart,
    joined_labels,
    jump_between,
    label_masks,
    label_pieces,
    label_pixels,
    near_label_pairs,
    nearest_seed_labels,
    plane_coordinates,
    sampled_median,
    shadowed_near,
    strided_crop,
    symmetric_eigen,
    touching_keys,
    unlabelled_box,
    upsampled_labels,
    window_counts,
)
from annotators.geometry.grid_segmentation import bounding_box, depth_jump, depth_seams, grow_on_surface, label_groups


def _blobs(seed: int, shape: tuple[int, int] = (40, 50), labels: int = 6) -> np.ndarray:
    """Random int32 labels 0..labels in blocky patches, with holes."""
    rng = np.random.default_rng(seed)
    coarse = rng.integers(0, labels + 1, (shape[0] // 4 + 1, shape[1] // 4 + 1))
    grid = np.kron(coarse, np.ones((4, 4), dtype=np.int64))[: shape[0], : shape[1]]
    grid[rng.random(shape) < 0.1] = 0
    return grid.astype(np.int32)


@pytest.mark.parametrize("seed", range(5))
def test_connected_parts_number_parts_as_opencv(seed: int) -> None:
    region = _blobs(seed) > 0
    _, reference, stats, _ = cv2.connectedComponentsWithStats(region.view(np.uint8), connectivity=4)
    keep = stats[:, cv2.CC_STAT_AREA] >= 5
    keep[0] = False
    expected = (np.cumsum(keep) * keep).astype(np.int32)[reference]
    assert np.array_equal(connected_parts(region, 5), expected)


@pytest.mark.parametrize("seed", range(5))
def test_label_pieces_are_the_connected_parts_of_each_label_in_raster_order(seed: int) -> None:
    labels = _blobs(seed)
    parts = []  # (first pixel's flat index, mask) of every 4-connected part of every label
    for label in np.unique(labels[labels > 0]):
        count, numbered = cv2.connectedComponents((labels == label).astype(np.uint8), connectivity=4)
        parts += [(int(np.argmax(numbered == part)), numbered == part) for part in range(1, count)]
    expected = np.zeros(labels.shape, dtype=np.int64)
    for number, (_, mask) in enumerate(sorted(parts, key=lambda part: part[0]), start=1):
        expected[mask] = number
    assert np.array_equal(label_pieces(labels), expected)


@pytest.mark.parametrize("seed", range(5))
def test_touching_keys_find_every_adjacent_pair(seed: int) -> None:
    labels = _blobs(seed)
    base = int(labels.max()) + 1
    expected = []
    for a, b in ((labels[:, :-1], labels[:, 1:]), (labels[:-1, :], labels[1:, :])):
        touching = (a != b) & (a > 0) & (b > 0)
        expected.append(np.minimum(a, b)[touching] * base + np.maximum(a, b)[touching])
    assert np.array_equal(np.sort(touching_keys(labels, base)), np.sort(np.concatenate(expected)))


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("reach", [1, 2, 3])
def test_near_label_pairs_are_the_labels_within_reach_of_each_other(seed: int, reach: int) -> None:
    labels = _blobs(seed, labels=9)
    expected = set()
    for a in range(1, int(labels.max()) + 1):
        grown = cv2.dilate((labels == a).astype(np.uint8), np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)) > 0
        expected |= {(a, int(b)) for b in np.unique(labels[grown]) if b > a}
    pairs = near_label_pairs(labels, reach)
    assert [tuple(pair) for pair in pairs.tolist()] == sorted(expected)


@pytest.mark.parametrize("seed", range(3))
def test_pixels_grouped_by_label_in_raster_order(seed: int) -> None:
    labels = _blobs(seed)
    where = np.random.default_rng(seed).random(labels.shape) < 0.5
    pixels, starts = grouped_pixels(labels, where, int(labels.max()))
    flat = labels.reshape(-1)
    chosen = np.flatnonzero(where.reshape(-1) & (flat > 0))
    assert np.array_equal(pixels, chosen[np.argsort(flat[chosen], kind="stable")])
    assert np.array_equal(np.diff(starts)[1:], np.bincount(flat[chosen], minlength=labels.max() + 1)[1:])
    all_pixels, all_starts, boxes = label_pixels(labels)
    for label in range(1, int(labels.max()) + 1):
        own = np.flatnonzero(flat == label)
        assert np.array_equal(all_pixels[all_starts[label] : all_starts[label + 1]], own)
        rows, cols = own // labels.shape[1], own % labels.shape[1]
        assert boxes[label].tolist() == [cols.min(), rows.min(), cols.max() + 1, rows.max() + 1]
    grid = np.zeros((labels.shape[0] + 7, labels.shape[1] + 9), dtype=labels.dtype)
    grid[5 : 5 + labels.shape[0], 3 : 3 + labels.shape[1]] = labels  # labels as a window of a larger grid
    in_grid, grid_starts, window_boxes = label_pixels(labels, (5, 3), grid.shape[1])
    expected, _, _ = label_pixels(grid)
    assert np.array_equal(in_grid, expected) and np.array_equal(grid_starts, all_starts)
    assert np.array_equal(window_boxes, boxes)


@pytest.mark.parametrize("seed", range(3))
def test_label_masks_hold_the_pixels_and_boxes_label_pixels_gives(seed: int) -> None:
    labels = _blobs(seed)
    labels[labels == 2] = 0  # a kept label without pixels gets an empty mask and a zero box
    origin, shape = (5, 3), (labels.shape[0] + 7, labels.shape[1] + 9)
    pixels, starts, boxes = label_pixels(labels, origin, shape[1])
    kept = [4, 2, 1, 6]  # any order, not every label
    masks, kept_boxes = label_masks(labels, kept, origin, shape)
    assert masks.shape == (len(kept), *shape) and masks.dtype == bool
    for mask, box, label in zip(masks, kept_boxes.tolist(), kept, strict=True):
        assert np.array_equal(np.flatnonzero(mask), pixels[starts[label] : starts[label + 1]])
        assert box == boxes[label].tolist()
    assert label_masks(labels, [], origin, shape)[0].shape == (0, *shape)


def test_facing_values_are_the_dilated_band_on_the_target() -> None:
    rng = np.random.default_rng(1)
    target = rng.random((60, 70)) < 0.3
    values = rng.random((60, 70)).astype(np.float32)
    rows, cols = np.array([20, 21, 30]), np.array([10, 11, 40])
    radius = 6
    r0, c0 = max(rows.min() - radius, 0), max(cols.min() - radius, 0)
    r1, c1 = rows.max() + radius + 1, cols.max() + radius + 1
    band = np.zeros((min(r1, 60) - r0, min(c1, 70) - c0), dtype=np.uint8)
    band[rows - r0, cols - c0] = 1
    facing = (cv2.dilate(band, np.ones((2 * radius + 1, 2 * radius + 1), np.uint8)) > 0) & target[r0:r1, c0:c1]
    assert np.array_equal(facing_values(rows, cols, target, values, radius), values[r0:r1, c0:c1][facing])


def test_shadowed_near_matches_dilations_and_components() -> None:
    rng = np.random.default_rng(2)
    occluding = np.zeros((50, 60), dtype=bool)
    occluding[20:30, 25:35] = True
    unmeasured = (rng.random((50, 60)) < 0.45) & ~occluding
    shadow, near = 8, 3
    beside = cv2.dilate(occluding.view(np.uint8), np.ones((3, 3), np.uint8)) > 0
    count, parts = cv2.connectedComponents(unmeasured.view(np.uint8), connectivity=4)
    touching = np.zeros(count, dtype=bool)
    touching[parts[beside & unmeasured]] = True
    touching[0] = False
    within = cv2.dilate(occluding.view(np.uint8), np.ones((2 * shadow + 1,) * 2, np.uint8)) > 0
    region = occluding | (touching[parts] & within)
    expected = cv2.dilate(region.view(np.uint8), np.ones((2 * near + 1,) * 2, np.uint8)) > 0
    assert np.array_equal(shadowed_near(occluding, unmeasured, shadow, near), expected)


def test_symmetric_eigen_agrees_with_lapack() -> None:
    rng = np.random.default_rng(3)
    points = rng.normal(size=(200, 15, 3)) * np.array([1.0, 0.2, 0.001])
    matrices = np.einsum("kni,knj->kij", points, points) / 15
    values, vectors = symmetric_eigen(matrices)
    expected_values, expected_vectors = np.linalg.eigh(matrices)
    assert np.allclose(values, expected_values, rtol=1e-9, atol=1e-15)
    assert np.allclose(np.abs(np.einsum("kij,kij->kj", vectors, expected_vectors)), 1.0, atol=1e-6)


def _jump(a: float, b: float, absolute: float, relative: float) -> bool:
    return abs(a - b) > absolute + relative * min(a, b)


def test_depth_seams_mark_the_far_pixel_of_each_jump() -> None:
    rng = np.random.default_rng(4)
    depth = (1.0 + 0.05 * rng.integers(0, 3, (12, 15))).astype(np.float32)
    candidates = rng.random((12, 15)) < 0.8
    expected = np.zeros((12, 15), dtype=bool)
    for r in range(12):
        for c in range(15):
            for nr, nc in ((r, c + 1), (r + 1, c)):
                both = nr < 12 and nc < 15 and candidates[r, c] and candidates[nr, nc]
                if both and _jump(float(depth[r, c]), float(depth[nr, nc]), 0.01, 0.01):
                    expected[(r, c) if depth[r, c] > depth[nr, nc] else (nr, nc)] = True
    assert np.array_equal(depth_seams(depth, candidates, 0.01, 0.01), expected)


def test_grow_on_surface_takes_the_first_neighbour_on_the_same_surface() -> None:
    rng = np.random.default_rng(5)
    labels = np.where(rng.random((12, 15)) < 0.4, rng.integers(1, 4, (12, 15)), 0).astype(np.int32)
    depth = (1.0 + 0.05 * rng.integers(0, 2, (12, 15))).astype(np.float32)
    region = rng.random((12, 15)) < 0.9
    expected = labels.copy()
    for _ in range(2):
        before = expected.copy()
        for r in range(12):
            for c in range(15):
                if not region[r, c] or before[r, c]:
                    continue
                for nr, nc in ((r, c - 1), (r, c + 1), (r - 1, c), (r + 1, c)):
                    labelled = 0 <= nr < 12 and 0 <= nc < 15 and before[nr, nc] > 0
                    if labelled and not _jump(float(depth[r, c]), float(depth[nr, nc]), 0.01, 0.01):
                        expected[r, c] = before[nr, nc]
                        break
    assert np.array_equal(grow_on_surface(labels, region, depth, 0.01, 0.01), expected)


@pytest.mark.parametrize("seed", range(5))
def test_graph_components_number_components_as_scipy_does(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(50):
        count = int(rng.integers(1, 40))
        pairs = rng.integers(0, count, (int(rng.integers(0, 40)), 2))
        graph = sparse.csr_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
        expected = csgraph.connected_components(graph, directed=False)[1]
        np.testing.assert_array_equal(graph_components(pairs, count), expected)


@pytest.mark.parametrize("seed", range(5))
def test_nearest_seed_labels_give_what_the_numpy_lookup_gives(seed: int) -> None:
    labels = _blobs(seed)
    labels[labels == 3] = 0  # a large unlabelled area, partly beyond reach
    unlabelled = (labels == 0) & (np.random.default_rng(seed).random(labels.shape) < 0.8)
    seeds = labels > 0
    distance, nearest = cv2.distanceTransformWithLabels(
        (~seeds).view(np.uint8), cv2.DIST_L2, 3, labelType=cv2.DIST_LABEL_PIXEL
    )
    max_distance = 2.1  # not a float32 value: compared in float32, as numpy compares it
    lookup = np.zeros(int(nearest.max()) + 1, dtype=labels.dtype)
    lookup[nearest[seeds]] = labels[seeds]
    reach = unlabelled & (distance <= max_distance)
    expected = labels.copy()
    expected[reach] = lookup[nearest[reach]]
    grown = labels.copy()
    nearest_seed_labels(labels, unlabelled, distance, nearest, max_distance, grown)
    np.testing.assert_array_equal(grown, expected)
    assert np.count_nonzero(grown != labels) > 0


@pytest.mark.parametrize("seed", range(5))
def test_unlabelled_box_is_the_box_of_the_unlabelled_region(seed: int) -> None:
    labels = _blobs(seed)
    region = np.zeros(labels.shape, dtype=bool)
    region[5:30, 8 + seed : 40] = True
    unlabelled, box, growing = unlabelled_box(labels, region, 3)
    np.testing.assert_array_equal(unlabelled, region & (labels == 0))
    assert growing
    assert tuple(box.tolist()) == bounding_box(region & (labels == 0), margin=3)
    assert not unlabelled_box(labels, np.zeros(labels.shape, dtype=bool), 3)[2]
    assert not unlabelled_box(np.zeros_like(labels), region, 3)[2]


def test_finite_rows_keep_the_rows_without_nan_or_inf_in_order() -> None:
    rng = np.random.default_rng(0)
    values = rng.normal(size=(200, 3)).astype(np.float32)
    values[rng.random((200, 3)) < 0.1] = np.nan
    values[7, 1] = np.inf
    indices = rng.permutation(200)[:120]
    expected = values[indices][np.isfinite(values[indices]).all(axis=1)]
    found = finite_rows(values, indices)
    np.testing.assert_array_equal(found, expected)
    assert found.dtype == values.dtype and 0 < found.shape[0] < indices.size


def test_jump_between_is_depth_jump_of_two_float32_depths() -> None:
    rng = np.random.default_rng(2)
    depths = rng.uniform(0.3, 2.0, (2000, 2))
    depths[1::7, 1] = depths[1::7, 0] * (1 + rng.uniform(0.0, 0.03, depths[1::7].shape[0]))  # near the threshold
    depths[5, 0] = np.nan
    for z_a, z_b in depths:
        expected = depth_jump(np.float32(z_a), np.float32(z_b), 0.02, 0.01)
        assert jump_between(z_a, z_b, 0.02, 0.01) == bool(expected)


def test_window_counts_count_the_labels_of_a_window_in_place() -> None:
    labels = _blobs(4)
    window = labels[3:30:2, 5:41]
    counts = window_counts(window, int(labels.max()))
    np.testing.assert_array_equal(counts, np.bincount(window.reshape(-1), minlength=int(labels.max()) + 1))


@pytest.mark.parametrize("dtype", [np.float32, np.uint8])
@pytest.mark.parametrize("channels", [0, 3, 4])  # 3: the fixed-length copy; others the general loop
def test_strided_crop_is_the_contiguous_copy_of_the_subsampled_window(channels: int, dtype: type) -> None:
    shape = (47, 61, channels) if channels else (47, 61)
    values = (np.random.default_rng(channels).random(shape) * 255).astype(dtype)
    if dtype == np.float32:
        values[3, 4] = np.nan
    crop = strided_crop(values, 2, (3, 1, 29, 22))
    expected = np.ascontiguousarray(values[::2, ::2][1:22, 3:29])
    np.testing.assert_array_equal(crop, expected)
    assert crop.shape == expected.shape and crop.flags.c_contiguous


@pytest.mark.parametrize("step", [1, 2, 3])
def test_upsampled_labels_keep_the_cell_label_where_no_depth_jump_parts_them(step: int) -> None:
    rng = np.random.default_rng(step)
    rows, cols = 37, 53  # not multiples of the step: the last cells are cut
    labels = _blobs(step, ((rows + step - 1) // step, (cols + step - 1) // step))
    coarse_depth = rng.uniform(0.5, 1.5, labels.shape).astype(np.float32)
    depth = (np.kron(coarse_depth, np.ones((step, step), dtype=np.float32))[:rows, :cols]
             + rng.normal(0.0, 0.02, (rows, cols)).astype(np.float32))  # fmt: skip
    depth[rng.random(depth.shape) < 0.05] = np.nan
    coarse_depth[rng.random(coarse_depth.shape) < 0.05] = np.nan
    keep = rng.random((rows, cols)) < 0.8
    cell_rows, cell_cols = np.arange(rows)[:, None] // step, np.arange(cols)[None, :] // step
    jump = depth_jump(depth, coarse_depth[cell_rows, cell_cols], 0.01, 0.01)
    expected = np.where(keep & ~jump, labels[cell_rows, cell_cols], 0)
    assert np.array_equal(upsampled_labels(labels, coarse_depth, depth, keep, step, 0.01, 0.01), expected)


def _groups_unless_apart_in_python(
    count: int,
    pairs: np.ndarray,
    apart: np.ndarray,
    weak: np.ndarray | None = None,
    sizes: np.ndarray | None = None,
    least: float = np.inf,
) -> np.ndarray:
    """The union-find with a set of kept-apart nodes per group that :func:`groups_unless_apart` replaces, and with
    each group's summed size, which a weak pair may not join when both sides hold ``least``."""
    parent = list(range(count))
    total = [0.0] * count if sizes is None else sizes.astype(float).tolist()
    weak_pairs = [False] * len(pairs) if weak is None else weak.tolist()
    keep_apart: dict[int, set[int]] = {}
    for a, b in apart.tolist():
        keep_apart.setdefault(a, set()).add(b)
        keep_apart.setdefault(b, set()).add(a)

    def root(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    for (a, b), is_weak in zip(pairs.tolist(), weak_pairs, strict=True):
        ra, rb = root(a), root(b)
        if ra == rb:
            continue
        against_a, against_b = keep_apart.get(ra, set()), keep_apart.get(rb, set())
        if any(root(n) == rb for n in against_a) or any(root(n) == ra for n in against_b):
            continue
        if is_weak and total[ra] >= least and total[rb] >= least:
            continue
        parent[rb] = ra
        total[ra] += total[rb]
        keep_apart[ra] = against_a | against_b
    return np.array([root(node) for node in range(count)], dtype=np.int64)


@pytest.mark.parametrize("seed", range(5))
def test_groups_unless_apart_give_what_the_python_union_find_gives(seed: int) -> None:
    rng = np.random.default_rng(seed)
    kept_apart = 0
    for _ in range(60):
        count = int(rng.integers(1, 60))
        pairs = rng.integers(0, count, (int(rng.integers(0, 80)), 2))
        apart = rng.integers(0, count, (int(rng.integers(0, 12)), 2))
        expected = _groups_unless_apart_in_python(count, pairs, apart)
        np.testing.assert_array_equal(groups_unless_apart(count, pairs, apart), expected)
        joined_regardless = _groups_unless_apart_in_python(count, pairs, apart[:0])
        kept_apart += int(np.unique(expected).size > np.unique(joined_regardless).size)
    assert kept_apart > 0  # some apart pairs did keep groups apart


@pytest.mark.parametrize("seed", range(5))
def test_weak_pairs_group_as_the_python_union_find_groups_them(seed: int) -> None:
    rng = np.random.default_rng(seed)
    refused = 0
    for _ in range(60):
        count = int(rng.integers(1, 60))
        pairs = rng.integers(0, count, (int(rng.integers(0, 80)), 2))
        apart = rng.integers(0, count, (int(rng.integers(0, 6)), 2))
        weak = rng.random(pairs.shape[0]) < 0.5
        sizes = rng.integers(1, 40, count).astype(float)
        expected = _groups_unless_apart_in_python(count, pairs, apart, weak, sizes, 60.0)
        np.testing.assert_array_equal(groups_unless_apart(count, pairs, apart, weak, sizes, 60.0), expected)
        refused += int(np.unique(expected).size > np.unique(groups_unless_apart(count, pairs, apart)).size)
    assert refused > 0  # some weak pairs did keep two large groups apart


def test_a_weak_pair_attaches_a_small_group_but_does_not_join_two_large_ones() -> None:
    # nodes 0-1 and 2-3 are two objects of 100 points each, node 4 a 10-point face on the seam between them
    sizes = np.array([50.0, 50.0, 50.0, 50.0, 10.0])
    strong = np.array([[0, 1], [2, 3]])
    seam = np.array([[1, 4], [4, 2], [1, 2]])
    pairs = np.concatenate([strong, seam])
    weak = np.array([False, False, True, True, True])
    groups = groups_unless_apart(5, pairs, np.zeros((0, 2)), weak, sizes, 80.0)
    assert groups[4] == groups[0] != groups[2]  # the seam face goes with the first object it agrees with
    assert np.unique(groups).size == 2
    # the same agreements counted strong join all, and no pair is refused without a size limit
    assert np.unique(groups_unless_apart(5, pairs, np.zeros((0, 2)))).size == 1
    assert np.unique(groups_unless_apart(5, pairs, np.zeros((0, 2)), weak, sizes)).size == 1


def _joined_labels_in_python(labels: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """The Python union-find and numpy renumbering :func:`joined_labels` replaces."""
    count = int(labels.max(initial=0)) + 1
    root = list(range(count))

    def find(node: int) -> int:
        while root[node] != node:
            root[node] = root[root[node]]
            node = root[node]
        return node

    for a, b in pairs.tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            root[max(ra, rb)] = min(ra, rb)
    present = np.bincount(labels.reshape(-1), minlength=count) > 0
    renumber = np.zeros(count, dtype=np.int32)
    numbers: dict[int, int] = {}
    for label in np.flatnonzero(present[1:]).tolist():
        renumber[label + 1] = numbers.setdefault(find(label + 1), len(numbers) + 1)
    return renumber[labels]


@pytest.mark.parametrize("seed", range(5))
def test_joined_labels_give_what_the_python_union_find_gives(seed: int) -> None:
    rng = np.random.default_rng(seed)
    labels = _blobs(seed)
    labels[labels == 2] = 0  # a label missing from the image, which pairs may still name
    count = int(labels.max()) + 1
    for size in (0, 1, 3, 8):
        pairs = rng.integers(1, count, (size, 2))
        joined = joined_labels(labels, pairs)
        assert joined.dtype == np.int32
        np.testing.assert_array_equal(joined, _joined_labels_in_python(labels, pairs))
    np.testing.assert_array_equal(joined_labels(np.zeros((3, 4), np.int32), np.zeros((0, 2))), np.zeros((3, 4)))


@pytest.mark.parametrize("seed", range(3))
def test_label_groups_are_the_stable_sort_of_the_labelled_pixels(seed: int) -> None:
    labels = _blobs(seed)
    labels[labels == 4] = 0  # a label missing in between
    flat = labels.reshape(-1)
    pixels = np.flatnonzero(flat)
    pixels = pixels[np.argsort(flat[pixels], kind="stable")]
    starts = np.searchsorted(flat[pixels], np.arange(int(flat.max()) + 2))
    grouped, grouped_starts = label_groups(labels)
    np.testing.assert_array_equal(grouped, pixels)
    np.testing.assert_array_equal(grouped_starts, starts)


def _fused(a: np.float32, b: np.float32, c: np.float32) -> np.float32:
    """``a * b + c`` computed exactly, rounded once to float32."""
    return np.float32(float(Fraction(float(a)) * Fraction(float(b)) + Fraction(float(c))))


@pytest.mark.parametrize("seed", range(3))
def test_plane_coordinates_round_each_sum_once_per_fused_product(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, 0.5, (200, 3)).astype(np.float32)
    to_plane = rng.normal(0.0, 1.0, (3, 3)).astype(np.float32)
    offset = rng.normal(0.0, 1.0, 3).astype(np.float32)
    result = plane_coordinates(points, to_plane, offset)
    for i in range(points.shape[0]):
        for k in range(3):
            total = np.float32(points[i, 0] * to_plane[0, k])
            total = _fused(points[i, 1], to_plane[1, k], total)
            total = _fused(points[i, 2], to_plane[2, k], total)
            assert result[i, k] == np.float32(total + offset[k])


def test_plane_coordinates_give_what_the_matrix_product_gives_on_a_grid_with_gaps() -> None:
    rng = np.random.default_rng(7)
    points = rng.normal(0.0, 0.5, (60_000, 3)).astype(np.float32)
    points[rng.random(points.shape[0]) < 0.1] = np.nan
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    to_plane = rotation.astype(np.float32)
    offset = np.array([0.0, 0.0, 0.7], dtype=np.float32)
    result = plane_coordinates(points, to_plane, offset)
    expected = points @ to_plane + offset
    assert np.array_equal(result, expected, equal_nan=True)
    assert not np.array_equal(result, points.astype(np.float64) @ to_plane + offset, equal_nan=True)


@pytest.mark.parametrize("step", [1, 2, 7])
def test_sampled_median_is_numpys_median_of_the_sample(step: int) -> None:
    rng = np.random.default_rng(step)
    values = rng.uniform(0.4, 2.0, 5000).astype(np.float32)
    indices = np.sort(rng.choice(5000, size=1001, replace=False))
    for end in (1001, 1000, 3):  # odd and even sample sizes
        expected = float(np.median(values[indices[:end:step]].astype(np.float64)))
        assert sampled_median(values, indices[:end], step) == expected
    values[indices[2 * step]] = np.nan
    assert np.isnan(sampled_median(values, indices, step))
    assert np.isnan(sampled_median(values, indices[:0], step))
