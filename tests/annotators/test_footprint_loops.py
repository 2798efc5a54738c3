"""The compiled footprint kernels: the convex hull covers what OpenCV's covers, the outside extents are the
quantiles of the projections numpy gives."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from annotators.geometry.grid_kernels import convex_hull, footprint_shares, outside_extents, sight_extents


def _polygon(points: np.ndarray) -> tuple[float, list[float], list[float]]:
    """Area, least and largest corner of a polygon: what a fill of it depends on, whatever vertex it starts at."""
    return float(cv2.contourArea(points.astype(np.float32))), points.min(axis=0).tolist(), points.max(axis=0).tolist()


@pytest.mark.parametrize("count", [3, 4, 17, 400, 800])
@pytest.mark.parametrize("kind", ["spread", "on_a_lattice", "on_a_line"])
def test_convex_hull_spans_opencvs_polygon(count: int, kind: str) -> None:
    rng = np.random.default_rng(count)
    for _ in range(50):
        points = rng.normal(size=(count, 3)).astype(np.float32)
        if kind == "on_a_lattice":  # repeated points and collinear hull edges
            points = np.round(points * 3) / 3
        if kind == "on_a_line":
            points[:, 1] = 2 * points[:, 0]
        ours = convex_hull(points[:, :2])  # a strided view, read in place
        theirs = cv2.convexHull(np.ascontiguousarray(points[:, :2])).reshape(-1, 2)
        assert ours.dtype == np.float32
        area, low, high = _polygon(ours)
        assert area == pytest.approx(_polygon(theirs)[0], abs=1e-5)
        assert (low, high) == _polygon(theirs)[1:]
        # every vertex is an input point, and the polygon turns one way only (convex, no collinear vertex)
        assert {tuple(v) for v in ours.tolist()} <= {tuple(p) for p in points[:, :2].tolist()}
        if ours.shape[0] >= 3:
            edges = np.roll(ours, -1, axis=0).astype(np.float64) - ours
            turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
            assert np.all(turns > 0)


def test_convex_hull_keeps_fewer_than_three_points() -> None:
    points = np.array([[0.5, 0.25], [1.0, 2.0]], dtype=np.float32)
    assert convex_hull(points).tolist() == points.tolist()


def test_outside_extents_are_the_quantiles_of_the_projections() -> None:
    rng = np.random.default_rng(3)
    near = (rng.normal(size=(501, 3)) * [0.03, 0.02, 0.04] + [0.4, -0.3, 0.06]).astype(np.float32)
    heights = np.sort(near[:, 2])
    extents = outside_extents(near, heights)
    centre = near[:, :2].astype(np.float64).mean(axis=0)
    along = centre / np.linalg.norm(centre)
    across = np.array([-along[1], along[0]])
    on_along, on_across = np.sort(near[:, :2] @ along), np.sort(near[:, :2] @ across)
    expected = [*along, on_across[25], on_across[475], heights[475], on_along[25], on_along[250], np.hypot(*centre)]
    assert extents == pytest.approx(expected, rel=1e-9, abs=1e-12)


def test_outside_extents_are_unknown_below_the_camera() -> None:
    near = np.array([[0.01, 0.0, 0.1], [-0.01, 0.0, 0.2], [0.0, 0.0, 0.3]], dtype=np.float32)
    assert np.isnan(outside_extents(near, np.sort(near[:, 2]))).all()


def _opencv_share(first: np.ndarray, second: np.ndarray) -> float:
    """Shared cells over the smaller polygon's, both filled by OpenCV on one raster (integer vertices)."""
    size = np.maximum(first.max(axis=0), second.max(axis=0)) + 1
    rasters = []
    for polygon in (first, second):
        raster = np.zeros((int(size[1]), int(size[0])), dtype=np.uint8)
        cv2.fillConvexPoly(raster, polygon.astype(np.int32), 1)
        rasters.append(raster.astype(bool))
    return np.count_nonzero(rasters[0] & rasters[1]) / max(1, min(np.count_nonzero(r) for r in rasters))


def test_footprint_shares_agree_with_opencvs_fill() -> None:
    rng = np.random.default_rng(5)
    polygons = []
    for _ in range(2 * 150):
        scatter = rng.normal(size=(200, 2)) * rng.uniform(1, 12, 2) + rng.uniform(60, 80, 2)
        polygons.append(cv2.convexHull(np.round(scatter).astype(np.int32)).reshape(-1, 2))
    count = len(polygons) // 2
    corner = np.array([polygon.min(axis=0) for polygon in polygons])
    boxes = np.column_stack([corner, np.array([polygon.max(axis=0) for polygon in polygons]) + 1 - corner])
    vertices = np.concatenate([polygon - low for polygon, low in zip(polygons, corner, strict=True)])
    starts = np.cumsum([0] + [polygon.shape[0] for polygon in polygons])
    everything = footprint_shares(vertices, starts, boxes, np.arange(count), count)
    expected = np.array([_opencv_share(polygons[k], polygons[count + k]) for k in range(count)])
    assert np.abs(everything - expected).max() < 0.05
    assert np.abs(everything - expected).mean() < 0.01
    assert (everything > 0).sum() == (expected > 0).sum() > 20  # the same pairs overlap, many of them
    # pairs left out stay 0; a polygon shares all of its cells with itself
    assert footprint_shares(vertices, starts, boxes, np.arange(1, count), count)[0] == 0.0
    same = footprint_shares(
        np.tile(vertices[: starts[1]], (2, 1)), np.array([0, starts[1], 2 * starts[1]]), boxes[[0, 0]], np.array([0]), 1
    )
    assert same[0] == 1.0


def test_sight_extents_are_the_quantiles_of_the_projections() -> None:
    rng = np.random.default_rng(4)
    points = (rng.normal(size=(300, 3)) * [0.02, 0.05, 0.03] + [-0.2, 0.5, 0.05]).astype(np.float32)
    along = np.array([0.6, 0.8])
    across = np.array([-0.8, 0.6])
    on_along, on_across = np.sort(points[:, :2] @ along), np.sort(points[:, :2] @ across)
    # index round(q * 299): 14.95 -> 15, 284.05 -> 284, 149.5 -> 150 (half to even)
    expected = [on_across[15], on_across[284], on_along[150], on_along[284]]
    assert sight_extents(points, along) == pytest.approx(expected, rel=1e-9, abs=1e-12)


def _monotone_chain(points: np.ndarray) -> list[list[float]]:
    """The hull of all points by Andrew's monotone chain (no points dropped first), counter-clockwise from the least
    (x, y), without collinear vertices: the reference for the compiled hull's filter."""
    ordered = sorted(map(tuple, points.astype(np.float64).tolist()))

    def turn(o: tuple, a: tuple, b: tuple) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    chain: list[tuple] = []
    for sweep in (ordered, ordered[::-1]):
        start = len(chain)
        for point in sweep:
            while len(chain) >= start + 2 and turn(chain[-2], chain[-1], point) <= 0.0:
                chain.pop()
            chain.append(point)
        chain.pop()
    return [list(point) for point in chain]


@pytest.mark.parametrize("seed", range(6))
def test_convex_hull_drops_no_vertex_with_its_octagon_filter(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(40):
        count = int(rng.integers(3, 500))
        points = rng.normal(size=(count, 2)) * rng.uniform(0.005, 0.1, 2) + rng.uniform(-0.5, 0.5, 2)
        if seed % 2:
            points = np.round(points, 2)  # a lattice: repeated points, collinear edges, ties in x and y
        points = points.astype(np.float32)
        assert convex_hull(points).astype(np.float64).tolist() == _monotone_chain(points)
