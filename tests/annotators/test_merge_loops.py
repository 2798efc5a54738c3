"""The compiled merge evidence (annotators/geometry/merge_loops.py through grid_kernels) and the branch-free selection
of footprint_loops against what they stand for: the same quantiles, hulls and decisions on random parts."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.geometry.footprint_loops import ranked_values
from annotators.geometry.grid_kernels import convex_hull, pair_evidence, part_hulls, sampled_pixels
from annotators.geometry.grid_segmentation import (
    FLOOR_FLATNESS,
    MergeRules,
    heights_nest,
    label_groups,
    looks_like_inside,
)


@pytest.mark.parametrize("seed", range(6))
def test_ranked_values_are_those_of_the_sorted_values(seed: int) -> None:
    rng = np.random.default_rng(seed)
    size = int(rng.integers(1, 900))
    values = np.round(rng.normal(size=size), int(rng.integers(0, 3))).astype(np.float32)  # many repeated values
    if seed % 3 == 2:
        values[rng.integers(0, size, 3)] = np.nan  # sorted last, as numpy does
    ranks = np.unique(np.rint(np.array([0.05, 0.5, 0.5, 0.95, 0.99]) * (size - 1)).astype(np.int64))
    for picks in (ranks, np.array([(size - 1) // 2, size // 2]), np.arange(max(0, size - 4), size)):
        expected = np.sort(values)[picks]  # adjacent ranks too (a median of an even count, the top few)
        assert np.array_equal(ranked_values(values.copy(), picks), expected.astype(np.float64), equal_nan=True)


def test_sampled_pixels_are_every_kth_pixel_of_the_labels_asked() -> None:
    rng = np.random.default_rng(1)
    labels = rng.integers(0, 6, (40, 50)).astype(np.int32)
    labels[labels == 3] = 0
    pixels, starts = label_groups(labels)
    sampled, offsets = sampled_pixels(pixels, starts, np.array([1, 2, 5]), 30)
    for label in range(starts.size - 1):
        own = pixels[starts[label] : starts[label + 1]]
        expected = own[:: max(1, own.size // 30)] if label in (1, 2, 5) else own[:0]
        assert np.array_equal(sampled[offsets[label] : offsets[label + 1]], expected)


def _random_parts(seed: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Plane coordinates of ``count`` parts (float32, concatenated) and their offsets; some parts are cup-like."""
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(count):
        size = int(rng.integers(2, 300))
        centre = rng.uniform(-0.3, 0.3, 2) + np.array([0.0, 0.6])
        spread = rng.uniform(0.005, 0.06, 2)
        base = rng.uniform(0.0, 0.05)
        height = rng.uniform(0.001, 0.15)
        uv = centre + rng.normal(size=(size, 2)) * spread
        parts.append(np.column_stack([uv, base + rng.uniform(0.0, height, size)]).astype(np.float32))
    # cups seen from the front: the outside (the front wall) and the inside (the inner back wall over the rim)
    for _ in range(3):
        angles = rng.uniform(0.0, np.pi, 60)
        radius, ahead, rim = rng.uniform(0.03, 0.06), rng.uniform(0.4, 0.8), rng.uniform(0.06, 0.12)
        front = np.column_stack([radius * np.cos(angles), ahead - radius * np.sin(angles), rng.uniform(0, rim, 60)])
        back = np.column_stack(
            [0.95 * radius * np.cos(angles), ahead + 0.95 * radius * np.sin(angles), rng.uniform(0.2, 0.9, 60) * rim]
        )
        parts += [front.astype(np.float32), back.astype(np.float32)]
    # a bowl's floor, flat and low, within its walls
    angles = rng.uniform(0.0, 2 * np.pi, 80)
    floor = np.column_stack([rng.normal(size=(80, 2)) * 0.01 + [0.1, 0.5], rng.uniform(0.010, 0.011, 80)])
    walls = np.column_stack([0.05 * np.cos(angles) + 0.1, 0.05 * np.sin(angles) + 0.5, rng.uniform(0.02, 0.08, 80)])
    parts += [floor.astype(np.float32), walls.astype(np.float32)]
    offsets = np.cumsum([0] + [part.shape[0] for part in parts])
    return np.concatenate(parts), offsets


