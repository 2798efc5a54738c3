"""Oriented bounding boxes of point sets, robust to tiny, flat and degenerate sets (they never raise).

Two fits: :func:`upright_box` when the up direction is known (the box stands on the floor: z is up and the yaw
comes from the minimum-area rectangle of the footprint), and :func:`principal_box` otherwise (axes from the
principal components of the points).

:func:`object_boxes_of_indexed` and :func:`object_boxes_of_sets` fit many objects at once (the pose annotator's
path): the gathering, stray removal, moments and extents run as compiled loops over all the sets
(:mod:`annotators.geometry.box_loops`, loaded on first use) with the arithmetic of the NumPy reductions they
replace; the boxes agree with :func:`object_box` of each set to rounding (its sums are added in another order).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from types import ModuleType

import cv2
import numpy as np


@dataclass(frozen=True, eq=False)
class OrientedBox:
    """A box: centre (3,), rotation (3x3, columns are the box axes) and extents (3,) along those axes."""

    centre: np.ndarray
    rotation: np.ndarray
    extents: np.ndarray

    def transformed(self, transform: np.ndarray) -> OrientedBox:
        """The same box expressed through a 4x4 rigid transform."""
        rotation = transform[:3, :3] @ self.rotation
        return OrientedBox(transform[:3, :3] @ self.centre + transform[:3, 3], rotation, self.extents.copy())


def finite_points(points: np.ndarray) -> np.ndarray:
    """The rows of an Nx3 array that are finite, as float64."""
    points = np.asarray(points).reshape(-1, 3)
    finite = np.isfinite(points)
    return points[finite[:, 0] & finite[:, 1] & finite[:, 2]].astype(np.float64)


STRAY_FENCE = 3.0
"""Tukey's far-out fence: a point farther from the median point than Q3 + 3 IQR of all such distances is a stray."""


def _finite_rows(points: np.ndarray) -> np.ndarray:
    """The finite rows of an Nx3 array as a 3xN float64 array (each coordinate contiguous)."""
    points = np.asarray(points).reshape(-1, 3)
    finite = np.isfinite(points)
    return np.array(points[finite[:, 0] & finite[:, 1] & finite[:, 2]].T, dtype=np.float64, order="C")


def _quartiles(values: np.ndarray) -> tuple[float, float]:
    """The first and third quartiles of N >= 2 values, as ``np.percentile(values, [25, 75])`` computes them
    (linear interpolation between order statistics)."""
    positions = [(values.size - 1) * 0.25, (values.size - 1) * 0.75]
    below = [math.floor(position) for position in positions]
    ranked = values.copy()
    ranked.partition(sorted({*below, *(rank + 1 for rank in below)}))
    quartiles = []
    for position, rank in zip(positions, below, strict=True):
        low, high = float(ranked[rank]), float(ranked[rank + 1])
        weight = position - rank
        step = high - low
        quartiles.append(high - step * (1.0 - weight) if weight >= 0.5 else low + step * weight)
    return quartiles[0], quartiles[1]


def _compact(rows: np.ndarray) -> np.ndarray:
    """:func:`compact_points` of finite points given as 3xN float64 rows (returned the same way)."""
    count = rows.shape[1]
    if count < 8:
        return rows
    low, high = (count - 1) // 2, count // 2
    ranked = rows.copy()
    ranked.partition([low, high] if low != high else low, axis=1)
    offsets = rows - ((ranked[:, low] + ranked[:, high]) / 2.0)[:, None]  # from the median point
    offsets *= offsets
    distances = np.sqrt(offsets[0] + offsets[1] + offsets[2])
    q1, q3 = _quartiles(distances)
    return rows.compress(distances <= q3 + STRAY_FENCE * (q3 - q1), axis=1)


