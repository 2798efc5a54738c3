"""The untuned Open3D recipe for tabletop objects, as a baseline to compare segmenters with (not an expert).

The recipe most tutorials give: the dominant plane by RANSAC (``segment_plane``, 1 cm, 3 points, 1000
iterations), its inliers removed, DBSCAN on the rest at 2 cm (``cluster_dbscan``, 10 points), and clusters of at
least ``min_points`` points kept (the same smallest object the grid segmenters keep). Open3D's RANSAC is seeded,
so a scene always gives the same segments.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d

PLANE_DISTANCE = 0.01
DBSCAN_EPS = 0.02
DBSCAN_MIN_POINTS = 10
MIN_POINTS = 300


def plane_dbscan_labels(points: np.ndarray, seed: int = 0, min_points: int = MIN_POINTS) -> np.ndarray:
    """HxW int32 segment labels (0 = none) of an organized HxWx3 cloud by plane RANSAC + DBSCAN."""
    flat = points.reshape(-1, 3)
    valid = np.flatnonzero(np.isfinite(flat).all(axis=1))
    labels = np.zeros(flat.shape[0], dtype=np.int32)
    if valid.size < 3:
        return labels.reshape(points.shape[:2])
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(flat[valid].astype(np.float64)))
    o3d.utility.random.seed(seed)
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        _, inliers = cloud.segment_plane(PLANE_DISTANCE, 3, 1000)
        rest = np.setdiff1d(np.arange(valid.size), np.asarray(inliers))
        clusters = np.asarray(cloud.select_by_index(rest).cluster_dbscan(DBSCAN_EPS, DBSCAN_MIN_POINTS))
    if clusters.size == 0:
        return labels.reshape(points.shape[:2])
    sizes = np.bincount(clusters[clusters >= 0])
    kept = np.flatnonzero(sizes >= min_points)
    renumber = np.zeros(sizes.size + 1, dtype=np.int32)  # index 0 is DBSCAN's noise (-1 shifted)
    renumber[kept + 1] = np.arange(1, kept.size + 1, dtype=np.int32)
    labels[valid[rest]] = renumber[clusters + 1]
    return labels.reshape(points.shape[:2])
