"""The compiled pixel picking and edge strengths give what OpenCV's erosion and Sobel filter give on the box."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from annotators.image.color_surfaces import edge_strength
from annotators.image.pixel_picking import box_pixels_and_edges, mask_pixels


def _reference_pick(mask: np.ndarray, box: tuple[int, int, int, int], max_pixels: int) -> tuple[np.ndarray, ...]:
    """The pixels as the annotator picked them with OpenCV: eroded mask when enough remain, then a stride."""
    y0, y1, x0, x1 = box
    local = mask[y0:y1, x0:x1]
    inner = cv2.erode(local.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)
    if np.count_nonzero(inner) >= max(20, np.count_nonzero(local) // 3):
        local = inner
    rows, cols = np.nonzero(local)
    step = max(1, rows.size // max_pixels)
    return rows[::step] + y0, cols[::step] + x0


def _random_blob_mask(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """A mask of a few random ellipses and speckle, so it has an interior, a ragged outline and holes."""
    canvas = np.zeros(shape, dtype=np.uint8)
    for _ in range(rng.integers(1, 4)):
        centre = (int(rng.integers(0, shape[1])), int(rng.integers(0, shape[0])))
        axes = (int(rng.integers(1, shape[1] // 2 + 2)), int(rng.integers(1, shape[0] // 2 + 2)))
        cv2.ellipse(canvas, centre, axes, float(rng.uniform(0, 180)), 0, 360, 1, -1)
    speckle = rng.random(shape) < 0.05
    return (canvas.astype(bool) ^ speckle).copy()


def _box_of(mask: np.ndarray) -> tuple[int, int, int, int]:
    ys, xs = np.nonzero(mask)
    return int(ys.min()), int(ys.max()) + 1, int(xs.min()), int(xs.max()) + 1


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("max_pixels", [7, 300, 100000])
def test_mask_pixels_match_erosion_and_stride(seed: int, max_pixels: int) -> None:
    rng = np.random.default_rng(seed)
    mask = _random_blob_mask(rng, (int(rng.integers(1, 60)), int(rng.integers(1, 80))))
    if not mask.any():
        mask[0, 0] = True
    box = _box_of(mask)
    rows, cols = mask_pixels(mask, *box, max_pixels, 20)
    expected_rows, expected_cols = _reference_pick(mask, box, max_pixels)
    assert np.array_equal(rows, expected_rows)
    assert np.array_equal(cols, expected_cols)


@pytest.mark.parametrize("seed", range(8))
def test_box_edges_match_the_sobel_filter_of_each_box(seed: int) -> None:
    rng = np.random.default_rng(seed)
    height, width = 40, 50
    image = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    image[:, : width // 2] = image[:, : width // 2] // 8  # a strong vertical edge as well as noise
    boxes = []
    for _ in range(3):
        y0, x0 = int(rng.integers(0, height - 1)), int(rng.integers(0, width - 1))
        boxes.append((y0, int(rng.integers(y0 + 1, height + 1)), x0, int(rng.integers(x0 + 1, width + 1))))
    rows, cols, owners = [], [], []
    for index, (y0, y1, x0, x1) in enumerate(boxes):
        ys, xs = np.mgrid[y0:y1, x0:x1]
        rows.append(ys.ravel())
        cols.append(xs.ravel())
        owners.append(np.full(ys.size, index))
    pixels, edges = box_pixels_and_edges(
        image, np.concatenate(rows), np.concatenate(cols), np.array(boxes, dtype=np.int64), np.concatenate(owners)
    )
    start = 0
    for y0, y1, x0, x1 in boxes:
        crop = image[y0:y1, x0:x1]
        end = start + crop.shape[0] * crop.shape[1]
        assert np.array_equal(pixels[start:end], crop.reshape(-1, 3))
        assert np.array_equal(edges[start:end], edge_strength(crop).ravel())
        start = end
