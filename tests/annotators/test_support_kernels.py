"""The compiled forms in annotators.geometry.support give what their numpy / OpenCV forms give."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from annotators.geometry.grid_segmentation import boundaries, inside_share, pixel_footprint
from annotators.geometry.support import (
    AppendageRules,
    close_borders,
    held_share,
    span,
    span_numpy,
    summarize_pieces,
    summarize_pieces_numpy,
)
from annotators.geometry.support_kernels import (
    appendage_candidates,
    box_label_points,
    hull_candidates,
    kept_labels,
    narrowest_slice_span,
    unsupported_candidates,
)
from annotators.geometry.support_kernels import pixel_footprint as compiled_footprint


def blocky_scene(seed: int, shape=(37, 53), count: int = 9) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Labels of random overlapping rectangles (some labels absent, gaps of 0), camera points and (u, v, height)
    plane coordinates with missing heights, repeated heights and heights beyond +-0.49 m."""
    rng = np.random.default_rng(seed)
    labels = np.zeros(shape, dtype=np.int32)
    for label in range(1, count + 1):
        if label == 4:
            continue  # an absent label
        y0, x0 = rng.integers(0, shape[0] - 3), rng.integers(0, shape[1] - 3)
        labels[y0 : y0 + rng.integers(2, 15), x0 : x0 + rng.integers(2, 20)] = label
    plane = rng.normal(0.0, 0.2, (*shape, 3)).astype(np.float32)
    plane[..., 2] = np.round(plane[..., 2], 2)  # ties
    plane[rng.random(shape) < 0.1, 2] = np.nan
    plane[0, 0, 2], plane[2, 2, 2] = 0.7, -0.8
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    depth = (1.0 + 0.01 * rng.random(shape)).astype(np.float32)
    depth[labels == 2] += 0.3  # a depth jump around one label
    points = np.stack([(cols - 26) * 0.002 * depth, (rows - 18) * 0.002 * depth, depth], axis=-1).astype(np.float32)
    points[rng.random(shape) < 0.03] = np.nan
    return labels, points, plane


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("step", [1, 2, 3])
def test_the_compiled_piece_summary_is_the_numpy_one(seed: int, step: int) -> None:
    labels, _, plane = blocky_scene(seed)
    compiled, reference = summarize_pieces(labels, plane, step), summarize_pieces_numpy(labels, plane, step)
    for name in ("sizes", "low", "high", "top", "starts", "boxes", "touching", "border"):
        assert np.array_equal(getattr(compiled, name), getattr(reference, name), equal_nan=True), name
    assert compiled.low.shape == (labels.max() + 1,) and compiled.touching.shape[0] > 0
    assert np.isfinite(compiled.low).sum() >= 5
    for label in range(1, labels.max() + 1):
        mine, theirs = compiled.hull(label), reference.hull(label)
        assert np.array_equal(np.unique(mine, axis=0), np.unique(theirs, axis=0))  # the same points, any order


def test_the_compiled_footprint_is_the_numpy_one() -> None:
    for seed in range(4):
        _, points, _ = blocky_scene(seed)
        points[3, :, 2] = 0.0  # a row of zero depths: infinite ratios
        assert compiled_footprint(points) == pixel_footprint(points)
    assert compiled_footprint(np.full((3, 4, 3), np.nan, dtype=np.float32)) == pixel_footprint(
        np.full((3, 4, 3), np.nan, dtype=np.float32)
    )


def test_the_held_share_is_the_inside_share() -> None:
    rng = np.random.default_rng(5)
    for _ in range(200):
        inner = rng.normal(0.0, 0.03, (int(rng.integers(3, 9)), 2)).astype(np.float32)
        outer = (rng.normal(0.0, 0.05, (int(rng.integers(3, 9)), 2)) + rng.normal(0.0, 0.03, 2)).astype(np.float32)
        inner, outer = cv2.convexHull(inner).reshape(-1, 2), cv2.convexHull(outer).reshape(-1, 2)
        assert held_share(inner, outer, 0.005) == inside_share(inner, outer, 0.005)


