"""The per-pixel steps of surface grouping for all the objects of a frame, in compiled passes.

For the picked pixels of each object (:func:`~annotators.image.color_surfaces.objects_pixels`), the steps
:func:`~annotators.image.color_surfaces.objects_surfaces` takes before grouping (:func:`pixel_features`): edge
pixels are left out when enough others remain; each pixel is white-balanced into linear RGB and CIELAB; clipped
pale pixels are highlights (and an object that is mostly highlight is an over-exposed white: its highlights become
white and count as regular pixels), near-black ones the dark pool; every pixel gets its row (L*, a*/(L*+16),
b*/(L*+16), linear R, G, B), its place in the log-chroma plane and its histogram cell there.

The same single-precision operations as the NumPy expressions they replace
(:func:`~annotators.image.color_space.linear_to_lab`, :func:`~annotators.image.color_surfaces.tints`,
:func:`~annotators.image.color_surfaces.chroma_plane`), without their temporaries; the cube and log roots are left
to NumPy between the passes (its vectorised loops are many times faster than scalar calls). The results agree to
rounding (a few units in the last place of single precision).

Compiled by numba (machine code cached on disk next to this file); import this module where it is needed, not at
start-up.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_EPSILON = np.float32(216 / 24389)
_KAPPA = np.float32(24389 / 27)
_F16, _F116, _F500, _F200 = np.float32(16.0), np.float32(116.0), np.float32(500.0), np.float32(200.0)


@njit(cache=True, nogil=True)
def _kept_xyz(
    rgb: np.ndarray,
    edges: np.ndarray,
    sizes: np.ndarray,
    linear_of_level: np.ndarray,
    gains: np.ndarray,
    to_xyz: np.ndarray,
    settings: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each object's kept pixels (interior ones, or all when too few are interior): their linear RGB (3xM) and
    white-relative XYZ (Mx3), whether they are clipped and pale (M), and each object's count."""
    edge_step, min_interior = np.float32(settings[0]), settings[1]
    clipped, floor_level = settings[2], settings[3]
    keep = np.empty(rgb.shape[0], dtype=np.bool_)
    counts = np.zeros(sizes.size, dtype=np.int64)
    start = 0
    for obj in range(sizes.size):
        end = start + sizes[obj]
        interior = 0
        for i in range(start, end):
            keep[i] = edges[i] <= edge_step
            interior += keep[i]
        if interior < min_interior * sizes[obj]:
            keep[start:end] = True
            interior = end - start
        counts[obj] = interior
        start = end
    kept = int(counts.sum())
    linear = np.empty((3, kept), dtype=np.float32)
    xyz = np.empty((kept, 3), dtype=np.float32)
    pale = np.empty(kept, dtype=np.bool_)
    at = 0
    for i in range(rgb.shape[0]):
        if not keep[i]:
            continue
        red, green, blue = rgb[i, 0], rgb[i, 1], rgb[i, 2]
        r = linear_of_level[red] * gains[0]
        g = linear_of_level[green] * gains[1]
        b = linear_of_level[blue] * gains[2]
        linear[0, at], linear[1, at], linear[2, at] = r, g, b
        for k in range(3):
            xyz[at, k] = r * to_xyz[0, k] + g * to_xyz[1, k] + b * to_xyz[2, k]
        pale[at] = max(red, green, blue) >= clipped and min(red, green, blue) >= floor_level
        at += 1
    return linear, xyz, pale, counts


