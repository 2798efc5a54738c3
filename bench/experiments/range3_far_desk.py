"""Issue 15, the TUM desk beyond 2.5 m: what the clutter segmenter finds when the support plane is read on to 4 m
with a candidate lift that grows with the Kinect v1 depth noise (bench/profiles/range3-analysis.txt).

    PYTHONPATH=. python bench/experiments/range3_far_desk.py

Runs the tabletop front (reader, 0.2-2.5 m crop, support plane) once on the shared TUM frame, then segments with
today's :func:`segment_clutter`, unchanged, on four inputs:

* ``near``: today's tree (the 2.5 m crop);
* ``far, fixed lift``: the cloud read on to 4 m, the plane's inliers continued by the far points within the
  depth noise sigma(z) = c * z^2 of the near plane (c = 0.04 / 5^2 per metre, Khoshelham & Elberink 2012,
  Sensors 12:1437: 4 cm at 5 m; 1 cm at 2.5 m), the 1 cm lift as today;
* ``far, lift k*sigma(z)`` for k = 1 and 2: as above, and far points within k * sigma(z) of the plane are no
  candidates (masked out; for candidacy the same as a lift of max(1 cm, k * sigma(z))).

For every segment: ROI, points, median depth, the top height above the plane and whether that top lies within
sigma(z) of the candidates' 0.5 m ceiling (the rule for a far piece cut by the ceiling: part of something taller).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import RangeFilter
from annotators.cloud.plane import plane_distances
from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.cloud.support_choice import SupportPlaneSegmenter
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import Plane, PointCloud
from trees.tabletop import create_reader

TUM = (Path(__file__).resolve().parents[3] / "shared" / "data" / "tum_rgbd_sample_open3d").resolve()
BOUND, FAR = 2.5, 4.0
KINECT_C = 0.04 / 5.0**2
"""Kinect v1 depth noise sigma(z) = KINECT_C * z^2 (Khoshelham & Elberink 2012)."""


def front() -> tuple[PointCloud, Plane]:
    """The cropped cloud and the support plane of the TUM frame, as the tabletop tree makes them."""
    steps = [create_reader(str(TUM), 0), PointCloudGenerator(), RangeFilter(0.2, BOUND), SupportPlaneSegmenter()]
    root = Pipeline("front", steps)
    Engine(root).tick()
    return root.cas.view(PointCloud), max(root.cas.annotations(Plane), key=lambda p: p.inlier_indices.size)


def report(name: str, cloud: PointCloud, mask: np.ndarray, inliers: np.ndarray, model: np.ndarray) -> None:
    """Segment and print one line per segment."""
    segments = segment_clutter(cloud.points, mask, model, inliers, ClutterParameters(), cloud.colors)
    heights = plane_distances(cloud.points, model).reshape(-1)
    depth = cloud.points[..., 2].reshape(-1)
    print(f"{name}: {len(segments)} segments")
    for segment in sorted(segments, key=lambda s: s.roi):
        h, z = heights[segment.indices], depth[segment.indices]
        top = int(np.nanargmax(h))
        ceiling = h[top] >= 0.5 - KINECT_C * z[top] ** 2
        print(
            f"  roi {segment.roi!s:22} {segment.indices.size:6d} pts  z {np.nanmedian(z):.2f} m  "
            f"top {h[top]:.3f} m{'  reaches the ceiling' if ceiling else ''}"
        )


def main() -> None:
    """Print the four segmentations."""
    cloud, plane = front()
    model = np.asarray(plane.model, dtype=np.float64)
    inliers = np.asarray(plane.inlier_indices)
    z_in = cloud.points.reshape(-1, 3)[inliers, 2]
    print(f"support inliers within 5 cm of {BOUND} m: {np.mean(z_in >= BOUND - 0.05):.1%}")
    report("near (today)", cloud, cloud.mask, inliers, model)
    finite = np.isfinite(cloud.points[..., 2])
    with np.errstate(invalid="ignore"):
        far = finite & (cloud.points[..., 2] > BOUND) & (cloud.points[..., 2] <= FAR) & ~cloud.mask
        height = np.abs(plane_distances(cloud.points, model))
        sigma = KINECT_C * cloud.points[..., 2] ** 2
    continued = np.concatenate([inliers, np.flatnonzero(far & (height <= sigma))])
    report("far, fixed lift", cloud, cloud.mask | far, continued, model)
    for k in (1.0, 2.0):
        with np.errstate(invalid="ignore"):
            lifted = far & ~(height <= k * sigma)
        report(f"far, lift {k:g} sigma(z)", cloud, cloud.mask | lifted, continued, model)


if __name__ == "__main__":
    main()