def compact_points(points: np.ndarray) -> np.ndarray:
    """The finite points of an object's compact body, without strays.

    A segment of a real depth image carries a few points that do not belong to the object's surface: flying pixels
    at depth edges (between the object and the background behind it) and specks of background. They are few but
    far away, so they would stretch a box by tens of centimetres. A point is a stray when its distance to the median
    point is beyond Tukey's far-out fence of those distances; an elongated or hollow object keeps all its points,
    since its distances spread evenly and the fence lies beyond its far end.
    """
    return np.ascontiguousarray(_compact(_finite_rows(points)).T)


def _degenerate_box(points: np.ndarray) -> OrientedBox:
    centre = points.mean(axis=0) if points.shape[0] else np.zeros(3)
    extents = np.ptp(points, axis=0) if points.shape[0] else np.zeros(3)
    return OrientedBox(centre, np.eye(3), extents)


def upright_box(points: np.ndarray) -> OrientedBox:
    """The box with a vertical (+z) axis around Nx3 points given in a z-up frame; yaw from the footprint."""
    return _upright(finite_points(points))


def _upright(points: np.ndarray) -> OrientedBox:
    """:func:`upright_box` of finite Nx3 float64 points."""
    if points.shape[0] < 3:
        return _degenerate_box(points)
    (cx, cy), (width, depth), angle = cv2.minAreaRect(points[:, :2].astype(np.float32))
    yaw = np.radians(angle)
    cos, sin = np.cos(yaw), np.sin(yaw)
    rotation = np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]])
    low, high = points[:, 2].min(), points[:, 2].max()
    centre = np.array([cx, cy, (low + high) / 2])
    return OrientedBox(centre, rotation, np.array([width, depth, high - low], dtype=np.float64))


def _determinant(matrix: np.ndarray) -> float:
    """The determinant of a 3x3 matrix (the scalar triple product of its rows)."""
    (a, b, c), (d, e, f), (g, h, i) = matrix.tolist()
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


def _principal(rows: np.ndarray) -> OrientedBox:
    """:func:`principal_box` of finite points given as 3xN float64 rows."""
    if rows.shape[1] < 3:
        return _degenerate_box(rows.T)
    mean = rows.mean(axis=1)
    centred = rows - mean[:, None]
    _, vectors = np.linalg.eigh(centred @ centred.T)
    rotation = vectors[:, ::-1].copy()  # largest spread first
    if _determinant(rotation) < 0:
        rotation[:, 2] *= -1
    local = rotation.T @ centred
    low, high = local.min(axis=1), local.max(axis=1)
    centre = mean + rotation @ ((low + high) / 2)
    return OrientedBox(centre, rotation, high - low)


def principal_box(points: np.ndarray) -> OrientedBox:
    """The box aligned with the principal axes of Nx3 points (a right-handed rotation)."""
    return _principal(_finite_rows(points))


def object_box(points_camera: np.ndarray, cam_to_world: np.ndarray | None) -> tuple[OrientedBox, str]:
    """The box of an object's camera-frame points (strays dropped) and its frame: upright in "world" when the
    camera pose is known."""
    rows = _compact(_finite_rows(points_camera))
    if cam_to_world is not None:
        transform = np.asarray(cam_to_world, dtype=np.float64)
        world = rows.T @ transform[:3, :3].T + transform[:3, 3]
        return upright_box(world), "world"
    return _principal(rows), "camera"


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.box_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import box_loops

    return box_loops