@njit(cache=True, nogil=True)
def _classes(
    xyz: np.ndarray, roots: np.ndarray, pale: np.ndarray, counts: np.ndarray, settings: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """CIELAB (3xM) from the XYZ values and their cube ``roots``, the over-exposed whites' highlights made white;
    the pixels' chroma and which are highlight, dark and regular."""
    highlight_tint, white_share, dark_lightness = np.float32(settings[4]), settings[5], np.float32(settings[6])
    radius_a_max, radius_b_max = np.float32(settings[9]), np.float32(settings[10])
    ratio_a, ratio_b = np.float32(settings[11]), np.float32(1.5 * settings[11])
    kept = xyz.shape[0]
    lab = np.empty((3, kept), dtype=np.float32)
    chroma = np.empty(kept, dtype=np.float32)
    highlight = np.empty(kept, dtype=np.bool_)
    dark = np.empty(kept, dtype=np.bool_)
    regular = np.empty(kept, dtype=np.bool_)
    start = 0
    for obj in range(counts.size):
        end = start + counts[obj]
        highlights = 0
        for i in range(start, end):
            fx, fy, fz = roots[i, 0], roots[i, 1], roots[i, 2]
            if xyz[i, 0] <= _EPSILON:
                fx = (_KAPPA * xyz[i, 0] + _F16) / _F116
            if xyz[i, 1] <= _EPSILON:
                fy = (_KAPPA * xyz[i, 1] + _F16) / _F116
            if xyz[i, 2] <= _EPSILON:
                fz = (_KAPPA * xyz[i, 2] + _F16) / _F116
            lightness, a, b = _F116 * fy - _F16, _F500 * (fx - fy), _F200 * (fy - fz)
            lab[0, i], lab[1, i], lab[2, i] = lightness, a, b
            lit = pale[i]
            if lit:
                scale = lightness + _F16
                radius_a = min(radius_a_max, ratio_a * scale)
                radius_b = min(radius_b_max, ratio_b * scale)
                lit = _hypot(a / radius_a, b / radius_b) <= highlight_tint
            highlight[i] = lit
            highlights += lit
            dark[i] = not lit and lightness < dark_lightness
            regular[i] = not lit and not dark[i]
        whitened = highlights >= white_share * counts[obj]  # an over-exposed white: its highlights are white
        for i in range(start, end):
            if whitened and highlight[i]:
                lab[0, i], lab[1, i], lab[2, i] = 100.0, 0.0, 0.0
                regular[i] = True
            chroma[i] = _hypot(lab[1, i], lab[2, i])
        start = end
    return lab, chroma, highlight, dark, regular


@njit(cache=True, nogil=True)
def _hypot(x: np.float32, y: np.float32) -> np.float32:
    """``hypot`` in single precision, rounded once from double."""
    return np.float32(np.sqrt(np.float64(x) * np.float64(x) + np.float64(y) * np.float64(y)))


@njit(cache=True, nogil=True)
def _rows_and_features(
    lab: np.ndarray, linear: np.ndarray, chroma: np.ndarray, logs: np.ndarray, cell: np.float32
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pixels' rows (6xM), log-chroma x and y (``logs``: log(1 + C*/softness)) and histogram cells (2xM)."""
    kept = lab.shape[1]
    rows = np.empty((6, kept), dtype=np.float32)
    px, py = np.empty(kept, dtype=np.float32), np.empty(kept, dtype=np.float32)
    cells = np.empty((2, kept), dtype=np.int64)
    for i in range(kept):
        lightness, a, b = lab[0, i], lab[1, i], lab[2, i]
        scale = logs[i] / max(chroma[i], np.float32(1e-9))
        px[i], py[i] = a * scale, b * scale
        cells[0, i], cells[1, i] = np.floor(px[i] / cell), np.floor(py[i] / cell)
        inverse = np.float32(1.0) / (lightness + _F16)
        rows[0, i], rows[1, i], rows[2, i] = lightness, a * inverse, b * inverse
        rows[3, i], rows[4, i], rows[5, i] = linear[0, i], linear[1, i], linear[2, i]
    return rows, px, py, cells


def pixel_features(
    rgb: np.ndarray,
    edges: np.ndarray,
    sizes: np.ndarray,
    linear_of_level: np.ndarray,
    gains: np.ndarray,
    to_xyz: np.ndarray,
    settings: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kept pixels of objects whose picked pixels (``rgb``, Nx3 uint8, and their ``edges``, N float32)
    come in runs of ``sizes``: their rows (6xM float32), log-chroma x and y (M each), histogram cells (2xM
    int64), which are regular, dark and highlight (M bools each), and each object's kept count.

    ``linear_of_level``: the linear value of each sRGB level (256, float32); ``gains``: the white-balance gains
    (3, float32); ``to_xyz``: linear RGB rows to white-relative XYZ (3x3 float32); ``settings``
    (:func:`~annotators.image.color_surfaces.pixel_settings`): the edge step, the smallest interior share, the
    clipped level, the highlight floor, the highlight tint, the highlight share that makes an object white, the
    dark lightness, the chroma softness, the group radius, the achromatic a* and b* radii and the dark tint
    ratio."""
    linear, xyz, pale, counts = _kept_xyz(rgb, edges, sizes, linear_of_level, gains, to_xyz, settings)
    lab, chroma, highlight, dark, regular = _classes(xyz, np.cbrt(xyz), pale, counts, settings)
    logs = np.log1p(chroma / np.float32(settings[7]))
    rows, px, py, cells = _rows_and_features(lab, linear, chroma, logs, np.float32(settings[8] / 2))
    return rows, px, py, cells, regular, dark, highlight, counts
