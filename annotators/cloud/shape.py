"""Primitive shape of each object hypothesis (box, cylinder, sphere or flat) by fitting models to its points.

Points and normals are taken into the upright support frame (:mod:`annotators.geometry.support_frame`) and then:

* **flat**: the object is lower than ``FLAT_HEIGHT`` or than ``FLAT_RATIO`` times its footprint's length;
* **cylinder** (upright axis): a circle fitted (algebraically, then refitted to its inliers) to the footprint of
  the side points (normals within ~27° of horizontal); its score is the share of side points on the circle whose
  normals point along the radius;
* **box** (upright): axes along the dominant direction of the side normals, faces at the footprint's extents; its
  score is the share of side points on a face whose normals are across that face (within 15°);
* **sphere**: a sphere fitted to all points; its score is the share of points on it with radial normals.

When hardly any side is visible (seen from above) the footprint decides between box and cylinder: a rectangle
fills its minimum-area rectangle, a circle only pi/4 of it. The best score wins; the confidence is that score
scaled by its margin over the runner-up: ``best * (0.5 + 0.5 * (best - second) / best)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.cloud_expert import CloudExpert
from annotators.geometry.support_frame import sampled_indices, support_frame, usable_plane
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, Normals, ObjectHypothesis, Plane, PointCloud, Shape

SHAPES: tuple[str, ...] = ("box", "cylinder", "sphere", "flat")
"""Every shape name this annotator reports (the ontology's shape classes, lower case)."""

FLAT_HEIGHT = 0.025
"""Objects lower than this (metres) are flat."""

FLAT_RATIO = 0.15
"""Objects lower than this fraction of their footprint's length are flat."""

SIDE_NORMAL_Z = 0.45
"""Normals whose vertical component is below this (in magnitude) belong to the sides."""

RADIAL_COSINE = 0.85
"""A normal counts as radial (cylinder, sphere) when its cosine with the radius is above this."""

EDGE_COSINE = float(np.cos(np.radians(15.0)))
"""A side normal counts as perpendicular to a box edge when its cosine with the edge normal is above this."""


@dataclass(frozen=True)
class ShapeFit:
    """The winning shape, its confidence and every model's score (share of points the model explains)."""

    shape: str
    confidence: float
    scores: Mapping[str, float] = field(default_factory=dict)


def _quantile(values: np.ndarray, q: float) -> float:
    ordered = np.sort(values)
    return float(ordered[round(q * (ordered.size - 1))])


def circle_fit(xy: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the least-squares (Kasa) circle through Nx2 points, None when degenerate."""
    if xy.shape[0] < 3:
        return None
    design = np.column_stack([xy, np.ones(xy.shape[0])])
    solution, *_ = np.linalg.lstsq(design, (xy**2).sum(axis=1), rcond=None)
    centre = solution[:2] / 2
    squared = solution[2] + centre @ centre
    return (centre, float(np.sqrt(squared))) if squared > 0 and np.all(np.isfinite(centre)) else None


def sphere_fit(points: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the least-squares sphere through Nx3 points, None when degenerate."""
    if points.shape[0] < 4:
        return None
    design = np.column_stack([points, np.ones(points.shape[0])])
    solution, *_ = np.linalg.lstsq(design, (points**2).sum(axis=1), rcond=None)
    centre = solution[:3] / 2
    squared = solution[3] + centre @ centre
    return (centre, float(np.sqrt(squared))) if squared > 0 and np.all(np.isfinite(centre)) else None


def _radial(offsets: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Whether each normal is (anti)parallel to its offset from the centre, within RADIAL_COSINE."""
    lengths = np.linalg.norm(offsets, axis=1) * np.linalg.norm(normals, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.abs(np.einsum("ij,ij->i", offsets, normals)) > RADIAL_COSINE * lengths


def cylinder_score(xy: np.ndarray, normals_xy: np.ndarray, length: float) -> float:
    """Share of side points (footprint ``xy``, horizontal normals) on an upright cylinder fitting the footprint."""
    inliers = np.ones(xy.shape[0], dtype=bool)
    score = 0.0
    for _ in range(3):
        fit = circle_fit(xy[inliers])
        if fit is None:
            return 0.0
        centre, radius = fit
        if radius < 0.01 or 2 * radius > 1.4 * length + 0.01:
            return 0.0
        offsets = xy - centre
        residual = np.abs(np.linalg.norm(offsets, axis=1) - radius)
        inliers = (residual < max(0.004, 0.08 * radius)) & _radial(offsets, normals_xy)
        score = float(np.count_nonzero(inliers)) / xy.shape[0]
        if np.count_nonzero(inliers) < 3:
            return score
    return score


def dominant_yaw(normals_xy: np.ndarray) -> float:
    """The yaw (radians, modulo 90°) most horizontal normals are aligned with: the mode of their directions
    modulo 90°, refined by the circular mean of those within 15° of it."""
    quarter = np.mod(np.arctan2(normals_xy[:, 1], normals_xy[:, 0]), np.pi / 2)
    counts, edges = np.histogram(quarter, bins=18, range=(0.0, np.pi / 2))
    mode = (edges[int(np.argmax(counts))] + edges[int(np.argmax(counts)) + 1]) / 2
    offset = np.mod(quarter - mode + np.pi / 4, np.pi / 2) - np.pi / 4
    near = np.abs(offset) < np.radians(15.0)
    return float(mode + offset[near].mean()) if near.any() else float(mode)


def box_score(xy: np.ndarray, normals_xy: np.ndarray, footprint: np.ndarray, length: float) -> float:
    """Share of side points lying on a face of an upright box whose normals are across that face.

    The box's yaw is the dominant direction of the side normals; its faces are at the 2 % / 98 % extents of the
    footprint along the two axes; a side point is on a face when its normal is within 15° of the face normal and
    it lies within a tolerance of the extent its normal points to.
    """
    yaw = dominant_yaw(normals_xy)
    axes = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])
    extent = footprint @ axes.T
    low = np.array([_quantile(extent[:, 0], 0.02), _quantile(extent[:, 1], 0.02)])
    high = np.array([_quantile(extent[:, 0], 0.98), _quantile(extent[:, 1], 0.98)])
    local = xy @ axes.T
    unit = normals_xy / np.maximum(np.linalg.norm(normals_xy, axis=1, keepdims=True), 1e-9)
    cosines = unit @ axes.T
    tolerance = max(0.006, 0.05 * length)
    on_face = np.zeros(xy.shape[0], dtype=bool)
    for axis in (0, 1):
        aligned = np.abs(cosines[:, axis]) > EDGE_COSINE
        face = np.where(cosines[:, axis] > 0, high[axis], low[axis])
        on_face |= aligned & (np.abs(local[:, axis] - face) < tolerance)
    return float(np.count_nonzero(on_face)) / xy.shape[0]


def sphere_score(points: np.ndarray, normals: np.ndarray, size: float) -> float:
    """Share of points on a sphere fitted to them whose normals are radial (``size``: the object's extent)."""
    fit = sphere_fit(points)
    if fit is None:
        return 0.0
    centre, radius = fit
    if radius < 0.01 or radius > 0.8 * size + 0.01:
        return 0.0
    offsets = points - centre
    residual = np.abs(np.linalg.norm(offsets, axis=1) - radius)
    inliers = (residual < max(0.005, 0.1 * radius)) & _radial(offsets, normals)
    return float(np.count_nonzero(inliers)) / points.shape[0]


def footprint_fill(footprint: np.ndarray) -> float:
    """Area of the footprint's convex hull over that of its minimum-area rectangle (box ~1, circle ~0.785)."""
    hull = cv2.convexHull(footprint.astype(np.float32))
    (_, _), (width, depth), _ = cv2.minAreaRect(hull)
    return float(cv2.contourArea(hull)) / max(width * depth, 1e-12)


def classify_shape(points: np.ndarray, normals: np.ndarray, on_plane: bool) -> ShapeFit:
    """The shape of an object from Nx3 points and normals in an upright frame (z = 0 on the support if ``on_plane``)."""
    z = points[:, 2]
    bottom = 0.0 if on_plane else _quantile(z, 0.02)
    height = max(_quantile(z, 0.98) - bottom, 0.0)
    footprint = points[:, :2]
    (_, _), (width, depth), _ = cv2.minAreaRect(footprint.astype(np.float32))
    length = float(max(width, depth))
    if height < FLAT_HEIGHT or height < FLAT_RATIO * length:
        limit = max(FLAT_HEIGHT, FLAT_RATIO * length)
        return ShapeFit("flat", 1.0 - 0.5 * height / limit, {"flat": 1.0})
    valid = np.isfinite(normals).all(axis=1)
    points, normals = points[valid], normals[valid]
    if points.shape[0] < 10:
        return ShapeFit("box", 0.0, {})
    side = np.abs(normals[:, 2]) < SIDE_NORMAL_Z
    scores = {"sphere": sphere_score(points, normals, max(length, height))}
    if np.count_nonzero(side) >= max(20, 0.1 * points.shape[0]):
        xy, normals_xy = points[side, :2], normals[side, :2]
        scores["cylinder"] = cylinder_score(xy, normals_xy, length)
        scores["box"] = box_score(xy, normals_xy, footprint, length)
    else:  # seen from above: the footprint's outline decides
        fill = footprint_fill(footprint)
        scores["box"] = float(np.clip((fill - 0.785) / (0.95 - 0.785), 0.0, 1.0))
        scores["cylinder"] = 1.0 - scores["box"]
    ranked = sorted(scores.items(), key=lambda item: -item[1])
    (best_shape, best), (_, second) = ranked[0], ranked[1]
    confidence = best * (0.5 + 0.5 * (best - second) / best) if best > 0 else 0.0
    return ShapeFit(best_shape, float(confidence), dict(scores))


class ShapeAnnotator(CloudExpert):
    """Attaches a Shape (box, cylinder, sphere or flat, with a confidence) to every object hypothesis.

    Measures in the supporting plane's frame when there is a Plane, else in the world frame when the camera pose
    is known, else assumes an upright camera (confidence halved).
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, PointCloud, Normals)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Shape,)
    purpose: ClassVar[str] = "fit shapes to"
    capability: ClassVar[Capability] = Capability(
        label="shape annotator",
        shapes=("Box", "Cylinder", "Sphere", "Flat"),
        preconditions=("NeedsDepth",),
        cost_ms=12.0,
        reliability=0.75,
    )

    def __init__(self, max_points: int = 1500, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_points = max_points

    def analyse(self) -> None:
        """Fit the models to each hypothesis; fail when no hypothesis has enough valid points."""
        cloud = self.usable_cloud()
        normals = self.view(Normals).normals
        if normals.shape != cloud.points.shape:
            self.fail(f"normals {normals.shape} and point cloud {cloud.points.shape} sizes differ")
        hypotheses = self.hypotheses()
        frame = support_frame(usable_plane(self.annotations(Plane)), self.optional_view(CameraInfo))
        flat_points, flat_normals = cloud.points.reshape(-1, 3), normals.reshape(-1, 3)
        fitted = 0
        for hypothesis in hypotheses:
            indices = sampled_indices(cloud, hypothesis, self.max_points)
            if indices.size < 10:
                continue
            points = frame.points(flat_points[indices].astype(np.float64))
            fit = classify_shape(points, frame.directions(flat_normals[indices].astype(np.float64)), frame.on_plane)
            confidence = fit.confidence * (0.5 if frame.guessed else 1.0)
            self.attach(hypothesis, Shape(shape=fit.shape, confidence=confidence))
            fitted += 1
        if fitted == 0:
            self.fail("no object hypothesis has enough valid points to fit a shape")
