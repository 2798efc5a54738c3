"""Form features of each object hypothesis for classification: height/width ratio, a handle, an open top.

Measured on the hypothesis' points in the upright support frame (:mod:`annotators.geometry.support_frame`, z up):

* **height over width**: the height (top at the 98 % height quantile; bottom at the support, or the 2 % quantile
  without one) over the footprint's longer extent (2 % to 98 % along its principal axes);
* **handle**: the body is the circle fitted to the footprint of the lowest part (up to ``BODY_SLICE`` of the
  height), where a handle never is. A handle is a clump of points of the middle part sticking out of that circle
  by more than ``HANDLE_GAP`` of its radius, in a narrow direction (circular spread under ``HANDLE_SPREAD``),
  while the lowest part does not stick out there (a wider base is no handle);
* **open top**: seen from the camera, the far half of a closed object shows only its top (a lid, a box's top
  face); an open one shows its inside wall below the rim. The share of far-half points lower than ``RIM`` of the
  height says open (more than ``OPEN_SHARE``) or closed; how many far-half points were seen is the confidence
  (none: the top was not seen, confidence 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from annotators.cloud.cloud_expert import CloudExpert
from annotators.cloud.shape import circle_fit
from annotators.geometry.support_frame import SupportFrame, sampled_indices, support_frame, usable_plane
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, FormFeatures, ObjectHypothesis, Plane, PointCloud

BODY_SLICE = 0.2
"""The lowest part of the object (share of its height) whose footprint is taken as the body."""
HANDLE_BAND = (0.25, 0.9)
"""The part of the height (shares) where a handle is looked for."""
HANDLE_GAP = 0.25
"""A handle point lies farther than (1 + this) body radii (and at least 1 cm more) from the body's axis."""
HANDLE_SPREAD = np.radians(40.0)
"""A handle's points point in one direction: their circular standard deviation around the axis is below this."""
HANDLE_MIN_SHARE = 0.02
"""A handle holds at least this share of the middle part's points (and 8 points)."""
RIM = 0.8
"""Points lower than this share of the height, on the far half, are inside an open object."""
OPEN_SHARE = 0.3
"""Share of far-half points below the rim from which the object is open at the top."""
FAR = 0.1
"""Far-half points lie beyond the footprint's median, seen from the camera, by this share of its extent."""
FULL_EVIDENCE = 40
"""Points (far half, or handle) at which the evidence is taken as complete (confidence 1)."""


@dataclass(frozen=True)
class Form:
    """The measured form features (see the module docstring)."""

    height_to_width: float
    has_handle: bool
    handle_confidence: float
    open_top: bool
    open_confidence: float


def _extent(xy: np.ndarray) -> float:
    centred = xy - xy.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    along = centred @ axes.T
    low, high = np.quantile(along, 0.02, axis=0), np.quantile(along, 0.98, axis=0)
    return float((high - low).max())


def _circular_spread(angles: np.ndarray) -> float:
    length = float(np.hypot(np.cos(angles).mean(), np.sin(angles).mean()))
    return float(np.sqrt(-2.0 * np.log(max(length, 1e-12))))


def handle_evidence(points: np.ndarray, bottom: float, height: float) -> tuple[bool, float]:
    """Whether a handle sticks out of the body's side, and the confidence of that (see the module docstring)."""
    z = points[:, 2] - bottom
    body = points[z <= BODY_SLICE * height, :2]
    middle = points[(z >= HANDLE_BAND[0] * height) & (z <= HANDLE_BAND[1] * height), :2]
    if body.shape[0] < 10 or middle.shape[0] < 20:
        return False, 0.0
    fit = circle_fit(body)
    if fit is None:
        return False, 0.0
    centre, radius = fit
    if not np.isfinite(radius) or radius <= 0.005 or radius > 2.0 * _extent(body):
        return False, 0.0
    reach = radius + max(0.01, HANDLE_GAP * radius)
    offsets = middle - centre
    out = np.linalg.norm(offsets, axis=1) > reach
    confidence = min(1.0, middle.shape[0] / FULL_EVIDENCE)
    if np.count_nonzero(out) < max(8, HANDLE_MIN_SHARE * middle.shape[0]):
        return False, confidence
    angles = np.arctan2(offsets[out, 1], offsets[out, 0])
    if _circular_spread(angles) > HANDLE_SPREAD:
        return False, confidence
    direction = np.array([np.cos(angles).mean(), np.sin(angles).mean()])
    below = body - centre
    base_out = (np.linalg.norm(below, axis=1) > reach) & (below @ direction > 0.7 * np.linalg.norm(below, axis=1))
    if np.count_nonzero(base_out) > 0.5 * np.count_nonzero(out) * body.shape[0] / middle.shape[0]:
        return False, confidence  # the base reaches out there too: a wider object, no handle
    return True, min(1.0, np.count_nonzero(out) / 20)


