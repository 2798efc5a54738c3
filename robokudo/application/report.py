"""Human-readable results of a CAS: a table of the object hypotheses (pictures: ``annotated_image``).

Sizes come from a Size annotation when an expert attached one, else from the oriented box of the hypothesis
points: upright in the world when the camera pose is known, upright on the supporting plane when there is one,
else along the principal axes. Positions are in the frame of the Pose annotation (world when the camera pose
was known).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from annotators.cloud.plane import plane_basis
from annotators.cloud.pose import hypothesis_points
from annotators.geometry.boxes import object_box
from robokudo.core.cas import CAS
from robokudo.core.types import (
    CameraInfo,
    ObjectHypothesis,
    Plane,
    PointCloud,
    Pose,
    SemanticColor,
    Size,
)


@dataclass(frozen=True)
class HypothesisSummary:
    """What the table and the picture show of one hypothesis."""

    number: int
    color: str
    color_confidence: float
    position: np.ndarray | None
    frame: str
    size: tuple[float, float, float] | None
    pixels: int
    roi: tuple[int, int, int, int]


def upright_frame(cas: CAS) -> np.ndarray | None:
    """A 4x4 camera-to-frame transform whose z axis is up: the world, else the supporting plane, else None."""
    camera = cas.view(CameraInfo)
    if camera is not None and camera.cam_to_world is not None:
        return np.asarray(camera.cam_to_world, dtype=np.float64)
    planes = cas.annotations(Plane)
    if not planes:
        return None
    model = np.asarray(max(planes, key=lambda p: np.asarray(p.inlier_indices).size).model, dtype=np.float64)
    normal = model[:3] / np.linalg.norm(model[:3])
    plane_to_camera = np.eye(4)
    plane_to_camera[:3, :2] = plane_basis(normal).T
    plane_to_camera[:3, 2] = normal
    plane_to_camera[:3, 3] = -model[3] * normal  # the camera's foot on the plane
    return np.linalg.inv(plane_to_camera)


def summarize(cas: CAS) -> list[HypothesisSummary]:
    """One summary per object hypothesis of the CAS, in CAS order, numbered from 1."""
    cloud = cas.view(PointCloud)
    upright = upright_frame(cas)
    summaries = []
    for number, hypothesis in enumerate(cas.annotations(ObjectHypothesis), start=1):
        color = hypothesis.first(SemanticColor)
        pose = hypothesis.first(Pose)
        size_annotation = hypothesis.first(Size)
        size: tuple[float, float, float] | None = None
        if size_annotation is not None:
            size = tuple(float(v) for v in size_annotation.dimensions)  # type: ignore[assignment]
        elif cloud is not None:
            points = hypothesis_points(cloud, hypothesis)
            if points.shape[0]:
                box, _ = object_box(points, upright)
                size = tuple(float(v) for v in sorted(box.extents, reverse=True))  # type: ignore[assignment]
        summaries.append(
            HypothesisSummary(
                number=number,
                color=color.color if color is not None else "?",
                color_confidence=color.confidence if color is not None else 0.0,
                position=np.asarray(pose.position, dtype=float) if pose is not None else None,
                frame=pose.frame if pose is not None else "",
                size=size,
                pixels=int(np.asarray(hypothesis.point_indices).size),
                roi=hypothesis.roi,
            )
        )
    return summaries


def describe_hypotheses(cas: CAS) -> str:
    """A text table of the hypotheses: colour (confidence), position in metres (frame), size in cm, pixels."""
    rows = [("#", "colour", "position [m]", "frame", "size [cm]", "pixels")]
    for s in summarize(cas):
        position = "-" if s.position is None else "({:+.3f}, {:+.3f}, {:+.3f})".format(*s.position)
        size = "-" if s.size is None else " x ".join(f"{100 * v:.1f}" for v in s.size)
        rows.append(
            (str(s.number), f"{s.color} ({s.color_confidence:.2f})", position, s.frame or "-", size, str(s.pixels))
        )
    if len(rows) == 1:
        return "no object hypotheses"
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return "\n".join(
        "  ".join(cell.ljust(width) for cell, width in zip(row, widths, strict=True)).rstrip() for row in rows
    )
