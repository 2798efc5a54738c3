"""The compiled surface grouping: separated colours become one group each, with exact order statistics."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.color_groups import DARK, GROUP_FIELDS, REGULAR, all_groups
from annotators.image.color_surfaces import DARK_GROUP, DEFAULT_PARAMETERS, group_settings


def _settings() -> np.ndarray:
    return group_settings(DEFAULT_PARAMETERS)


def _expected(rows: np.ndarray, percentile: float) -> np.ndarray:
    """L* at the percentile's rank, median chromaticity times (L* + 16), mean linear RGB, count (as Python
    rounds the ranks)."""
    count = rows.shape[1]
    lit = float(np.sort(rows[0])[round(percentile / 100.0 * (count - 1))])
    middle = round(0.5 * (count - 1))
    a, b = (float(np.sort(rows[i])[middle]) * (lit + 16.0) for i in (1, 2))
    return np.array([lit, a, b, *rows[3:].astype(np.float64).mean(axis=1), count])


@pytest.mark.parametrize("seed", range(5))
def test_two_separated_colours_are_two_groups_with_exact_statistics(seed: int) -> None:
    rng = np.random.default_rng(seed)
    sizes = (int(rng.integers(200, 700)), int(rng.integers(100, 400)), int(rng.integers(1, 50)))
    # features: two tight clusters far apart in the log-chroma plane; the last pixels are dark (not regular)
    centres = ((0.8, 0.1), (-0.6, -0.5), (0.0, 0.0))
    px = np.concatenate([rng.normal(c[0], 0.03, n) for c, n in zip(centres, sizes, strict=True)]).astype(np.float32)
    py = np.concatenate([rng.normal(c[1], 0.03, n) for c, n in zip(centres, sizes, strict=True)]).astype(np.float32)
    total = sum(sizes)
    rows = np.empty((6, total), dtype=np.float32)
    rows[0] = rng.uniform(40, 80, total)
    rows[1:3] = np.where(px > 0, 0.6, -0.5) * rng.uniform(0.8, 1.2, (2, total))  # clearly saturated
    rows[3:] = rng.uniform(0, 1, (3, total))
    cells = np.floor(np.stack([px, py]) / np.float32(DEFAULT_PARAMETERS.group_radius / 2)).astype(np.int64)
    dark = np.arange(total) >= sizes[0] + sizes[1]
    groups = all_groups(rows, px, py, cells, ~dark, dark, np.array([total]), _settings(), 5)
    assert groups.shape == (3, GROUP_FIELDS)
    assert list(groups[:, 1]) == [REGULAR, REGULAR, DARK]
    assert DARK == DARK_GROUP
    first, second = np.arange(sizes[0]), np.arange(sizes[0], sizes[0] + sizes[1])
    for row, members, percentile in ((0, first, 80.0), (1, second, 80.0), (2, np.flatnonzero(dark), 50.0)):
        np.testing.assert_allclose(groups[row, 2:], _expected(rows[:, members], percentile), rtol=1e-12)


def test_objects_are_grouped_apart_and_few_pixels_make_one_surface() -> None:
    rng = np.random.default_rng(0)
    sizes = (300, 2)
    total = sum(sizes)
    px, py = rng.normal(0.5, 0.02, total).astype(np.float32), rng.normal(0.5, 0.02, total).astype(np.float32)
    rows = np.vstack([rng.uniform(50, 60, total), np.full((2, total), 0.5), rng.uniform(0, 1, (3, total))])
    rows = rows.astype(np.float32)
    cells = np.floor(np.stack([px, py]) / np.float32(0.15)).astype(np.int64)
    regular = np.ones(total, dtype=bool)
    groups = all_groups(rows, px, py, cells, regular, ~regular, np.cumsum(sizes), _settings(), 5)
    assert list(groups[:, 0]) == [0, 1]
    assert list(groups[:, 8]) == [300, 2]
    np.testing.assert_allclose(groups[1, 2:], _expected(rows[:, 300:], 80.0), rtol=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_select_finds_every_rank_with_ties_and_sorted_runs(seed: int) -> None:
    from annotators.image.color_groups import _select

    rng = np.random.default_rng(seed)
    arrays = [
        rng.normal(0, 1, 257).astype(np.float32),
        rng.integers(0, 4, 100).astype(np.float32),  # many ties
        np.sort(rng.normal(0, 1, 64)).astype(np.float32),
        np.sort(rng.normal(0, 1, 64))[::-1].astype(np.float32).copy(),
        np.full(9, 2.5, dtype=np.float32),
        np.array([1.0], dtype=np.float32),
    ]
    for values in arrays:
        expected = np.sort(values)
        for rank in range(values.size):
            shuffled = values.copy()
            assert _select(shuffled, rank) == expected[rank]
            np.testing.assert_array_equal(np.sort(shuffled), expected)  # reordered, nothing lost