def open_evidence(points: np.ndarray, bottom: float, height: float, camera_xy: np.ndarray) -> tuple[bool, float]:
    """Whether the object is open at the top, and the confidence of that (see the module docstring)."""
    xy = points[:, :2]
    centre = np.median(xy, axis=0)
    away = centre - camera_xy
    distance = float(np.linalg.norm(away))
    if distance < 1e-6:
        return False, 0.0
    away /= distance
    depth = (xy - centre) @ away
    far = depth > FAR * _extent(xy)
    if not far.any():
        return False, 0.0
    low = (points[far, 2] - bottom) < RIM * height
    share = float(np.count_nonzero(low)) / np.count_nonzero(far)
    return share > OPEN_SHARE, min(1.0, np.count_nonzero(far) / FULL_EVIDENCE)


def measure_form(points: np.ndarray, frame: SupportFrame) -> Form | None:
    """The form features of an object's Nx3 points in ``frame`` (upright); None for fewer than 20 points or no
    height or width."""
    if points.shape[0] < 20:
        return None
    z = points[:, 2]
    bottom = 0.0 if frame.on_plane else float(np.quantile(z, 0.02))
    height = float(np.quantile(z, 0.98)) - bottom
    width = _extent(points[:, :2])
    if height <= 0.0 or width <= 0.0:
        return None
    handle, handle_confidence = handle_evidence(points, bottom, height)
    camera_xy = frame.camera_to_frame[:2, 3]
    open_top, open_confidence = open_evidence(points, bottom, height, camera_xy)
    return Form(height / width, handle, handle_confidence, open_top, open_confidence)


class FormAnnotator(CloudExpert):
    """Attaches FormFeatures (height over width, a handle, an open top) to every object hypothesis.

    Measures in the supporting plane's frame when there is a Plane, else in the world frame when the camera pose
    is known, else assumes an upright camera (confidences halved).
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, PointCloud)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (FormFeatures,)
    purpose: ClassVar[str] = "measure the form of"
    capability: ClassVar[Capability] = Capability(
        label="form annotator",
        synonyms=("handle detector",),
        preconditions=("NeedsDepth",),
        cost_ms=4.0,
        reliability=0.7,
    )

    def __init__(self, max_points: int = 3000, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_points = max_points

    def analyse(self) -> None:
        """Measure each hypothesis; fail when none has enough valid points."""
        cloud = self.usable_cloud()
        hypotheses = self.hypotheses()
        frame = support_frame(usable_plane(self.annotations(Plane)), self.optional_view(CameraInfo))
        flat = cloud.points.reshape(-1, 3)
        scale = 0.5 if frame.guessed else 1.0
        measured = 0
        for hypothesis in hypotheses:
            indices = sampled_indices(cloud, hypothesis, self.max_points)
            form = measure_form(frame.points(flat[indices].astype(np.float64)), frame)
            if form is None:
                continue
            self.attach(
                hypothesis,
                FormFeatures(
                    height_to_width=form.height_to_width,
                    has_handle=form.has_handle,
                    handle_confidence=form.handle_confidence * scale,
                    open_top=form.open_top,
                    open_confidence=form.open_confidence * scale,
                    confidence=scale,
                ),
            )
            measured += 1
        if measured == 0:
            self.fail("no object hypothesis has enough valid points to measure its form")
