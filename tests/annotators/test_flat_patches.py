"""Grown patches (annotators/geometry/flat_patches.py): boundaries from the data, not from where a grid starts."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.normals import grid_normals
from annotators.cloud.plane import ransac_support_plane
from annotators.geometry.flat_patches import flat_patches
from tests.annotators.test_clutter import SCENES, best_ious, render


def roof(rows: int = 40, cols: int = 60, ridge: int = 27, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Organized points (about 1 m away) of two planes meeting at a ridge along column ``ridge`` at 90 degrees, with
    1 mm noise; and their normals."""
    rng = np.random.default_rng(seed)
    v, u = np.indices((rows, cols), dtype=np.float64)
    x = (u - ridge) * 0.004
    y = v * 0.004
    z = 1.0 + np.abs(x) + rng.normal(0.0, 0.001, x.shape)
    points = np.stack([x, y, z], axis=-1).astype(np.float32)
    return points, grid_normals(points, 2, 3, 0.02, 0.02)


def partition(labels: np.ndarray) -> set[frozenset[int]]:
    """The patches as sets of flat pixel indices (the numbering left out)."""
    flat = labels.reshape(-1)
    return {frozenset(np.flatnonzero(flat == label).tolist()) for label in range(1, int(flat.max()) + 1)}


def test_a_patch_never_lies_across_a_ridge() -> None:
    points, normals = roof()
    surfaces = np.ones(points.shape[:2], dtype=np.int32)
    patches = flat_patches(surfaces, normals, points, 6, 16.0, 0.01)
    cols = np.indices(patches.shape)[1]
    inner = slice(4, -4)  # away from the border, where the normals are known
    for label in np.unique(patches[inner, inner]):
        sides = np.unique(np.sign(cols[inner, inner][patches[inner, inner] == label] - 27))
        assert set(sides.tolist()) <= {-1, 0} or set(sides.tolist()) <= {0, 1}, (label, sides)


def test_the_patches_cover_each_surface_and_stay_small() -> None:
    points, normals = roof()
    surfaces = np.ones(points.shape[:2], dtype=np.int32)
    surfaces[:, 40:] = 2
    patches = flat_patches(surfaces, normals, points, 6, 16.0, 0.01)
    known = np.isfinite(normals[..., 0])
    assert (patches[known] > 0).all()
    for label in range(1, int(patches.max()) + 1):
        rows, cols = np.nonzero(patches == label)
        assert np.unique(surfaces[rows, cols]).size == 1  # one surface
        assert np.ptp(rows) < 18 and np.ptp(cols) < 18, (label, np.ptp(rows), np.ptp(cols))


@pytest.mark.parametrize(("dy", "dx"), [(1, 0), (0, 3), (5, 2)])
def test_shifting_the_crop_moves_the_patches_with_it(dy: int, dx: int) -> None:
    points, normals = roof(ridge=31)
    surfaces = np.zeros(points.shape[:2], dtype=np.int32)
    surfaces[6:36, 8:52] = 1
    first = flat_patches(surfaces, normals, points, 6, 16.0, 0.01)
    pad = ((dy, 0), (dx, 0))
    second = flat_patches(
        np.pad(surfaces, pad),
        np.pad(normals, (*pad, (0, 0)), constant_values=np.nan),
        np.pad(points, (*pad, (0, 0)), constant_values=np.nan),
        6,
        16.0,
        0.01,
    )
    assert partition(second[dy:, dx:]) == partition(first)


def segment(points: np.ndarray, colors: np.ndarray) -> np.ndarray:
    """Clutter labels with grown patches."""
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    plane = ransac_support_plane(points, mask)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    parameters = ClutterParameters(grown_patches=True)
    found = segment_clutter(points, mask, plane.model, plane.inlier_indices, parameters, colors)
    for number, segment in enumerate(found, 1):
        labels[segment.mask] = number
    return labels


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_box_is_one_segment_with_grown_patches(name: str) -> None:
    points, colors, objects = render(SCENES[name])
    labels = segment(points, colors)
    assert int(labels.max()) == len(SCENES[name])
    assert all(iou >= 0.8 for iou in best_ious(objects, labels)), best_ious(objects, labels)
