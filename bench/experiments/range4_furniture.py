"""Issue 15, the TUM desk beyond 2.5 m, range3's causes A and B measured (bench/profiles/range4-analysis.txt).

    PYTHONPATH=. python bench/experiments/range4_furniture.py

Starts from range3's far input (bench/experiments/range3_far_desk.py: the cloud read on to 4 m, the support's
inliers continued by the far points within the Kinect v1 noise of the near plane) and removes, before
:func:`segment_clutter` (unchanged), the candidates on large flat faces: planes fitted one after another on the
candidates (points 1 cm to 0.5 m above the support), their inliers within the depth-resolution step
``2.8e-3 * z^2`` (Khoshelham & Elberink 2012: 7 cm at 5 m; at least 1 cm), split into 8-connected pieces; a piece
longer in the plane than ``FURNITURE`` (0.5 m, the candidates' own ceiling: nothing graspable is that big) is a face
of furniture (the shelf block's front, the partition) and is no candidate. Prints the segments as range3 did, a
segment whose top lies within the resolution step of the 0.5 m ceiling marked (cut by the ceiling: part of something
taller), for the near input, the far input, and the far input with a fixed 1 cm face tolerance (without cause B's
resolution step).
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from range3_far_desk import BOUND, FAR, KINECT_C, front

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.plane import plane_basis, plane_distances, ransac_support_plane
from robokudo.core.types import PointCloud

RESOLUTION_C = 0.07 / 5.0**2
"""Kinect v1 depth resolution step = RESOLUTION_C * z^2 (Khoshelham & Elberink 2012: 7 cm at 5 m)."""
FURNITURE = 0.5
MIN_FACE = 400


def furniture_faces(
    points: np.ndarray, candidates: np.ndarray, tries: int = 8, resolution: float = RESOLUTION_C
) -> tuple[np.ndarray, list[str]]:
    """The candidate pixels on flat faces longer than FURNITURE, and one line per face found; a face's inliers lie
    within ``max(1 cm, resolution * z^2)`` of its plane (``resolution`` 0: a fixed 1 cm)."""
    left = candidates.copy()
    removed = np.zeros_like(candidates)
    lines = []
    depth = points[..., 2]
    for attempt in range(tries):
        fit = ransac_support_plane(points, left, distance=0.02, seed=attempt)
        if fit is None:
            break
        with np.errstate(invalid="ignore"):
            tolerance = np.maximum(0.01, resolution * depth**2)
            on = left & (np.abs(plane_distances(points, fit.model)) <= tolerance)
        count, labels = cv2.connectedComponents(on.view(np.uint8), connectivity=8)
        basis = plane_basis(np.asarray(fit.model[:3], dtype=np.float64))
        for label in range(1, count):
            piece = labels == label
            if np.count_nonzero(piece) < MIN_FACE:
                continue
            flat = points[piece].astype(np.float64) @ basis.T
            flat -= flat.mean(axis=0)
            axes = np.linalg.svd(flat, full_matrices=False)[2]
            spans = np.percentile(flat @ axes.T, 99, axis=0) - np.percentile(flat @ axes.T, 1, axis=0)
            ys, xs = np.nonzero(piece)
            big = spans[0] > FURNITURE
            lines.append(
                f"  face {attempt}: normal {np.round(fit.model[:3], 2)} roi ({xs.min()},{ys.min()},{xs.max()},"
                f"{ys.max()}) {np.count_nonzero(piece)} pts span {spans[0]:.2f} x {spans[1]:.2f} m"
                f"{'  FURNITURE' if big else ''}"
            )
            if big:
                removed |= piece
        left &= ~on
    return removed, lines


def report(name: str, cloud: PointCloud, mask: np.ndarray, inliers: np.ndarray, model: np.ndarray) -> None:
    """Segment and print one line per segment; a segment whose top lies within the depth-resolution step of the
    candidates' 0.5 m ceiling is marked (part of something taller, cut by the ceiling) and counted apart."""
    segments = segment_clutter(cloud.points, mask, model, inliers, ClutterParameters(), cloud.colors)
    heights = plane_distances(cloud.points, model).reshape(-1)
    depth = cloud.points[..., 2].reshape(-1)
    lines, kept = [], 0
    for segment in sorted(segments, key=lambda s: s.roi):
        h, z = heights[segment.indices], depth[segment.indices]
        top = int(np.nanargmax(h))
        ceiling = h[top] >= 0.5 - max(0.01, RESOLUTION_C * z[top] ** 2)
        kept += not ceiling
        lines.append(
            f"  roi {segment.roi!s:22} {segment.indices.size:6d} pts  z {np.nanmedian(z):.2f} m  "
            f"top {h[top]:.3f} m{'  reaches the ceiling' if ceiling else ''}"
        )
    print(f"{name}: {len(segments)} segments, {kept} below the ceiling")
    print("\n".join(lines))


def main() -> None:
    """Print the segments with and without the furniture faces."""
    cloud, plane = front()
    model = np.asarray(plane.model, dtype=np.float64)
    inliers = np.asarray(plane.inlier_indices)
    points = cloud.points
    finite = np.isfinite(points[..., 2])
    with np.errstate(invalid="ignore"):
        far = finite & (points[..., 2] > BOUND) & (points[..., 2] <= FAR) & ~cloud.mask
        signed = plane_distances(points, model)
        sigma = KINECT_C * points[..., 2] ** 2
    continued = np.concatenate([inliers, np.flatnonzero(far & (np.abs(signed) <= sigma))])
    for name, mask, resolution in (
        ("near", cloud.mask, RESOLUTION_C),
        ("far", cloud.mask | far, RESOLUTION_C),
        ("far, 1 cm face tolerance", cloud.mask | far, 0.0),
    ):
        with np.errstate(invalid="ignore"):
            candidates = mask & (signed > 0.01) & (signed <= 0.5)
        removed, lines = furniture_faces(points, candidates, resolution=resolution)
        print(f"{name}: {np.count_nonzero(removed)} candidate pixels on furniture faces")
        print("\n".join(lines))
        plane_points = inliers if name == "near" else continued
        report(f"{name}, furniture faces removed", cloud, mask & ~removed, plane_points, model)


if __name__ == "__main__":
    main()
