"""Picking an object's pixels from its mask, and their edge strengths, in compiled passes.

:func:`mask_pixels` picks the pixels of a mask in its box: its inner pixels (those whose 3x3 neighbourhood in the
box is all in the mask, as ``cv2.erode`` with a 3x3 kernel keeps them) when there are enough of them, else all,
then every ``step``-th of them in raster order. A pixel's edge strength (:func:`box_pixels_and_edges`) is the
largest, over the three channels, 3x3 Sobel gradient magnitude of the box cut out of the image (``cv2.Sobel`` of
the box, mirrored at the box's border as OpenCV's BORDER_REFLECT_101 does), in sRGB levels per pixel (the
magnitude / 8): exactly what :func:`~annotators.image.color_surfaces.edge_strength` gives for the box, computed at
the chosen pixels only. Compiled by numba (machine code cached on disk next to this file); import this module
where it is needed, not at start-up.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _mirrored(index: int, low: int, high: int) -> int:
    """``index`` (at most one step outside ``low..high-1``) mirrored back inside about the end pixel."""
    if index < low:
        return min(low + 1, high - 1)
    if index >= high:
        return max(high - 2, low)
    return index


@njit(cache=True, nogil=True)
def box_pixels_and_edges(
    image: np.ndarray, rows: np.ndarray, cols: np.ndarray, boxes: np.ndarray, box_of: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The RGB values (Nx3 uint8) and edge strengths (N, float32) of the pixels (``rows``, ``cols``) of an RGB
    image (HxWx3 uint8), each in box ``boxes[box_of[k]]`` (y0, y1, x0, x1 rows; the pixel inside it)."""
    count = rows.size
    pixels = np.empty((count, 3), dtype=np.uint8)
    edges = np.empty(count, dtype=np.float32)
    for k in range(count):
        row, col = rows[k], cols[k]
        y0, y1, x0, x1 = boxes[box_of[k], 0], boxes[box_of[k], 1], boxes[box_of[k], 2], boxes[box_of[k], 3]
        up, down = _mirrored(row - 1, y0, y1), _mirrored(row + 1, y0, y1)
        left, right = _mirrored(col - 1, x0, x1), _mirrored(col + 1, x0, x1)
        strongest = 0
        for channel in range(3):
            ul, uc, ur = (
                np.int32(image[up, left, channel]),
                np.int32(image[up, col, channel]),
                np.int32(image[up, right, channel]),
            )
            ml, mr = np.int32(image[row, left, channel]), np.int32(image[row, right, channel])
            dl, dc, dr = (
                np.int32(image[down, left, channel]),
                np.int32(image[down, col, channel]),
                np.int32(image[down, right, channel]),
            )
            gx = (ur + 2 * mr + dr) - (ul + 2 * ml + dl)
            gy = (dl + 2 * dc + dr) - (ul + 2 * uc + ur)
            strongest = max(strongest, gx * gx + gy * gy)
            pixels[k, channel] = image[row, col, channel]
        edges[k] = np.sqrt(np.float32(strongest)) / np.float32(8.0)
    return pixels, edges


@njit(cache=True, nogil=True)
def mask_pixels(
    mask: np.ndarray, y0: int, y1: int, x0: int, x1: int, max_pixels: int, min_inner: int
) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns (frame coordinates) of the pixels picked from ``mask`` (HxW bool) in its box: the inner
    pixels when there are at least ``min_inner`` of them and a third of the mask's, else all the mask's pixels;
    of those, every ``max(1, count // max_pixels)``-th in raster order."""
    height, width = y1 - y0, x1 - x0
    # runs[r, c]: the mask's pixels c-1, c, c+1 of box row r are all set (those outside the box count as set)
    runs = np.empty((height, width), dtype=np.bool_)
    for r in range(height):
        row = mask[y0 + r, x0:x1]
        for c in range(width):
            runs[r, c] = row[c] and (c == 0 or row[c - 1]) and (c == width - 1 or row[c + 1])
    total = inner = 0
    for r in range(height):
        row, above, here, below = mask[y0 + r, x0:x1], runs[max(r - 1, 0)], runs[r], runs[min(r + 1, height - 1)]
        for c in range(width):
            total += row[c]
            inner += here[c] & above[c] & below[c]  # a set run implies the pixel is set
    use_inner = inner >= max(min_inner, total // 3)
    count = inner if use_inner else total
    step = max(1, count // max_pixels)
    picked = (count + step - 1) // step
    rows = np.empty(picked, dtype=np.int64)
    cols = np.empty(picked, dtype=np.int64)
    taken = 0
    wait = 0  # picked pixels to pass over before the next is taken
    for r in range(height):
        row, above, here, below = mask[y0 + r, x0:x1], runs[max(r - 1, 0)], runs[r], runs[min(r + 1, height - 1)]
        for c in range(width):
            if here[c] & above[c] & below[c] if use_inner else row[c]:
                if wait == 0:
                    rows[taken], cols[taken] = y0 + r, x0 + c
                    taken += 1
                    wait = step
                wait -= 1
    return rows, cols
