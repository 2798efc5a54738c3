"""The clutter segmenter on rendered tabletops whose ground truth is known per pixel (ray-cast geometry ids)."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest

from annotators.cloud.clutter import segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.plane import ransac_support_plane
from annotators.geometry.convexity import dense_labels
from annotators.geometry.grid_segmentation import (
    disc_offsets,
    grow_from_seeds,
    grow_labels,
    grow_labels_nearby,
    seed_distances,
)

Box = tuple[tuple[float, float, float], tuple[float, float, float]]  # (size, corner)


def render(boxes: list[Box], seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Organized 480x640 camera-frame points, colours and per-pixel object ids (0 = table or nothing) of boxes on
    a table, seen from 0.8 m at 45 degrees with 1.5 mm depth noise."""
    scene = o3d.t.geometry.RaycastingScene()
    table = o3d.geometry.TriangleMesh.create_box(1.2, 1.0, 0.02).translate((-0.6, -0.3, -0.02))
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(table))
    for size, corner in boxes:
        mesh = o3d.geometry.TriangleMesh.create_box(*size).translate(corner)
        scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    eye, target = np.array([0.0, -0.55, 0.55]), np.array([0.0, 0.1, 0.0])
    rays = o3d.t.geometry.RaycastingScene.create_rays_pinhole(55.0, target.tolist(), eye.tolist(), [0, 0, 1], 640, 480)
    hits = scene.cast_rays(rays)
    t, ids = hits["t_hit"].numpy(), hits["geometry_ids"].numpy().astype(np.int64)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    offset = rays.numpy()[..., 3:] * np.where(np.isfinite(t), t, 0.0)[..., None]
    points = np.stack([offset @ right, offset @ down, offset @ forward], axis=-1)
    points[~np.isfinite(t)] = np.nan
    points *= (1.0 + np.random.default_rng(seed).normal(0.0, 0.0015, t.shape) / points[..., 2])[..., None]
    objects = np.where(np.isfinite(t) & (ids >= 1) & (ids <= len(boxes)), ids, 0)
    palette = np.array([[150, 110, 70], [200, 40, 40], [40, 160, 60], [40, 60, 200], [220, 200, 40]], np.uint8)
    colors = palette[np.where(np.isfinite(t), np.minimum(ids, len(palette) - 1), 0)]
    return points.astype(np.float32), np.ascontiguousarray(colors), objects


def segment(points: np.ndarray, colors: np.ndarray) -> np.ndarray:
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    plane = ransac_support_plane(points, mask)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    for number, found in enumerate(segment_clutter(points, mask, plane.model, plane.inlier_indices, colors=colors), 1):
        labels[found.mask] = number
    return labels


def best_ious(objects: np.ndarray, labels: np.ndarray) -> list[float]:
    """Per object: the best IoU any segment reaches on its pixels."""
    result = []
    for object_id in range(1, int(objects.max()) + 1):
        truth = objects == object_id
        result.append(max(np.count_nonzero(truth & (labels == s)) / np.count_nonzero(truth | (labels == s))
                          for s in range(1, int(labels.max()) + 1)))  # fmt: skip
    return result


