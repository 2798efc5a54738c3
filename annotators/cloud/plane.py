"""Supporting-plane segmentation: a seeded, vectorised RANSAC on the organized cloud, refined by least squares.

Plane hypotheses come from point triples drawn close together on the pixel grid (so most triples lie on one
surface), are scored all at once on a random subsample of the points, and the winner is refitted to its inliers
on the whole cloud; only the largest connected region of inliers on the pixel grid is kept (the surface
itself, not a wall line or a bowl bottom that happens to lie on the same plane). With a known gravity
direction only planes facing up toward the camera (within ``max_tilt_degrees``) are considered, so a wall
or the underside of a shelf is never the support.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.cloud.cloud_loops import centred_scatter, plane_band
from robokudo.core.types import CameraInfo

MIN_PLANE_POINTS = 50


@dataclass(frozen=True, eq=False)
class PlaneFit:
    """A plane ``model`` (a, b, c, d with unit normal toward the camera) and its inliers as flat grid indices."""

    model: np.ndarray
    inlier_indices: np.ndarray


def orient_toward_origin(model: np.ndarray) -> np.ndarray:
    """The plane with its normal flipped, if needed, so that the camera (origin) is on the positive side."""
    return -model if model[3] < 0 else model


def least_squares_plane(points: np.ndarray) -> np.ndarray | None:
    """The total-least-squares plane through Nx3 points (unit normal toward the origin), None when degenerate."""
    if points.shape[0] < 3:
        return None
    columns = np.ascontiguousarray(points.T, dtype=np.float64)  # 3xN: each coordinate's values contiguous
    centre = columns.mean(axis=1)
    centred = columns.T - centre
    eigenvalues, eigenvectors = np.linalg.eigh(centred.T @ centred)
    if eigenvalues[1] <= 1e-6 * max(eigenvalues[2], 1e-12):
        return None  # collinear or coincident points
    normal = eigenvectors[:, 0]
    return orient_toward_origin(np.append(normal, -normal @ centre))


def _refit(points: np.ndarray, step: int, indices: np.ndarray) -> np.ndarray | None:
    """:func:`least_squares_plane` of the points at ``indices`` (flat indices into the grid of every ``step``-th
    row and column of the HxWx3 ``points``), without gathering them."""
    if indices.size < 3:
        return None
    centre, scatter = centred_scatter(points, step, indices)
    eigenvalues, eigenvectors = np.linalg.eigh(scatter)
    if eigenvalues[1] <= 1e-6 * max(eigenvalues[2], 1e-12):
        return None  # collinear or coincident points
    normal = eigenvectors[:, 0]
    return orient_toward_origin(np.append(normal, -normal @ centre))


def plane_distances(points: np.ndarray, model: np.ndarray) -> np.ndarray:
    """Signed distances (float32, the points' shape without the last axis; NaN for NaN points) of Nx3 or HxWx3
    points to ``model`` (one affine transform in OpenCV, accumulated in double precision)."""
    grid = np.ascontiguousarray(points, dtype=np.float32)
    if grid.size == 0:
        return np.zeros(grid.shape[:-1], dtype=np.float32)
    distances = cv2.transform(grid.reshape(-1, 1, 3), np.asarray(model, dtype=np.float64).reshape(1, 4))
    return distances.reshape(grid.shape[:-1])


def _support(sample: np.ndarray, normals: np.ndarray, offsets: np.ndarray, distance: float) -> np.ndarray:
    """How many of the Nx3 sample points lie within ``distance`` of each of the K planes (normals Kx3)."""
    residuals = normals.astype(np.float32) @ sample.T  # KxN: each plane's residuals contiguous
    residuals += offsets.astype(np.float32)[:, None]
    np.abs(residuals, out=residuals)
    return np.count_nonzero(residuals < distance, axis=1)


def _triples(
    valid: np.ndarray, candidates: np.ndarray, count: int, radius: int, rng: np.random.Generator
) -> np.ndarray:
    """``count`` triples of flat indices of valid pixels (``candidates``, the flat indices of ``valid``): an
    anchor and two partners within ``radius`` px."""
    rows, cols = valid.shape
    anchors = candidates[rng.integers(0, candidates.size, size=count)]
    offsets = rng.integers(-radius, radius + 1, size=(count, 2, 2))
    r = np.clip(anchors[:, None] // cols + offsets[..., 0], 0, rows - 1)
    c = np.clip(anchors[:, None] % cols + offsets[..., 1], 0, cols - 1)
    partners = r * cols + c
    triples = np.column_stack([anchors, partners])
    return triples[valid.reshape(-1)[partners].all(axis=1)]


def ransac_support_plane(
    points: np.ndarray,
    mask: np.ndarray,
    distance: float = 0.01,
    iterations: int = 400,
    seed: int = 0,
    up: np.ndarray | None = None,
    max_tilt_degrees: float = 20.0,
    sample_size: int = 2000,
    triple_radius: int = 40,
) -> PlaneFit | None:
    """The dominant plane of the organized cloud's masked points (the dominant upward one when ``up`` is given).

    ``up`` is the gravity-opposite direction in the camera frame. Returns None when no plane with at least
    ``MIN_PLANE_POINTS`` inliers is found. Deterministic for a given ``seed``.
    """
    with np.errstate(invalid="ignore"):
        valid = mask & np.isfinite(points[..., 2])
    points = np.ascontiguousarray(points, dtype=np.float32)  # the compiled passes read it flat
    flat = points.reshape(-1, 3)
    valid_indices = np.flatnonzero(valid)
    if valid_indices.size < MIN_PLANE_POINTS:
        return None
    rng = np.random.default_rng(seed)
    triples = _triples(valid, valid_indices, iterations, triple_radius, rng)
    if triples.shape[0] == 0:
        return None
    p0, p1, p2 = (flat[triples[:, i]].astype(np.float64) for i in range(3))
    first, second = p1 - p0, p2 - p0
    normals = np.cross(first, second)
    lengths = np.linalg.norm(normals, axis=1)
    keep = lengths > 1e-3 * np.linalg.norm(first, axis=1) * np.linalg.norm(second, axis=1)  # not collinear
    normals = normals[keep] / lengths[keep, None]
    offsets = -np.einsum("ij,ij->i", normals, p0[keep])
    flip = np.where(offsets < 0, -1.0, 1.0)
    normals *= flip[:, None]
    offsets *= flip
    if up is not None:
        facing = normals @ (up / np.linalg.norm(up)) >= np.cos(np.radians(max_tilt_degrees))
        normals, offsets = normals[facing], offsets[facing]
    if normals.shape[0] == 0:
        return None

    # score every hypothesis on a small sample, then the best few on a larger one
    sample = flat[valid_indices[rng.integers(0, valid_indices.size, size=sample_size)]]
    first_round = _support(sample[: sample_size // 4], normals, offsets, distance)
    finalists = np.argsort(-first_round, kind="stable")[:16]
    best = int(finalists[np.argmax(_support(sample, normals[finalists], offsets[finalists], distance))])
    model = np.append(normals[best], offsets[best])

    max_tilt = np.cos(np.radians(max_tilt_degrees))
    for band in (distance, distance / 2):  # refit to the inliers; the narrower band keeps edges of walls out
        inliers = np.flatnonzero(plane_band(points, valid, 2, model, np.float32(band)))  # on every 2nd pixel
        if inliers.size < MIN_PLANE_POINTS // 4:
            return None
        refined = _refit(points, 2, inliers[:: inliers.size // 20000 + 1])
        if refined is None or (up is not None and refined[:3] @ up / np.linalg.norm(up) < max_tilt):
            break
        model = refined
    near = plane_band(points, valid, 1, model, np.float32(distance))
    inliers = np.flatnonzero(largest_region_mask(near))
    if inliers.size < MIN_PLANE_POINTS:
        return None
    return PlaneFit(model=model, inlier_indices=inliers)


def largest_region_mask(mask: np.ndarray, step: int = 2) -> np.ndarray:
    """``mask`` (HxW bool) reduced to its largest 8-connected region, found on every ``step``-th pixel as in
    :func:`largest_region` (a pixel stays when its coarse cell or a neighbour belongs to the largest region)."""
    coarse = np.ascontiguousarray(mask[::step, ::step]).view(np.uint8)
    count, labels = cv2.connectedComponents(coarse, connectivity=8)  # several times faster than ...WithStats
    if count <= 2:
        return mask
    biggest = 1 + int(np.argmax(np.bincount(labels.reshape(-1), minlength=count)[1:]))  # the largest area
    keep = cv2.dilate((labels == biggest).view(np.uint8), np.ones((3, 3), np.uint8))
    rows, cols = mask.shape
    keep = cv2.resize(keep, (keep.shape[1] * step, keep.shape[0] * step), interpolation=cv2.INTER_NEAREST)
    return mask & keep[:rows, :cols].view(bool)  # keep holds 0 and 1 only (dilated 0/1, scaled up)


def largest_region(indices: np.ndarray, shape: tuple[int, int], step: int = 2) -> np.ndarray:
    """The flat indices of the pixels in the largest 8-connected region the given pixels form on the grid.

    Regions are found on every ``step``-th pixel (a coarse cell keeps a pixel when the cell or a neighbour
    belongs to the largest region), which is several times faster and the same for any sizeable surface.
    """
    if indices.size == 0:
        return indices
    image = np.zeros(shape, dtype=np.uint8)
    image.reshape(-1)[indices] = 1
    coarse = np.ascontiguousarray(image[::step, ::step])
    count, labels, stats, _ = cv2.connectedComponentsWithStats(coarse, connectivity=8)
    if count <= 2:
        return indices
    biggest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    keep = cv2.dilate((labels == biggest).view(np.uint8), np.ones((3, 3), np.uint8))
    rows, cols = indices // shape[1], indices % shape[1]
    return indices[keep[rows // step, cols // step] > 0]


def plane_basis(normal: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors (2x3) spanning the plane with this unit normal."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    first = np.cross(normal, helper)
    first /= np.linalg.norm(first)
    return np.stack([first, np.cross(normal, first)])


def up_in_camera(camera: CameraInfo | None) -> np.ndarray | None:
    """The world's up axis (+z) in the camera frame, or None when the camera pose is unknown."""
    if camera is None or camera.cam_to_world is None:
        return None
    rotation = np.asarray(camera.cam_to_world, dtype=np.float64)[:3, :3]
    up = rotation.T @ np.array([0.0, 0.0, 1.0])
    return up if np.all(np.isfinite(up)) and np.linalg.norm(up) > 0.5 else None