@pytest.mark.parametrize("seed", range(4))
def test_the_close_borders_are_those_of_the_boundaries(seed: int) -> None:
    labels, points, _ = blocky_scene(seed)
    normals = np.zeros_like(points)
    normals[..., 2] = -1.0
    rules = AppendageRules()
    footprint = pixel_footprint(points)
    pairs, close, length = close_borders(labels, points, normals, rules, footprint)
    reference = boundaries(
        labels, points, normals, rules.jump_absolute, rules.jump_relative, reach=2, footprint=footprint
    )
    assert pairs.shape[0] > 0
    assert np.array_equal(pairs, reference.pairs)
    assert np.array_equal(close, reference.close) and np.array_equal(length, reference.length)


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_candidates_are_the_numpy_ones(seed: int) -> None:
    labels, _, plane = blocky_scene(seed)
    plane[..., 2] = np.abs(plane[..., 2]) * 0.3  # heights over the table, so that some pieces qualify
    pieces = summarize_pieces(labels, plane, 1)
    pairs = pieces.touching
    both = np.concatenate([pairs, pairs[:, ::-1]])
    sizes, low, high, top = pieces.sizes, pieces.low, pieces.high, pieces.top
    with np.errstate(invalid="ignore"):
        held = (
            (low[both[:, 0]] > low[both[:, 1]] + 0.003)
            & (low[both[:, 0]] < low[both[:, 1]] + 0.5 * (high[both[:, 1]] - low[both[:, 1]]))
            & (sizes[both[:, 1]] >= sizes[both[:, 0]])
        )
    assert np.array_equal(unsupported_candidates(pairs, sizes, low, high, 0.003, 0.5), both[held])
    border = np.concatenate([pieces.border, pieces.border])
    for small_share in (0.25, 1.0):
        with np.errstate(invalid="ignore"):
            fits = (
                (sizes[both[:, 0]] <= small_share * sizes[both[:, 1]])
                & (
                    (low[both[:, 0]] >= low[both[:, 1]] - 0.003)
                    | (0.5 * (low[both[:, 0]] + high[both[:, 0]]) >= low[both[:, 1]])
                )
                & (high[both[:, 0]] <= top[both[:, 1]] + 0.003)
                & (border >= np.maximum(3, 0.6 * np.sqrt(sizes[both[:, 0]])))
            )
        found = appendage_candidates(pairs, pieces.border, sizes, low, high, top, small_share, 0.003, 3, 0.6)
        assert np.array_equal(found, both[fits])


def test_kept_labels_are_those_numpy_keeps() -> None:
    labels, _, _ = blocky_scene(2)
    keep = np.zeros(labels.max() + 1, dtype=bool)
    keep[[2, 5, 7]] = True
    window = labels[3:30, 5:40]
    kept = kept_labels(window, keep)
    assert np.array_equal(kept, np.where(keep[window], window, 0)) and kept.dtype == window.dtype
    assert kept.flags.c_contiguous and np.count_nonzero(kept) > 0


def test_the_hull_candidates_have_the_hull_of_all_points() -> None:
    rng = np.random.default_rng(11)
    for trial in range(300):
        points = rng.normal(0.0, 0.05, (int(rng.integers(4, 300)), 2)).astype(np.float32)
        if trial % 3 == 1:
            points = np.round(points / 0.01).astype(np.float32) * np.float32(0.01)  # duplicates, collinear runs
        if trial % 3 == 2:
            points[:, 1] = points[:, 0] * np.float32(0.5)  # all on one line
        candidates = hull_candidates(points)
        assert candidates.shape[0] <= points.shape[0]
        mine, theirs = cv2.convexHull(candidates).reshape(-1, 2), cv2.convexHull(points).reshape(-1, 2)
        assert np.array_equal(np.unique(mine, axis=0), np.unique(theirs, axis=0))
    assert hull_candidates(rng.normal(0.0, 0.05, (500, 2)).astype(np.float32)).shape[0] < 250  # it does thin


