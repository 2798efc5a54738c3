"""The compiled search behind :func:`annotators.geometry.occlusion.join_occluded` (numba, machine code cached on
disk next to this file): every occluder's pieces behind it, found in one call instead of one Python round of
kernel calls per occluder and piece. Importing this module imports numba;
:mod:`~annotators.geometry.occlusion` imports it on first use."""

from __future__ import annotations

import numpy as np
from numba import njit

from annotators.geometry.grid_loops import grouped_pixels, jump_between, piece_near, shadowed_near, window_counts


@njit(cache=True, nogil=True)
def apart_from_another(labels: np.ndarray, touching: np.ndarray) -> np.ndarray:
    """The ``labels`` (in their order) that do not touch at least one of the others (``touching`` is the
    symmetric (count+1)x(count+1) bool matrix of labels that touch as 4-neighbours)."""
    kept = np.empty(labels.size, dtype=np.int64)
    found = 0
    for a in labels:
        for b in labels:
            if b != a and not touching[a, b]:
                kept[found] = a
                found += 1
                break
    return kept[:found]


@njit(cache=True, nogil=True)
def _finite_rows_into(values: np.ndarray, indices: np.ndarray, out: np.ndarray, start: int) -> int:
    """Copy the rows of Nx3 ``values`` at ``indices`` with all entries finite to ``out[start:]``; their number."""
    kept = 0
    for index in indices:
        if np.isfinite(values[index, 0]) and np.isfinite(values[index, 1]) and np.isfinite(values[index, 2]):
            out[start + kept] = values[index]
            kept += 1
    return kept


@njit(cache=True, nogil=True)
def pieces_behind(
    labels: np.ndarray,
    points: np.ndarray,
    flat_normals: np.ndarray,
    flat_plane: np.ndarray,
    mean_depth: np.ndarray,
    sizes: np.ndarray,
    boxes: np.ndarray,
    touching: np.ndarray,
    band: int,
    min_points: int,
    absolute: float,
    relative: float,
) -> tuple[np.ndarray, ...]:
    """See :func:`annotators.geometry.occlusion.pieces_behind`."""
    rows, cols = labels.shape
    count = sizes.size - 1
    margin, reach = 3 * band + 1, 3 * band
    depth = points[:, :, 2]
    unmeasured = ~np.isfinite(depth)
    owners = []
    pieces = []
    centres = []
    pixels = []
    bands = []
    xyzs = []
    normals = []
    sections = []
    for occluder in range(1, count + 1):
        # what an occluder hides lies farther than it as a whole: at least two such objects or nothing to join
        farther = np.flatnonzero(mean_depth > mean_depth[occluder])
        if sizes[occluder] < min_points or farther.size < 2:
            continue
        x0, y0 = max(boxes[occluder, 0] - margin, 0), max(boxes[occluder, 1] - margin, 0)
        x1, y1 = min(boxes[occluder, 2] + margin, cols), min(boxes[occluder, 3] + margin, rows)
        window = labels[y0:y1, x0:x1]
        # a piece's band near the occluder lies in the window: only pieces with enough pixels there can join
        in_window = window_counts(window, count)
        possible = farther[in_window[farther] >= min_points]
        if possible.size < 2 or apart_from_another(possible, touching).size < 2:
            continue  # fewer than two farther objects near this one, or they all touch one another
        occluding = window == occluder
        near = shadowed_near(occluding, unmeasured[y0:y1, x0:x1], reach, band)
        # the farther objects with enough pixels near the occluder; two of them must be apart to join anything
        near_pixels, near_starts = grouped_pixels(window, near, count)
        band_sizes = near_starts[1:] - near_starts[:-1]
        candidates = apart_from_another(farther[band_sizes[farther] >= min_points], touching)
        if candidates.size < 2:
            continue
        window_depth = depth[y0:y1, x0:x1]
        for piece in candidates:
            own = near_pixels[near_starts[piece] : near_starts[piece + 1]]
            facing, piece_depth, occluder_depth, flat, xyz, centre, pixel = piece_near(
                own, (x1 - x0, y0, x0), occluding, window_depth, reach, points
            )
            if facing < min_points:
                continue  # too few of the occluder's pixels within reach of the band
            if not jump_between(piece_depth, occluder_depth, absolute, relative):
                continue
            if piece_depth <= occluder_depth or xyz.shape[0] < min_points:
                continue
            band_normals = np.empty((flat.size, 3), dtype=flat_normals.dtype)
            section = np.empty((flat.size, 3), dtype=flat_plane.dtype)
            band_normals = band_normals[: _finite_rows_into(flat_normals, flat, band_normals, 0)]
            section = section[: _finite_rows_into(flat_plane, flat, section, 0)]
            owners.append(occluder)
            pieces.append(piece)
            centres.append(centre)
            pixels.append(pixel)
            bands.append(flat)
            xyzs.append(xyz)
            normals.append(band_normals)
            sections.append(section)
    found = len(owners)
    starts = np.zeros((4, found + 1), dtype=np.int64)
    for k in range(found):
        starts[0, k + 1] = starts[0, k] + bands[k].size
        starts[1, k + 1] = starts[1, k] + xyzs[k].shape[0]
        starts[2, k + 1] = starts[2, k] + normals[k].shape[0]
        starts[3, k + 1] = starts[3, k] + sections[k].shape[0]
    all_bands = np.empty(starts[0, found], dtype=np.int64)
    all_xyz = np.empty((starts[1, found], 3), dtype=points.dtype)
    all_normals = np.empty((starts[2, found], 3), dtype=flat_normals.dtype)
    all_sections = np.empty((starts[3, found], 3), dtype=flat_plane.dtype)
    all_centres = np.empty((found, 3))
    all_pixels = np.empty((found, 2))
    for k in range(found):
        all_bands[starts[0, k] : starts[0, k + 1]] = bands[k]
        all_xyz[starts[1, k] : starts[1, k + 1]] = xyzs[k]
        all_normals[starts[2, k] : starts[2, k + 1]] = normals[k]
        all_sections[starts[3, k] : starts[3, k + 1]] = sections[k]
        all_centres[k] = centres[k]
        all_pixels[k] = pixels[k]
    ids = np.empty((found, 2), dtype=np.int64)
    for k in range(found):
        ids[k, 0], ids[k, 1] = owners[k], pieces[k]
    return ids, starts, all_bands, all_xyz, all_normals, all_sections, all_centres, all_pixels
