"""The compiled per-pixel steps of surface grouping give what the NumPy expressions they replace give."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.color_pixels import pixel_features
from annotators.image.color_space import RELATIVE_XYZ32, UINT8_TO_LINEAR32, linear_to_lab
from annotators.image.color_surfaces import (
    DEFAULT_PARAMETERS,
    WHITE_LAB,
    NamingParameters,
    chroma_plane,
    pixel_settings,
    tints,
)


def _numpy_features(
    rgb: np.ndarray, edges: np.ndarray, sizes: np.ndarray, gains: np.ndarray, parameters: NamingParameters
) -> tuple[np.ndarray, ...]:
    """The steps in NumPy, array by array (as objects_surfaces took them before they were compiled)."""
    owner = np.repeat(np.arange(sizes.size), sizes)
    interior = edges <= parameters.edge_step
    interior_counts = np.bincount(owner[interior], minlength=sizes.size)
    keep = interior | (interior_counts < parameters.min_interior_share * sizes)[owner]
    rgb, owner = rgb[keep], owner[keep]
    counts = np.bincount(owner, minlength=sizes.size)
    linear = UINT8_TO_LINEAR32[rgb] * gains.astype(np.float32)
    lab = linear_to_lab(linear)
    brightest, darkest = rgb.max(axis=1), rgb.min(axis=1)
    highlight = (brightest >= parameters.clipped_level) & (darkest >= parameters.highlight_floor)
    highlight[highlight] = tints(lab[highlight], parameters) <= parameters.highlight_tint
    dark = ~highlight & (lab[:, 0] < parameters.dark_lightness)
    regular = ~highlight & ~dark
    white = np.bincount(owner[highlight], minlength=sizes.size) >= parameters.highlight_keep_share * counts
    whitened = highlight & white[owner]
    lab[whitened] = WHITE_LAB
    regular |= whitened
    features = chroma_plane(lab, parameters.chroma_softness)
    rows = np.vstack([lab[:, 0], (lab[:, 1:].T * (1.0 / (lab[:, 0] + 16.0))), linear.T])
    cells = np.floor(features.T / np.float32(parameters.group_radius / 2)).astype(np.int64)
    return rows, features[:, 0], features[:, 1], cells, regular, dark, highlight, counts


def _objects(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixels of a few objects: random colours, some clipped pale ones (one object mostly so), some near black,
    and edge strengths that leave out some pixels (and, on one object, too many to leave out)."""
    rng = np.random.default_rng(seed)
    sizes = np.array([400, 250, 120, 60], dtype=np.int64)
    rgb = rng.integers(0, 256, size=(int(sizes.sum()), 3)).astype(np.uint8)
    rgb[rng.random(rgb.shape[0]) < 0.15] = rng.integers(230, 256, size=3).astype(np.uint8)
    rgb[rng.random(rgb.shape[0]) < 0.1] //= 12
    rgb[400:600] = rng.integers(242, 256, size=(200, 3)).astype(np.uint8)  # an over-exposed white
    edges = rng.uniform(0.0, 40.0, rgb.shape[0]).astype(np.float32)
    edges[650:770] = 30.0  # every pixel of the third object on an edge: all are kept
    return rgb, edges, sizes


@pytest.mark.parametrize("seed", range(4))
def test_pixel_features_match_numpy(seed: int) -> None:
    rgb, edges, sizes = _objects(seed)
    gains = np.array([1.1, 0.95, 1.3])
    compiled = pixel_features(
        rgb,
        edges,
        sizes,
        UINT8_TO_LINEAR32,
        gains.astype(np.float32),
        RELATIVE_XYZ32,
        pixel_settings(DEFAULT_PARAMETERS),
    )
    expected = _numpy_features(rgb, edges, sizes, gains, DEFAULT_PARAMETERS)
    rows, px, py, cells, regular, dark, highlight, counts = compiled
    np.testing.assert_array_equal(counts, expected[7])
    assert counts[2] == sizes[2] and counts[0] < sizes[0]
    for got, want in zip((regular, dark, highlight), expected[4:7], strict=True):
        np.testing.assert_array_equal(got, want)
    assert highlight.any() and dark.any() and regular.any()
    np.testing.assert_allclose(rows, expected[0], rtol=1e-5, atol=1e-4)
    np.testing.assert_allclose(px, expected[1], rtol=1e-5, atol=1e-5)  # a* and b* are differences: absolute rounding
    np.testing.assert_allclose(py, expected[2], rtol=1e-5, atol=1e-5)  # a* and b* are differences: absolute rounding
    assert np.count_nonzero(cells != expected[3]) <= 2  # a cell differs only for a value on a cell border
    assert rows.dtype == np.float32 and cells.dtype == np.int64
