"""Pose estimation: every hypothesis gets the centre and orientation of its oriented bounding box."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from annotators.cloud.cloud_expert import CloudExpert
from annotators.geometry.boxes import box_orientations, finite_points, object_boxes_of_indexed
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, ObjectHypothesis, PointCloud, Pose


def hypothesis_points(cloud: PointCloud, hypothesis: ObjectHypothesis, max_points: int = 2000) -> np.ndarray:
    """Up to about ``max_points`` finite camera-frame points (Nx3 float64) of the hypothesis, evenly sampled."""
    indices = np.asarray(hypothesis.point_indices)
    indices = indices[:: max(1, indices.size // max_points)]
    indices = indices[(indices >= 0) & (indices < cloud.mask.size)]
    return finite_points(cloud.points.reshape(-1, 3)[indices])


def sampled_indices(hypotheses: list[ObjectHypothesis], max_points: int) -> tuple[np.ndarray, np.ndarray]:
    """The point indices :func:`hypothesis_points` samples of each hypothesis (about ``max_points`` evenly
    spaced), all of them one hypothesis after another, and how many each hypothesis has."""
    picked = []
    for hypothesis in hypotheses:
        indices = np.asarray(hypothesis.point_indices)
        picked.append(indices[:: max(1, indices.size // max_points)])
    sizes = np.array([indices.size for indices in picked], dtype=np.int64)
    every = np.concatenate(picked).astype(np.intp, copy=False) if picked else np.zeros(0, dtype=np.intp)
    return every, sizes


class PoseAnnotator(CloudExpert):
    """Attaches the oriented-box pose of every hypothesis: upright in the world frame when the camera pose is
    known, else principal axes in the camera frame."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, PointCloud)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Pose,)
    purpose: ClassVar[str] = "estimate poses for"
    capability: ClassVar[Capability] = Capability(
        label="pose annotator",
        cost_ms=2.0,
        reliability=0.9,
    )

    def __init__(self, max_points: int = 1000, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_points = max_points

    def analyse(self) -> None:
        """Attach one Pose per hypothesis with points; fail when no hypothesis has any valid point."""
        cloud = self.usable_cloud()
        hypotheses = self.hypotheses()
        camera = self.optional_view(CameraInfo)
        cam_to_world = camera.cam_to_world if camera is not None else None
        if cam_to_world is not None and (np.shape(cam_to_world) != (4, 4) or not np.all(np.isfinite(cam_to_world))):
            self.fail(f"camera pose must be a finite 4x4 matrix, got shape {np.shape(cam_to_world)}")
        indices, sizes = sampled_indices(hypotheses, self.max_points)
        points = np.ascontiguousarray(cloud.points).reshape(-1, 3)
        boxes, has_points = object_boxes_of_indexed(points, indices, sizes, cam_to_world)
        posed = [hypothesis for hypothesis, kept in zip(hypotheses, has_points.tolist(), strict=True) if kept]
        if not posed:
            self.fail("no object hypothesis has a valid 3-D point")
        orientations = box_orientations([box for box, _ in boxes])
        for hypothesis, (box, frame), orientation in zip(posed, boxes, orientations, strict=True):
            self.attach(hypothesis, Pose(position=box.centre, orientation=orientation.copy(), frame=frame))
