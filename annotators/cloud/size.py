"""Metric size and size class of each object hypothesis, measured upright on its support.

In the support frame (:mod:`annotators.geometry.support_frame`) the footprint's axes come from its minimum-area
rectangle and the extents are the 1 % / 99 % quantiles of the points along them (robust to stray pixels). On a
supporting plane the height runs from the plane to the top, so a bottom hidden behind the object still counts; in
the world frame it is the points' own vertical extent. Without a plane or camera pose the principal axes are used
and the confidence is lowered. The size class comes from the largest extent with :data:`SIZE_CLASS_THRESHOLDS`."""

from __future__ import annotations

from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.cloud_expert import CloudExpert
from annotators.geometry.boxes import compact_points, principal_box
from annotators.geometry.support_frame import SupportFrame, sampled_indices, support_frame, usable_plane
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, ObjectHypothesis, Plane, PointCloud, Size

SIZE_CLASS_THRESHOLDS: tuple[float, float] = (0.12, 0.25)
"""Largest extent < 0.12 m -> "small", < 0.25 m -> "medium", else "large"."""

SIZE_CLASSES: tuple[str, ...] = ("small", "medium", "large")
"""Every size class this annotator reports (the ontology's size classes, lower case)."""

GUESSED_FRAME_CONFIDENCE = 0.6
"""Confidence of a size measured without a supporting plane or camera pose."""


def size_class_for(size: tuple[float, float, float]) -> str:
    """Size class from the largest extent (see ``SIZE_CLASS_THRESHOLDS``)."""
    largest = max(size)
    if largest < SIZE_CLASS_THRESHOLDS[0]:
        return "small"
    if largest < SIZE_CLASS_THRESHOLDS[1]:
        return "medium"
    return "large"


def _spread(values: np.ndarray, low: float = 0.01, high: float = 0.99) -> float:
    ordered = np.sort(values)
    last = ordered.size - 1
    return float(ordered[round(high * last)] - ordered[round(low * last)])


def upright_extents(points: np.ndarray, on_plane: bool) -> tuple[float, float, float]:
    """Footprint length, footprint width and height of Nx3 points in an upright frame (z = 0 on the support)."""
    footprint = points[:, :2].astype(np.float32)
    (_, _), (_, _), angle = cv2.minAreaRect(footprint)
    yaw = np.radians(angle)
    axes = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])
    local = points[:, :2] @ axes.T
    first, second = _spread(local[:, 0]), _spread(local[:, 1])
    z = np.sort(points[:, 2])
    height = float(max(z[round(0.99 * (z.size - 1))], 0.0)) if on_plane else _spread(z)
    return max(first, second), min(first, second), height


def measure(points_camera: np.ndarray, frame: SupportFrame) -> tuple[float, float, float]:
    """The object's extents (metres, largest first) from its Nx3 camera-frame points."""
    if frame.guessed:
        extents = principal_box(compact_points(points_camera)).extents
    else:
        extents = np.array(upright_extents(frame.points(points_camera), frame.on_plane))
    ordered = sorted((float(v) for v in extents), reverse=True)
    return ordered[0], ordered[1], ordered[2]


class SizeAnnotator(CloudExpert):
    """Attaches metric dimensions (largest first) and a size class (small, medium, large) to every hypothesis."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, PointCloud)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Size,)
    purpose: ClassVar[str] = "measure"
    capability: ClassVar[Capability] = Capability(
        label="size annotator",
        sizes=("Small", "Medium", "Large"),
        preconditions=("NeedsDepth",),
        cost_ms=5.0,
        reliability=0.9,
    )

    def __init__(self, max_points: int = 3000, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_points = max_points

    def analyse(self) -> None:
        """Measure each hypothesis; fail when none has enough valid points."""
        cloud = self.usable_cloud()
        hypotheses = self.hypotheses()
        frame = support_frame(usable_plane(self.annotations(Plane)), self.optional_view(CameraInfo))
        confidence = GUESSED_FRAME_CONFIDENCE if frame.guessed else 1.0
        flat = cloud.points.reshape(-1, 3)
        measured = 0
        for hypothesis in hypotheses:
            indices = sampled_indices(cloud, hypothesis, self.max_points)
            if indices.size < 3:
                continue
            dimensions = measure(flat[indices].astype(np.float64), frame)
            self.attach(
                hypothesis,
                Size(dimensions=dimensions, size_class=size_class_for(dimensions), confidence=confidence),
            )
            measured += 1
        if measured == 0:
            self.fail("no object hypothesis has enough valid points to measure")