SCENES = {
    "apart": [((0.10, 0.08, 0.12), (-0.20, 0.05, 0.0)), ((0.12, 0.12, 0.06), (0.05, 0.10, 0.0))],
    "touching": [((0.10, 0.08, 0.12), (-0.10, 0.05, 0.0)), ((0.12, 0.10, 0.10), (0.0, 0.08, 0.0))],
    "stacked": [((0.16, 0.12, 0.05), (-0.08, 0.04, 0.0)), ((0.08, 0.06, 0.08), (-0.05, 0.06, 0.05))],
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_box_is_one_segment_whether_apart_touching_or_stacked(name: str) -> None:
    points, colors, objects = render(SCENES[name])
    labels = segment(points, colors)
    assert int(labels.max()) == len(SCENES[name])
    assert all(iou >= 0.8 for iou in best_ious(objects, labels)), best_ious(objects, labels)


def test_dense_labels_number_present_keys_in_order() -> None:
    keys = np.array([[0, 7, 7], [30, 0, 2]])
    assert dense_labels(keys).tolist() == [[0, 2, 2], [3, 0, 1]]


@pytest.mark.parametrize("seed", range(4))
def test_labels_grow_alike_from_a_transform_made_for_a_farther_reach(seed: int) -> None:
    rng = np.random.default_rng(seed)
    labels = np.zeros((120, 160), dtype=np.int32)  # blocky parts with gaps, away from the grid's border
    coarse = rng.integers(0, 6, (12, 16))
    labels[30:78, 40:104] = np.kron(coarse, np.ones((4, 4), dtype=np.int64)).astype(np.int32)
    labels[rng.random(labels.shape) < 0.15] = 0
    region = np.zeros(labels.shape, dtype=bool)  # the transforms' boxes differ with the reach
    region[20:88, 30:114] = rng.random((68, 84)) < 0.8
    renamed = np.where(labels > 0, rng.permutation(np.arange(1, 7))[labels - 1] + 10, 0).astype(np.int32)
    for near, far in ((2.0, 12.0), (3.0, 3.0), (1.5, 7.0)):
        expected = grow_labels(renamed, region, near)
        assert np.array_equal(grow_from_seeds(renamed, seed_distances(labels, region, far), near), expected)
        assert np.count_nonzero(expected) > np.count_nonzero(renamed)  # something grew


def test_disc_offsets_are_the_pixels_within_the_radius_nearest_first() -> None:
    offsets = disc_offsets(3.0)
    squared = (offsets**2).sum(axis=1)
    assert offsets.shape == (28, 2)  # 29 pixels within 3 px of the origin, the origin left out
    assert squared.min() == 1 and squared.max() == 9 and np.all(np.diff(squared) >= 0)
    assert offsets[:4].tolist() == [[-1, 0], [0, -1], [0, 1], [1, 0]]  # row-major among equals


@pytest.mark.parametrize("seed", range(4))
def test_nearby_growth_gives_each_unlabelled_pixel_the_nearest_label_within_reach(seed: int) -> None:
    rng = np.random.default_rng(seed)
    labels = np.zeros((60, 80), dtype=np.int32)
    labels[rng.random(labels.shape) < 0.03] = 1
    labels[rng.random(labels.shape) < 0.03] = 2
    region = rng.random(labels.shape) < 0.7
    grown = grow_labels_nearby(labels, region, 3.0)
    rows, cols = np.nonzero(labels)
    for r, c in zip(*np.nonzero(region & (labels == 0)), strict=True):
        distances = np.hypot(rows - r, cols - c)
        if distances.min() > 3.0:
            assert grown[r, c] == 0
        else:  # the label of a nearest labelled pixel (one of them where several lie at that distance)
            assert grown[r, c] in set(labels[rows, cols][distances == distances.min()].tolist())
    assert np.array_equal(grown[~region | (labels > 0)], labels[~region | (labels > 0)])


@pytest.mark.parametrize("seed", range(4))
def test_nearby_growth_reaches_the_pixels_the_distance_transform_reaches(seed: int) -> None:
    # the chamfer transform of grow_labels and the Euclidean disc reach the same pixels within 3 px; they may
    # pick another of two labels only where both lie about as near, and never on blocky parts with one label
    rng = np.random.default_rng(seed)
    labels = np.zeros((120, 160), dtype=np.int32)
    labels[30:78, 40:104] = np.kron(rng.integers(0, 6, (12, 16)), np.ones((4, 4), dtype=np.int64)).astype(np.int32)
    labels[rng.random(labels.shape) < 0.15] = 0
    region = np.zeros(labels.shape, dtype=bool)
    region[20:88, 30:114] = rng.random((68, 84)) < 0.8
    nearby, transformed = grow_labels_nearby(labels, region, 3.0), grow_labels(labels, region, 3.0)
    assert np.array_equal(nearby > 0, transformed > 0)
    assert np.count_nonzero(nearby != transformed) < 0.05 * np.count_nonzero(nearby > labels)
    single = (labels > 0).astype(np.int32)
    assert np.array_equal(grow_labels_nearby(single, region, 3.0), grow_labels(single, region, 3.0))