def _principal_boxes(rows: np.ndarray, sizes: np.ndarray) -> list[OrientedBox]:
    """:func:`principal_box` of several sets of finite points stored one after another as 3xN float64 rows (each
    set's size in ``sizes``, every set non-empty), at once: the means and covariances of all the sets in one
    compiled pass, their eigen-decompositions in one LAPACK call, then each set's extents along its axes in
    another compiled pass."""
    loops = _loops()
    starts = np.cumsum(sizes) - sizes
    fitted = sizes >= 3
    boxes: list[OrientedBox | None] = [
        None if fit else _degenerate_box(rows[:, start : start + size].T)
        for fit, start, size in zip(fitted.tolist(), starts.tolist(), sizes.tolist(), strict=True)
    ]
    if not fitted.any():
        return [box for box in boxes if box is not None]
    if not fitted.all():
        chosen = zip(starts[fitted].tolist(), sizes[fitted].tolist(), strict=True)
        rows = np.concatenate([rows[:, start : start + size] for start, size in chosen], axis=1)
        sizes = sizes[fitted]
    mean, products = loops.set_moments(rows, sizes)  # 3 x sets, 6 x sets
    covariance = products[[0, 1, 2, 1, 3, 4, 2, 4, 5]].T.reshape(-1, 3, 3)
    _, vectors = np.linalg.eigh(covariance)
    rotation = vectors[:, :, ::-1].copy()  # largest spread first
    rotation[np.linalg.det(rotation) < 0, :, 2] *= -1
    low, high = loops.set_extents(rows, sizes, mean, rotation)  # the sets in their boxes' axes
    centres = mean.T + np.einsum("sij,sj->si", rotation, (low + high) / 2)
    extents = high - low
    boxes_fitted = iter(OrientedBox(c, r, e) for c, r, e in zip(centres, rotation, extents, strict=True))
    return [box if box is not None else next(boxes_fitted) for box in boxes]


def box_orientations(boxes: list[OrientedBox]) -> np.ndarray:
    """The unit quaternions (Kx4: x, y, z, w) of the boxes' rotations, each what
    :func:`robokudo.core.geometry.quaternion_from_matrix` gives, converted at once."""
    if not boxes:
        return np.zeros((0, 4))
    return _loops().rotation_quaternions(np.stack([box.rotation for box in boxes]).astype(np.float64, copy=False))


def object_boxes_of_indexed(
    points: np.ndarray, indices: np.ndarray, sizes: np.ndarray, cam_to_world: np.ndarray | None
) -> tuple[list[tuple[OrientedBox, str]], np.ndarray]:
    """:func:`object_box` of several objects whose camera-frame points are ``points[indices]`` (Nx3, C-contiguous;
    indices outside the array and points not finite are skipped), each object's a consecutive group of ``sizes``
    indices; and which objects had a finite point (the boxes are theirs, in order)."""
    rows, kept = _loops().gathered_compact_sets(points, indices, np.asarray(sizes, dtype=np.int64), STRAY_FENCE)
    posed = kept > 0
    return _boxes_of_compact(rows, kept[posed], cam_to_world), posed


def _boxes_of_compact(
    rows: np.ndarray, sizes: np.ndarray, cam_to_world: np.ndarray | None
) -> list[tuple[OrientedBox, str]]:
    """:func:`object_box` of compacted sets (3xN float64 rows, sets one after another, none empty)."""
    if cam_to_world is not None:
        transform = np.asarray(cam_to_world, dtype=np.float64)
        world = rows.T @ transform[:3, :3].T + transform[:3, 3]  # all the sets at once
        fit = _upright if np.isfinite(world).all() else upright_box  # only an overflow makes a point infinite
        return [(fit(part), "world") for part in np.split(world, np.cumsum(sizes)[:-1])]
    return [(box, "camera") for box in _principal_boxes(rows, sizes)]


def object_boxes_of_sets(
    rows: np.ndarray, sizes: np.ndarray, cam_to_world: np.ndarray | None
) -> list[tuple[OrientedBox, str]]:
    """:func:`object_box` of several objects whose finite camera-frame points are stored one after another as 3xN
    float64 rows (C-contiguous), each object's number of points (at least one) in ``sizes``."""
    sizes = np.asarray(sizes, dtype=np.int64)
    rows, sizes = _loops().compact_sets(np.ascontiguousarray(rows, dtype=np.float64), sizes, STRAY_FENCE)
    return _boxes_of_compact(rows, sizes, cam_to_world)