@pytest.mark.parametrize("seed", range(5))
def test_the_height_quantiles_of_many_small_tied_pieces_are_the_numpy_ones(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    labels = rng.integers(0, 60, (24, 31)).astype(np.int32)  # pieces of 0 to ~20 pixels, scattered
    plane = rng.normal(0.0, 0.1, (24, 31, 3)).astype(np.float32)
    plane[..., 2] = np.round(plane[..., 2], 1 + seed % 2)  # many equal heights
    plane[rng.random((24, 31)) < 0.2, 2] = np.nan
    compiled, reference = summarize_pieces(labels, plane, 1), summarize_pieces_numpy(labels, plane, 1)
    for name in ("low", "high", "top"):
        assert np.array_equal(getattr(compiled, name), getattr(reference, name), equal_nan=True), name


@pytest.mark.parametrize("seed", range(6))
def test_box_label_points_match_the_masked_box(seed: int) -> None:
    labels, _, plane = blocky_scene(seed)
    pieces = summarize_pieces(labels, plane, 1)
    window = (slice(2, -3), slice(1, -4))  # a strided view of the grid is read in place, as a whole one
    for grid, labelling in ((plane, labels), (plane[window], labels[window])):
        for label in range(0, int(labelling.max()) + 2):
            for box in ((0, 0, labelling.shape[1], labelling.shape[0]), (3, 2, 17, 11), (5, 5, 5, 9)):
                x0, y0, x1, y1 = box
                expected = grid[y0:y1, x0:x1][labelling[y0:y1, x0:x1] == label]
                found = box_label_points(labelling, grid, label, np.array(box))
                assert found.dtype == expected.dtype
                assert np.array_equal(found, expected, equal_nan=True)
    for label in range(1, int(labels.max()) + 1):  # the labels' own boxes, as the support joins read them
        x0, y0, x1, y1 = pieces.boxes[label]
        expected = plane[y0:y1, x0:x1][labels[y0:y1, x0:x1] == label]
        assert np.array_equal(box_label_points(labels, plane, label, pieces.boxes[label]), expected, equal_nan=True)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("count", [1, 2, 3, 40, 900])
def test_the_compiled_span_is_the_numpy_one(seed: int, count: int) -> None:
    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.005, 0.3, 2)
    feet = (rng.normal(size=(count, 2)) * scale @ np.array([[0.8, 0.6], [-0.6, 0.8]]) + rng.uniform(-1, 1, 2)).astype(
        np.float32
    )
    # the float32 points' spans agree to float32 rounding (the NumPy form computes in float32)
    assert span(feet) == pytest.approx(span_numpy(feet), rel=1e-5, abs=1e-7)
    assert span(feet.astype(np.float64), 0.2) == pytest.approx(span_numpy(feet.astype(np.float64), 0.2), rel=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_the_narrowest_slice_is_the_least_span_of_the_slices_measured_one_by_one(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, 0.05, (600, 3))
    points[:, 2] = rng.uniform(0.0, 0.2, 600)
    points[points[:, 2] < 0.06, :2] *= 0.2  # a narrow neck low down
    bottoms = np.arange(0.0, 0.1, 0.01)
    expected = np.inf
    for bottom in bottoms:
        inside = points[(points[:, 2] >= bottom) & (points[:, 2] < bottom + 0.01), :2]
        if inside.shape[0] >= 5:
            expected = min(expected, span_numpy(inside))
    assert narrowest_slice_span(points, bottoms, 0.01, 5) == pytest.approx(expected, rel=1e-9)
    assert narrowest_slice_span(points, bottoms, 0.01, 10_000) == np.inf
