"""The compiled loops of the form expert give what the NumPy expressions they replace give: the grazing pixels and
the body profile's band system and surface offsets bit for bit, the lines of sight and the top's outline test to
rounding (their dot products are not fused as BLAS may fuse them)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from annotators.cloud import body_profile_loops, form_loops
from annotators.geometry.grazing import GRAZING_RATIO, grazing_pixels


def _grazing_numpy(points: np.ndarray, pixels: np.ndarray, ratio: float) -> np.ndarray:
    """The whole-array NumPy form of :func:`grazing_pixels`."""
    height, width = points.shape[:2]
    rows, cols = np.divmod(np.asarray(pixels, dtype=np.int64), width)
    here = points[rows, cols].astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        sight = here / np.linalg.norm(here, axis=1, keepdims=True)
    grazing = np.zeros(rows.size, dtype=bool)
    for step_row, step_col in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        other = points[np.clip(rows + step_row, 0, height - 1), np.clip(cols + step_col, 0, width - 1)]
        step = other.astype(np.float64) - here
        along = (step * sight).sum(axis=1)
        across = np.linalg.norm(step - along[:, None] * sight, axis=1)
        with np.errstate(invalid="ignore"):
            grazing |= np.abs(along) > ratio * np.maximum(across, 1e-9)
    return grazing


def _grid(seed: int, shape: tuple[int, int] = (30, 40)) -> np.ndarray:
    """An HxWx3 float32 camera-frame grid: a bumpy surface with depth jumps, NaN holes and a zero point."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float64)
    depth = 0.8 + 0.002 * rng.standard_normal(shape) + 0.3 * (rng.random(shape) < 0.1)
    points = np.stack([(u - shape[1] / 2) / 500 * depth, (v - shape[0] / 2) / 500 * depth, depth], axis=-1)
    points[rng.random(shape) < 0.05] = np.nan
    points[0, 0] = 0.0
    return points.astype(np.float32)


@pytest.mark.parametrize("seed", range(4))
def test_grazing_pixels_are_the_numpy_ones(seed: int) -> None:
    points = _grid(seed)
    pixels = np.random.default_rng(seed).permutation(points.shape[0] * points.shape[1])[:700]
    expected = _grazing_numpy(points, pixels, GRAZING_RATIO)
    assert expected.any() and not expected.all()
    assert np.array_equal(grazing_pixels(points, pixels), expected)


@pytest.mark.parametrize("seed", range(4))
def test_the_band_system_and_surface_offsets_are_the_numpy_ones(seed: int) -> None:
    rng = np.random.default_rng(seed)
    bands = 6
    xy = rng.normal(0.0, 0.05, (500, 2)) + np.array([0.1, 0.7])
    band = rng.choice([0, 1, 2, 4, 5], 500)  # band 3 empty
    keep = rng.random(500) < 0.8
    squares = (xy**2).sum(axis=1)
    counts, means, matrix, rhs = body_profile_loops.band_system(xy, squares, band, keep, bands)
    expected_counts = np.bincount(band[keep], minlength=bands).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        expected_means = np.stack(
            [np.bincount(band[keep], v, minlength=bands) / expected_counts for v in (*xy[keep].T, squares[keep])],
            axis=1,
        )
    assert np.array_equal(counts, expected_counts)
    assert np.array_equal(means, expected_means, equal_nan=True) and np.isnan(means[3]).all()
    assert np.array_equal(matrix, 2.0 * (xy[keep] - expected_means[band[keep], :2]))
    assert np.array_equal(rhs, squares[keep] - expected_means[band[keep], 2])
    centre = np.array([0.1, 0.7])
    radii = np.where(np.arange(bands) == 3, np.nan, rng.uniform(0.02, 0.05, bands))
    expected_off = np.abs(np.linalg.norm(xy - centre, axis=1) - np.where(np.isfinite(radii[band]), radii[band], np.inf))
    assert np.array_equal(body_profile_loops.surface_offsets(xy, band, centre, radii), expected_off)


@pytest.mark.parametrize("seed", range(4))
def test_lines_of_sight_and_the_outline_test_are_the_numpy_ones_to_rounding(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, 0.04, (800, 3)) + np.array([0.0, 0.8, 0.1])
    tested = points[::4]
    camera = np.array([0.0, 0.0, 0.5])
    sight = camera - tested
    sight /= np.linalg.norm(sight, axis=1, keepdims=True)
    equations = ConvexHull(points).equations
    inside = -(tested @ equations[:, :3].T + equations[:, 3])
    toward = sight @ equations[:, :3].T
    with np.errstate(divide="ignore", invalid="ignore"):
        expected = np.maximum(np.where(toward > 1e-12, inside / toward, np.inf).min(axis=1), 0.0)
    runs = form_loops.sight_runs(np.ascontiguousarray(tested), sight, equations)
    assert (expected > 0.0).any() and (expected == 0.0).any()
    np.testing.assert_allclose(runs, expected, rtol=1e-12, atol=1e-15)

    outline = ConvexHull(points[:, :2]).equations
    probes = rng.normal(0.0, 0.06, (400, 2)) + np.array([0.0, 0.8])
    distance = (probes @ outline[:, :2].T + outline[:, 2]).max(axis=1)
    clear = np.abs(distance - 0.01) > 1e-12  # not on the margin, where rounding may decide
    within = form_loops.within_outline(probes, outline, 0.01)
    assert within[clear].any() and not within[clear].all()
    assert np.array_equal(within[clear], (distance <= 0.01)[clear])
    probes[0] = np.nan
    assert not form_loops.within_outline(probes, outline, 0.01)[0]
