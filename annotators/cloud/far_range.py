"""Reading a support plane on beyond the precise range, where the range bound cuts it.

The tabletop tree crops depth at the range where the sensor's noise reaches the segmenters' 1 cm lift (2.5 m for a
Kinect v1, :mod:`annotators.geometry.depth_noise`) and fits the support plane there, on precise points. A desk
seen from a few metres away runs on past that bound, and what stands on its far half is never seen. When the
support's own inliers reach the bound - more than ``reach_share`` of them within ``reach`` of it, which no plane
the crop leaves whole does - the cloud is read on to ``far_depth`` and the plane's inliers are continued by the
far points that lie within the depth noise at their depth of the plane fitted on the precise range. The model is
not refitted: the far points are noisier, and the near plane extrapolates well (bench/profiles/range3-analysis.txt).
A plane that does not reach the bound leaves the cloud and the plane untouched.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from annotators.cloud.filters import range_mask
from annotators.cloud.plane import plane_distances
from annotators.cloud.point_cloud import cloud_problem
from annotators.geometry.depth_noise import KINECT_V1, DepthNoise
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, Plane, PointCloud


def reaches_bound(depths: np.ndarray, bound: float, reach: float, share: float) -> bool:
    """Whether more than ``share`` of the inlier ``depths`` lie within ``reach`` metres of the range ``bound``."""
    depths = depths[np.isfinite(depths)]
    return depths.size > 0 and float(np.mean(depths >= bound - reach)) > share


def far_inliers(
    points: np.ndarray, far: np.ndarray, model: np.ndarray, noise: DepthNoise, k: float = 1.0
) -> np.ndarray:
    """Flat indices of the ``far`` points (HxW bool) within ``k`` times the depth noise at their depth of the
    plane ``model``."""
    index = np.flatnonzero(far)
    flat = points.reshape(-1, 3)[index]
    distances = np.abs(plane_distances(flat, model))
    return index[distances <= k * noise.coefficient * flat[:, 2] * flat[:, 2]]


class FarSupportRange(Annotator):
    """Reads the cloud on to ``far_depth`` and continues the support plane's inliers there, when the range bound
    ``bound`` cuts the support (its inliers reach the bound); else leaves both as they are."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, Plane)
    capability: ClassVar[Capability] = Capability(label="far support range", cost_ms=3.0, reliability=1.0)

    def __init__(
        self,
        bound: float = 2.5,
        far_depth: float = 4.0,
        noise: DepthNoise = KINECT_V1,
        reach: float = 0.05,
        reach_share: float = 0.01,
        name: str | None = None,
    ) -> None:
        """``bound``: the range the plane was fitted on (metres); ``far_depth``: how far to read on (Kinect v1's
        specified range, 4 m); ``reach``/``reach_share``: the plane reaches the bound when more than
        ``reach_share`` of its inliers lie within ``reach`` metres of it."""
        super().__init__(name=name)
        if not 0 < bound < far_depth:
            raise ValueError(f"need 0 < bound < far_depth, got {bound}, {far_depth}")
        self.bound, self.far_depth, self.noise = bound, far_depth, noise
        self.reach, self.reach_share = reach, reach_share

    def analyse(self) -> None:
        """Write the widened cloud and the continued plane when the support reaches the bound."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        planes = self.annotations(Plane)
        if not planes:
            self.fail("no supporting Plane in the CAS")
        plane = max(planes, key=lambda candidate: np.asarray(candidate.inlier_indices).size)
        inliers = np.asarray(plane.inlier_indices)
        depths = cloud.points.reshape(-1, 3)[inliers, 2]
        if not reaches_bound(depths, self.bound, self.reach, self.reach_share):
            return
        finite = np.isfinite(cloud.points[..., 2])
        far = range_mask(cloud.points, finite, self.bound, self.far_depth) & ~cloud.mask
        if not far.any():
            return
        model = np.asarray(plane.model, dtype=np.float64)
        more = far_inliers(cloud.points, far, model, self.noise)
        self.write(cloud.with_mask(cloud.mask | far))
        self.write(Plane(model=plane.model, inlier_indices=np.concatenate([inliers, more]), source=self.name))
