"""Human-readable results of a CAS: a table of the object hypotheses and an annotated colour image.

Sizes come from a Size annotation when an expert attached one, else from the oriented box of the hypothesis
points: upright in the world when the camera pose is known, upright on the supporting plane when there is one,
else along the principal axes. Positions are in the frame of the Pose annotation (world when the camera pose
was known).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import cv2
import numpy as np

from annotators.cloud.plane import plane_basis
from annotators.cloud.pose import hypothesis_points
from annotators.geometry.boxes import object_box
from reasoning.beliefs.answer import Answer
from robokudo.core.cas import CAS
from robokudo.core.types import (
    CameraInfo,
    ColorImage,
    ObjectHypothesis,
    Plane,
    PointCloud,
    Pose,
    QueryAnswer,
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


_DRAW_COLORS: Mapping[str, tuple[int, int, int]] = MappingProxyType(
    {
        "red": (230, 40, 40),
        "orange": (255, 150, 20),
        "yellow": (250, 230, 40),
        "green": (40, 200, 60),
        "blue": (40, 110, 255),
        "purple": (160, 60, 220),
        "pink": (255, 120, 200),
        "brown": (150, 90, 40),
        "white": (255, 255, 255),
        "grey": (160, 160, 160),
        "black": (20, 20, 20),
    }
)


def draw_hypotheses(cas: CAS) -> np.ndarray:
    """The colour image (a new RGB array) with every hypothesis outlined, boxed and labelled."""
    color_view = cas.view(ColorImage)
    if color_view is None:
        raise ValueError("the CAS has no ColorImage to draw on")
    canvas = np.ascontiguousarray(color_view.image).copy()
    hypotheses = cas.annotations(ObjectHypothesis)
    for summary, hypothesis in zip(summarize(cas), hypotheses, strict=True):
        rgb = _DRAW_COLORS.get(summary.color, (0, 255, 255))
        x0, y0, x1, y1 = summary.roi
        local = np.ascontiguousarray(hypothesis.mask[y0:y1, x0:x1]).view(np.uint8)
        contours, _ = cv2.findContours(local, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE, offset=(x0, y0))
        cv2.drawContours(canvas, contours, -1, rgb, 1, cv2.LINE_AA)
        cv2.rectangle(canvas, (x0, y0), (x1 - 1, y1 - 1), rgb, 2)
        label = f"{summary.number} {summary.color}"
        if summary.size is not None:
            label += f" {100 * summary.size[0]:.0f}cm"
        (width, height), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
        top = max(y0 - height - 6, 0)
        cv2.rectangle(canvas, (x0, top), (x0 + width + 6, top + height + 6), (0, 0, 0), -1)
        cv2.putText(canvas, label, (x0 + 3, top + height + 2), cv2.FONT_HERSHEY_SIMPLEX, 0.45, rgb, 1, cv2.LINE_AA)
    return canvas


@dataclass(frozen=True)
class Box:
    """A hypothesis' image box and its label."""

    roi: tuple[int, int, int, int]
    label: str


def answer_boxes(cas: CAS) -> tuple[Box, ...]:
    """The answer's objects seen in this frame (``#id label``), or else every hypothesis, with their boxes."""
    found = cas.view(QueryAnswer)
    if found is not None and isinstance(found.answer, Answer):
        labelled = tuple(
            Box(tuple(int(v) for v in o.roi), f"#{o.id} {o.shown_label()}")  # type: ignore[arg-type]
            for o in found.answer.objects
            if o.roi is not None
        )
        if labelled:
            return labelled
    hypotheses = cas.annotations(ObjectHypothesis)
    return tuple(Box(tuple(int(v) for v in h.roi), f"hypothesis {i}") for i, h in enumerate(hypotheses, 1))  # type: ignore[arg-type]


def draw_answer(cas: CAS) -> np.ndarray:
    """The colour image (a new RGB array) with the hypotheses outlined and the answer's objects boxed with their
    id and class (every hypothesis numbered when the CAS holds no answer)."""
    color_view = cas.view(ColorImage)
    if color_view is None:
        raise ValueError("the CAS has no ColorImage to draw on")
    canvas = np.ascontiguousarray(color_view.image).copy()
    for hypothesis in cas.annotations(ObjectHypothesis):
        x0, y0, x1, y1 = hypothesis.roi
        local = np.ascontiguousarray(hypothesis.mask[y0:y1, x0:x1]).view(np.uint8)
        contours, _ = cv2.findContours(local, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE, offset=(x0, y0))
        cv2.drawContours(canvas, contours, -1, (160, 160, 160), 1, cv2.LINE_AA)
    for box in answer_boxes(cas):
        _draw_box(canvas, box.roi, box.label, (0, 229, 255))
    return canvas


def _draw_box(canvas: np.ndarray, roi: tuple[int, int, int, int], label: str, rgb: tuple[int, int, int]) -> None:
    x0, y0, x1, y1 = roi
    cv2.rectangle(canvas, (x0, y0), (x1 - 1, y1 - 1), rgb, 2)
    (width, height), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
    top = max(y0 - height - 6, 0)
    cv2.rectangle(canvas, (x0, top), (x0 + width + 6, top + height + 6), (0, 0, 0), -1)
    cv2.putText(canvas, label, (x0 + 3, top + height + 2), cv2.FONT_HERSHEY_SIMPLEX, 0.45, rgb, 1, cv2.LINE_AA)


def write_image(picture: np.ndarray, path: str | Path) -> Path:
    """Write an RGB picture to ``path`` (format from the suffix); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), cv2.cvtColor(picture, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write an image to {path}")
    return path


def write_annotated_image(cas: CAS, path: str | Path) -> Path:
    """Draw the hypotheses and write the picture to ``path`` (format from the suffix); returns the path."""
    return write_image(draw_hypotheses(cas), path)
