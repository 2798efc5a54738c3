"""Plane RANSAC and oriented boxes on synthetic point sets."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters
from annotators.cloud.normals import grid_normals
from annotators.cloud.plane import ransac_support_plane, up_in_camera
from annotators.geometry.boxes import object_box, principal_box, upright_box
from annotators.geometry.grid_segmentation import (
    MergeRules,
    boundaries,
    chroma_image,
    color_edges,
    distinct_keys,
    footprint_overlap,
    footprint_overlaps,
    heights_nest,
    is_floor_within,
    looks_like_inside,
    merge_parts,
)
from robokudo.core.types import CameraInfo, CameraIntrinsics


def scene_cloud(rows: int = 120, cols: int = 160) -> np.ndarray:
    """An organized cloud (focal length 100 px): a wall 0.8 m ahead above a floor 0.3 m below the camera.

    The wall covers most pixels, so only the gravity prior makes the floor the support.
    """
    v, u = np.mgrid[0:rows, 0:cols].astype(np.float64)
    rays = np.stack([(u - cols / 2) / 100, (v - rows / 2) / 100, np.ones_like(u)], axis=-1)
    with np.errstate(divide="ignore"):
        floor_depth = np.where(rays[..., 1] > 0, 0.3 / rays[..., 1], np.inf)
    return (rays * np.minimum(floor_depth, 0.8)[..., None]).astype(np.float32)


def test_ransac_is_deterministic_and_finds_the_floor_when_up_is_known() -> None:
    points = scene_cloud()
    mask = np.isfinite(points[..., 2])
    up = np.array([0.0, -1.0, 0.0])  # camera y points down
    first = ransac_support_plane(points, mask, seed=3, up=up)
    second = ransac_support_plane(points, mask, seed=3, up=up)
    assert first is not None and second is not None
    assert np.array_equal(first.model, second.model)
    assert np.array_equal(first.inlier_indices, second.inlier_indices)
    assert first.model[:3] @ up > 0.999 and first.model[3] == pytest.approx(0.3, abs=1e-3)


def test_plane_normal_points_toward_the_camera() -> None:
    points = scene_cloud()
    mask = np.isfinite(points[..., 2])
    fit = ransac_support_plane(points, mask, up=np.array([0.0, -1.0, 0.0]))
    assert fit is not None and fit.model[3] > 0  # the origin lies on the positive side
    wall = ransac_support_plane(points, mask)  # without gravity: the dominant plane
    assert wall is not None and wall.model[2] < -0.999 and wall.model[3] == pytest.approx(0.8, abs=1e-3)


def test_up_in_camera_follows_the_camera_pose() -> None:
    k = CameraIntrinsics(1.0, 1.0, 0.0, 0.0, 1, 1)
    assert up_in_camera(CameraInfo(k)) is None
    looking_forward = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 1.5], [0, 0, 0, 1]])
    assert np.allclose(up_in_camera(CameraInfo(k, looking_forward)), [0, -1, 0])


@pytest.mark.parametrize(
    "points",
    [
        np.zeros((0, 3)),
        np.array([[0.1, 0.2, 0.3]]),
        np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0]]),
        np.array([[0.0, 0.0, 1.0]] * 50),
        np.column_stack([np.linspace(0, 1, 30), np.zeros(30), np.ones(30)]),  # a line
        np.column_stack([np.random.default_rng(0).random((40, 2)), np.ones(40)]),  # flat
        np.full((10, 3), np.nan),
    ],
)
def test_boxes_of_degenerate_point_sets_never_raise(points: np.ndarray) -> None:
    for fit in (principal_box, upright_box):
        box = fit(points)
        assert box.centre.shape == (3,) and np.all(np.isfinite(box.centre))
        assert np.allclose(box.rotation @ box.rotation.T, np.eye(3), atol=1e-6)
        assert np.all(box.extents >= 0)


def test_upright_box_recovers_a_rotated_box() -> None:
    rng = np.random.default_rng(1)
    local = (rng.random((2000, 3)) - 0.5) * [0.2, 0.1, 0.3]
    yaw = np.radians(30)
    rotation = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    world = local @ rotation.T + [1.0, 2.0, 0.9]
    box = upright_box(world)
    assert np.allclose(box.centre, [1.0, 2.0, 0.9], atol=0.005)
    assert np.allclose(sorted(box.extents), [0.1, 0.2, 0.3], atol=0.01)
    assert box.rotation[2, 2] == pytest.approx(1.0)


def test_object_box_reports_world_frame_only_with_a_camera_pose() -> None:
    points = np.random.default_rng(2).random((100, 3))
    assert object_box(points, None)[1] == "camera"
    box, frame = object_box(points, np.eye(4))
    assert frame == "world" and np.allclose(box.centre, (points.min(0) + points.max(0)) / 2, atol=0.2)


def test_the_inside_of_a_cup_is_recognised_and_a_neighbour_is_not() -> None:
    angles = np.linspace(0, np.pi, 50)
    # plane coordinates (u across, v along the line of sight, height); the cup stands 0.6 m ahead
    front = np.column_stack([0.04 * np.cos(angles), 0.6 - 0.04 * np.sin(angles), np.full(50, 0.08)])
    front = np.vstack([front, front * [1, 1, 0.2]])
    # the inner back wall, seen over the front rim, from the rim (0.07 m) down to 0.02 m
    back = np.column_stack([0.038 * np.cos(angles), 0.6 + 0.038 * np.sin(angles), np.linspace(0.02, 0.07, 50)])
    beside = back + np.array([0.09, 0.0, 0.0])
    taller_behind = back * np.array([1, 1, 0]) + np.array([0, 0.06, 0.2])
    flat_top_behind = back * np.array([1, 1, 0]) + np.array([0, 0.0, 0.075])  # a box's top face behind the cup
    assert looks_like_inside(front, back, 0.01, 1.5)
    assert not looks_like_inside(front, beside, 0.01, 1.5)
    assert not looks_like_inside(front, taller_behind, 0.01, 1.5)
    assert not looks_like_inside(front, flat_top_behind, 0.01, 1.5)


def _heights(low: float, high: float, count: int = 200) -> np.ndarray:
    return np.linspace(low, high, count)


def test_a_handle_reaching_the_rim_nests_in_its_body_and_what_stands_on_it_does_not() -> None:
    # a mug body seen from above: many points low on its wall, few up to its rim at 0.095 m
    body = np.concatenate([_heights(0.015, 0.085, 380), _heights(0.085, 0.095, 20)])
    handle = _heights(0.070, 0.095)  # hangs from the rim: above the body's 95 % height, not above its top
    assert heights_nest(handle, body, 0.003)
    lid = _heights(0.095, 0.105)  # a flat lid lying on top
    assert not heights_nest(lid, body, 0.003)
    # a neighbour as tall, seen from higher up, is measured against the 95 % height, not the top
    neighbour = _heights(0.030, 0.0965)
    assert not heights_nest(neighbour, body, 0.003)


def test_the_top_of_a_bowls_outer_wall_nests_in_its_inside_up_to_the_rim() -> None:
    # the inside seen over the rim: floor to rim, few points on the rim itself (bench/profiles/segscore-analysis.txt,
    # learn35's white bowl); the outer wall's upper half, the rest cut off as another piece, reaches the rim
    inside = np.concatenate([_heights(0.017, 0.084, 470), _heights(0.084, 0.089, 25)])
    outer_top = _heights(0.052, 0.0905)  # more than half the inside's heights, all in their upper half
    assert heights_nest(outer_top, inside, 0.003)
    # a neighbour beside it, seen from higher up, reaching as high: measured against the 95 % height
    beside = _heights(0.030, 0.094)
    assert not heights_nest(beside, inside, 0.003)


def _disk(centre: tuple[float, float], radius: float, height: np.ndarray) -> np.ndarray:
    angles = np.linspace(0, 2 * np.pi, height.size, endpoint=False)
    radii = radius * np.sqrt(np.linspace(0.05, 1.0, height.size))
    return np.column_stack([centre[0] + radii * np.cos(angles), centre[1] + radii * np.sin(angles), height])


def _hull(points: np.ndarray) -> np.ndarray:
    return cv2.convexHull(points[:, :2].astype(np.float32)).reshape(-1, 2)


def test_a_bowls_floor_joins_its_walls_and_a_box_under_another_does_not() -> None:
    rules = MergeRules(nested=True)
    walls = _disk((0.0, 0.6), 0.08, _heights(0.02, 0.085, 400))
    floor = _disk((0.0, 0.6), 0.03, np.full(200, 0.012))
    assert is_floor_within(walls, floor, _hull(walls), _hull(floor), rules)
    # the side of a narrower box under a wider one: inside its footprint and below it, but not a flat floor
    side = _disk((0.0, 0.6), 0.03, _heights(0.0, 0.018))
    assert not is_floor_within(walls, side, _hull(walls), _hull(side), rules)
    # a flat object beside the bowl (a coaster partly outside its footprint) is not its floor
    coaster = _disk((0.08, 0.6), 0.04, np.full(200, 0.005))
    assert not is_floor_within(walls, coaster, _hull(walls), _hull(coaster), rules)


def folded_sheet(fold: float) -> tuple[np.ndarray, np.ndarray]:
    """A 40x40 organized sheet 1 m ahead (4 mm pixels) folded along its middle column: ``fold`` > 0 bends the
    middle away from the camera (a concave crease), < 0 toward it (a convex ridge); points and their normals."""
    v, u = np.mgrid[0:40, 0:40].astype(np.float32)
    x, y = (u - 20) * 0.004, (v - 20) * 0.004
    points = np.stack([x, y, 1.0 - fold * np.abs(x)], axis=-1).astype(np.float32)
    return points, grid_normals(points, 2, 3, 0.02, 0.01)


@pytest.mark.parametrize(("fold", "crease_rows"), [(0.5, (36, 8)), (-0.5, (0, 0))])
def test_a_crease_is_measured_along_the_part_of_a_boundary_it_runs(fold: float, crease_rows: tuple[int, int]) -> None:
    points, normals = folded_sheet(fold)
    cols = np.arange(40)[None, :].repeat(40, axis=0)
    halves = np.where(cols < 20, 1, 2).astype(np.int32)
    halves[:, :2] = 0
    upper_joined = halves.copy()  # the right half's upper 30 rows belong to the left part: 10 rows of crease left
    upper_joined[:30][upper_joined[:30] == 2] = 1
    for labels, rows in zip((halves, upper_joined), crease_rows, strict=True):
        found = boundaries(labels, points, normals, 0.02, 0.01)
        assert found.pairs.tolist() == [[1, 2]]
        assert found.crease_length.tolist() == [rows]
        assert (found.creased > 0) == (rows > 0)


def square(x: float, y: float, side: float) -> np.ndarray:
    """The corners (4x2, metres, float32) of an axis-aligned square with its lower corner at (x, y)."""
    return np.array([[x, y], [x + side, y], [x + side, y + side], [x, y + side]], dtype=np.float32)


def test_footprint_overlaps_of_many_pairs_are_those_of_each_pair_alone() -> None:
    firsts = [square(0.0, 0.0, 0.1), square(0.0, 0.0, 0.1), square(0.0, 0.0, 0.1), square(0.3, 0.2, 0.04)]
    seconds = [square(0.05, 0.0, 0.1), square(0.5, 0.5, 0.1), square(0.02, 0.02, 0.05), square(0.0, 0.0, 0.1)]
    shares = footprint_overlaps(firsts, seconds, 0.005)
    assert shares[0] == pytest.approx(0.5, abs=0.06)  # half of one square lies on the other
    assert shares[1] == 0.0 and shares[3] == 0.0  # apart
    assert shares[2] == 1.0  # the small square lies within the large one
    assert shares.tolist() == [footprint_overlap(a, b, 0.005) for a, b in zip(firsts, seconds, strict=True)]
    assert footprint_overlaps([], [], 0.005).shape == (0,)


@pytest.mark.parametrize("size", [0, 1, 7, 3000])
def test_distinct_keys_are_numpy_unique_with_inverse(size: int) -> None:
    keys = np.repeat(np.random.default_rng(size).integers(0, 500, size), 3)[:size]  # runs, as along boundaries
    unique, inverse = distinct_keys(keys)
    expected, expected_inverse = np.unique(keys, return_inverse=True)
    np.testing.assert_array_equal(unique, expected)
    np.testing.assert_array_equal(inverse, expected_inverse)


def test_color_edges_are_the_canny_edges_of_the_chroma_channels() -> None:
    rng = np.random.default_rng(5)
    colors = cv2.resize(rng.integers(0, 256, (12, 16, 3), dtype=np.uint8), (160, 120), interpolation=cv2.INTER_NEAREST)
    colors = cv2.add(colors, rng.integers(0, 12, colors.shape, dtype=np.uint8))  # sensor noise
    chroma = chroma_image(colors)
    assert chroma.shape == (120, 160, 2)
    with_constant = np.dstack([chroma, np.full((120, 160), 128, dtype=np.uint8)])  # a flat third channel adds none
    edges = color_edges(colors, 40.0, 100.0)
    np.testing.assert_array_equal(edges, cv2.Canny(with_constant, 40.0, 100.0) > 0)
    assert edges.any()


def _box_beside_a_lower_box() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Labels, depth and plane coordinates ``(u, v, height)`` of two touching parts on a 10x60 grid: a box 0-10 cm
    along u and 10 cm tall (label 1, columns 0-39) and a lower box 20-30 cm along u, 2-8 cm tall (label 2, columns
    40-59); label 1's last column took points of the lower box (u 25 cm)."""
    rows, cols = np.mgrid[0:10, 0:60].astype(np.float32)
    u = np.where(cols < 39, cols * 0.1 / 38, np.where(cols < 40, 0.25, 0.2 + (cols - 40) * 0.1 / 19))
    height = np.where(cols < 39, rows * 0.1 / 9, np.where(cols < 40, 0.05, 0.02 + rows * 0.06 / 9))
    table = np.stack([u, rows * 0.01, height], axis=-1).reshape(-1, 3).astype(np.float32)
    labels = np.where(cols < 40, 1, 2).astype(np.int32)
    return labels, np.ones(labels.shape, dtype=np.float32), table


def test_footprints_that_overlap_only_through_stray_pixels_do_not_join() -> None:
    labels, depth, table = _box_beside_a_lower_box()
    rules = ClutterParameters().merge_rules()
    assert merge_parts(labels, depth, table, rules).max() == 1  # the stray points stretch the box over its neighbour
    spilled = np.zeros(labels.shape, dtype=bool)
    spilled[:, 39] = True  # strays: 2.5 % of the box's pixels
    assert merge_parts(labels, depth, table, rules, spilled=spilled).max() == 2
    spilled[:, 24:39] = True  # 40 %: the shape of a piece cut at an outline, not strays; the join stands
    assert merge_parts(labels, depth, table, rules, spilled=spilled).max() == 1
