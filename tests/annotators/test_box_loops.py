"""The compiled loops of the batched box fits against the NumPy expressions they replace."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.geometry import box_loops
from annotators.geometry.boxes import STRAY_FENCE, _compact, object_box, object_boxes_of_sets
from robokudo.core.geometry import quaternion_from_matrix


def point_sets(seed: int, sizes: list[int], decimals: int | None = None) -> list[np.ndarray]:
    """Random 3xN sets of different spreads and places, a few far strays in the larger ones; rounded to
    ``decimals`` (many ties, like quantised depth) when given."""
    rng = np.random.default_rng(seed)
    sets = []
    for size in sizes:
        points = rng.normal(size=(3, size)) * rng.uniform(0.01, 0.3, size=(3, 1)) + rng.normal(size=(3, 1))
        if size >= 20:
            points[:, :3] *= 30.0
        sets.append(np.round(points, decimals) if decimals is not None else points)
    return sets


@pytest.mark.parametrize("count", [1, 2, 7, 8, 9, 15, 16, 17, 100, 127, 128, 129, 130, 255, 256, 257, 1000, 2049])
def test_reduced_sum_adds_like_numpy(count: int) -> None:
    values = np.random.default_rng(count).normal(size=count + 3) * 1e3
    expected = np.add.reduceat(np.stack([values[3:]] * 2), [0], axis=1)[0, 0]
    assert box_loops.reduced_sum(values, 3, count) == expected


@pytest.mark.parametrize("decimals", [None, 2, 1])
def test_compact_sets_keeps_what_compact_keeps(decimals: int | None) -> None:
    sizes = [1, 3, 7, 8, 9, 10, 11, 31, 64, 400, 999, 1500]
    sets = point_sets(7, sizes, decimals)
    rows, kept = box_loops.compact_sets(np.concatenate(sets, axis=1), np.array(sizes, dtype=np.int64), STRAY_FENCE)
    expected = [_compact(points) for points in sets]
    assert kept.tolist() == [points.shape[1] for points in expected]
    assert np.array_equal(rows, np.concatenate(expected, axis=1))
    assert kept.sum() < sum(sizes)  # the strays went


def test_set_moments_equal_the_numpy_reductions() -> None:
    sizes = np.array([1, 2, 5, 9, 130, 777, 1800], dtype=np.int64)
    rows = np.concatenate(point_sets(3, sizes.tolist()), axis=1)
    means, products = box_loops.set_moments(rows, sizes)
    starts = np.cumsum(sizes) - sizes
    expected_means = np.add.reduceat(rows, starts, axis=1) / sizes
    centred = rows - expected_means[:, np.repeat(np.arange(sizes.size), sizes)]
    pairs = centred[[0, 0, 0, 1, 1, 2]] * centred[[0, 1, 2, 1, 2, 2]]
    assert np.array_equal(means, expected_means)
    assert np.array_equal(products, np.add.reduceat(pairs, starts, axis=1))


def test_set_extents_equal_the_matrix_product_to_rounding() -> None:
    sizes = np.array([3, 40, 900], dtype=np.int64)
    rows = np.concatenate(point_sets(5, sizes.tolist()), axis=1)
    rng = np.random.default_rng(5)
    rotations = np.stack([np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in sizes])
    starts = np.cumsum(sizes) - sizes
    means = np.add.reduceat(rows, starts, axis=1) / sizes
    low, high = box_loops.set_extents(rows, sizes, means, rotations)
    for index, (start, size) in enumerate(zip(starts, sizes, strict=True)):
        local = rotations[index].T @ (rows[:, start : start + size] - means[:, index : index + 1])
        np.testing.assert_allclose(low[index], local.min(axis=1), rtol=0, atol=1e-14)
        np.testing.assert_allclose(high[index], local.max(axis=1), rtol=0, atol=1e-14)


CAMERA_POSE = np.array([[1, 0, 0, 0.1], [0, 0, 1, -0.5], [0, -1, 0, 1.2], [0, 0, 0, 1]], dtype=np.float64)


@pytest.mark.parametrize("cam_to_world", [None, CAMERA_POSE])
def test_object_boxes_of_sets_fit_each_set_as_object_box_does(cam_to_world: np.ndarray | None) -> None:
    sizes = [1, 2, 5, 60, 700]
    sets = point_sets(11, sizes)
    boxes = object_boxes_of_sets(np.concatenate(sets, axis=1), np.array(sizes), cam_to_world)
    for points, (box, frame) in zip(sets, boxes, strict=True):
        alone, alone_frame = object_box(points.T, cam_to_world)
        assert frame == alone_frame
        np.testing.assert_allclose(box.centre, alone.centre, rtol=0, atol=1e-12)
        np.testing.assert_allclose(box.extents, alone.extents, rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.abs(box.rotation), np.abs(alone.rotation), rtol=0, atol=1e-9)


def test_rotation_quaternions_equal_quaternion_from_matrix() -> None:
    rng = np.random.default_rng(2)
    rotations = [np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(200)]
    rotations = [r if np.linalg.det(r) > 0 else -r for r in rotations]
    rotations += [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    rotations += [np.diag([1.0, 1.0, -1.0]), np.full((3, 3), np.nan), np.zeros((3, 3))]
    quaternions = box_loops.rotation_quaternions(np.stack(rotations))
    for rotation, quaternion in zip(rotations, quaternions, strict=True):
        assert np.array_equal(quaternion, quaternion_from_matrix(rotation))


def test_gathered_compact_sets_compact_the_finite_indexed_points() -> None:
    rng = np.random.default_rng(4)
    points = np.concatenate(point_sets(4, [3000]), axis=1).T.astype(np.float32)
    points[rng.integers(0, 3000, size=300), rng.integers(0, 3, size=300)] = np.nan
    sizes = np.array([0, 5, 12, 900, 40, 1], dtype=np.int64)
    indices = rng.integers(-20, 3020, size=sizes.sum())
    rows, kept = box_loops.gathered_compact_sets(points, indices, sizes, STRAY_FENCE)
    expected = []
    for group in np.split(indices, np.cumsum(sizes)[:-1]):
        chosen = points[group[(group >= 0) & (group < 3000)]].astype(np.float64)
        expected.append(_compact(chosen[np.isfinite(chosen).all(axis=1)].T))
    assert kept.tolist() == [part.shape[1] for part in expected]
    assert np.array_equal(rows, np.concatenate(expected, axis=1))


@pytest.mark.parametrize(
    "values",
    [
        np.arange(1000.0),
        np.arange(1000.0)[::-1].copy(),
        np.full(700, 2.5),
        np.repeat([1.0, 2.0, 3.0], 300),
        np.concatenate([np.zeros(990), np.full(10, 1e9)]),
        np.random.default_rng(8).normal(size=1301),
        np.random.default_rng(9).integers(0, 20, size=50).astype(np.float64),
    ],
)
def test_rank_pair_finds_the_values_of_two_neighbouring_ranks(values: np.ndarray) -> None:
    ranked = np.sort(values)
    scratch = np.empty(values.size)
    original = values.copy()
    for rank in sorted({0, 1, values.size // 4, values.size // 2, values.size - 2}):
        assert box_loops._rank_pair(values, rank, scratch) == (ranked[rank], ranked[rank + 1])
    assert np.array_equal(values, original)
