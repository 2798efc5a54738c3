"""The compiled cloud passes give exactly what the NumPy/OpenCV expressions they replace give."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.cloud.cloud_loops import centred_scatter, plane_band
from annotators.cloud.filters import range_mask
from annotators.cloud.plane import plane_distances


def _cloud(seed: int, dtype: type = np.float32) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1.0, 3.0, (48, 64, 3)).astype(dtype)
    points[rng.random((48, 64)) < 0.15] = np.nan
    return points, rng.random((48, 64)) < 0.8


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("bounds", [(0.2, 2.5), (0.7, 2.3), (np.float64(0.7), np.float64(2.3))])  # float32(0.7) < 0.7
def test_range_mask_matches_numpy_comparison_in_the_same_precision(dtype: type, bounds: tuple) -> None:
    points, mask = _cloud(1, dtype)
    low, high = bounds
    points[0, :4, 2] = [np.float32(low), np.float32(high), np.nextafter(np.float32(low), 0), np.inf]
    mask[0, :4] = True
    with np.errstate(invalid="ignore"):
        expected = mask & (points[..., 2] >= low) & (points[..., 2] <= high)
    assert np.array_equal(range_mask(points, mask, low, high), expected)
    assert np.array_equal(range_mask(points[:, ::2], mask[:, ::2], low, high), expected[:, ::2])


@pytest.mark.parametrize("step", [1, 2, 3])
def test_plane_band_matches_the_opencv_plane_distances(step: int) -> None:
    points, valid = _cloud(2)
    model = np.array([0.1, -0.7, 0.7, -0.4])
    model[:3] /= np.linalg.norm(model[:3])
    with np.errstate(invalid="ignore"):
        expected = valid & (np.abs(plane_distances(points, model)) < 0.3)
    found = plane_band(points, valid, step, model, np.float32(0.3))
    assert 0 < found.sum() < valid.sum()
    assert np.array_equal(found, expected[::step, ::step])


def test_centred_scatter_matches_the_gathered_points_scatter() -> None:
    points, _ = _cloud(3)
    coarse = points[::2, ::2].reshape(-1, 3)
    indices = np.flatnonzero(np.isfinite(coarse[:, 2]))[::3]
    picked = coarse[indices].astype(np.float64)
    centre, scatter = centred_scatter(points, 2, indices)
    centred = picked - picked.mean(axis=0)
    assert np.allclose(centre, picked.mean(axis=0), rtol=0, atol=1e-12)
    assert np.allclose(scatter, centred.T @ centred, rtol=1e-12, atol=1e-12)