@pytest.mark.parametrize("seed", range(3))
def test_part_hulls_are_the_convex_hulls_of_the_parts(seed: int) -> None:
    points, offsets = _random_parts(seed, 30)
    offsets[5] = offsets[4]  # part 4 without coordinates (no hull), part 5 with its own and 4's
    hulls, hull_offsets = part_hulls(points, offsets)
    for k in range(offsets.size - 1):
        part = points[offsets[k] : offsets[k + 1]]
        expected = convex_hull(part[:, :2]) if part.shape[0] else np.zeros((0, 2), np.float32)
        assert np.array_equal(hulls[hull_offsets[k] : hull_offsets[k + 1]], expected)


@pytest.mark.parametrize("seed", range(4))
def test_pair_evidence_decides_as_the_python_rules(seed: int) -> None:
    points, offsets = _random_parts(seed, 20)
    count = offsets.size - 1
    heights = points[:, 2].copy()
    for k in range(count):
        heights[offsets[k] : offsets[k + 1]].sort()
    rng = np.random.default_rng(seed)
    depth = rng.uniform(0.4, 1.2, count * 7).astype(np.float32)
    depth[-56:-14] = np.repeat(np.tile([0.5, 0.6], 3), 7)  # each cup's front wall is nearer than its inside
    pixels = rng.permutation(depth.size).astype(np.int64)  # part k owns 7 pixels
    starts = np.arange(0, depth.size + 1, 7, dtype=np.int64)
    pairs = np.array([(a, b) for a in range(count) for b in range(a + 1, count)], dtype=np.int64)
    rules = MergeRules(inside_tolerance=0.01, inside_depth_ratio=1.5, nest_tolerance=0.003)
    overlapping = rng.random(pairs.shape[0]) < 0.7
    overlapping[-1] = True  # the bowl's floor and walls
    unjoined = rng.random(pairs.shape[0]) < 0.8
    nest, floors, holds = pair_evidence(
        points, heights, offsets, depth, pixels, starts, pairs, overlapping, unjoined, rules.pair_tolerances(), True
    )
    part = [points[offsets[k] : offsets[k + 1]] for k in range(count)]
    median = [float(np.median(depth[pixels[starts[k] : starts[k + 1]]])) for k in range(count)]
    for k, (a, b) in enumerate(pairs.tolist()):
        nests = heights_nest(part[a][:, 2], part[b][:, 2], rules.nest_tolerance)
        assert nest[k] == (overlapping[k] and nests)
        near, far = sorted((a, b), key=median.__getitem__)
        assert holds[k] == (unjoined[k] and looks_like_inside(part[near], part[far], 0.01, 1.5))
        for bit, floor, walls in ((1, a, b), (2, b, a)):
            low, high = np.sort(part[floor][:, 2])[
                np.rint(np.array([0.05, 0.95]) * (part[floor].shape[0] - 1)).astype(int)
            ]
            walls_low = np.sort(part[walls][:, 2])[round(0.05 * (part[walls].shape[0] - 1))]
            ranks = np.rint(np.array([0.05, 0.95]) * (part[floor].shape[0] - 1)).astype(int)
            width = max(float(np.subtract(*np.sort(part[floor][:, axis])[ranks[::-1]])) for axis in (0, 1))
            candidate = high <= walls_low + rules.nest_tolerance and not high - low > FLOOR_FLATNESS * width
            assert bool(floors[k] & bit) == (overlapping[k] and not nests and bool(candidate))
    assert nest.any() and holds.any() and floors.any()  # each test decided some pairs both ways
    assert not nest.all() and not holds.all()


def test_part_hulls_refuse_coordinates_that_are_not_finite() -> None:
    # the compiled hull sorts by coordinate: NaN among them gave a wrong hull (one vertex for a part of 200 points)
    points = np.random.default_rng(0).normal(size=(20, 3)).astype(np.float32)
    points[7, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        part_hulls(points, np.array([0, 10, 20]))
