"""Depth-only people detection: person-sized columns standing on the ground, found on the organized cloud.

1. The ground is the dominant plane facing up (the world's up when the camera pose is known, else the image's
   up, the camera's -y) among the lower half of the image.
2. Every point gets its height above the ground and its foot on the ground plane; a height map (the highest
   point per ground cell) marks person-height cells and drops cells of taller structures (walls, shelves).
3. Heads are local maxima of the height map at person height, at least ``head_separation`` apart; each point
   between ``min_height`` and the head joins the nearest head whose column (``column_radius``) it stands in.
4. A person is a column with enough points that reaches from near the legs up to its head.

Each person becomes a :class:`PersonHypothesis` with its point indices, image mask and ROI, a Pose at the
centroid of its points and the class Human.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import cv2
import numpy as np

from annotators.cloud.plane import plane_basis, plane_distances, ransac_support_plane, up_in_camera
from annotators.cloud.point_cloud import cloud_problem
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import PERSON_CLASS, CameraInfo, CasType, Classification, PersonHypothesis, PointCloud, Pose

"""The ontology class of a person."""

IMAGE_UP = np.array([0.0, -1.0, 0.0])
"""The up direction of a camera held level (optical frame: y points down)."""


@dataclass(frozen=True)
class PeopleParameters:
    """Thresholds of :func:`find_people`, in metres (heights are above the ground)."""

    ground_distance: float = 0.04
    max_ground_tilt_degrees: float = 35.0
    min_height: float = 0.15
    min_head_height: float = 1.2
    max_head_height: float = 2.1
    max_structure_height: float = 2.25
    cell: float = 0.05
    head_separation: float = 0.35
    column_radius: float = 0.4
    min_vertical_extent: float = 0.8
    min_points: int = 1500


@dataclass(frozen=True, eq=False)
class PersonSegment:
    """One person: flat point indices, an HxW mask, the ROI (x1/y1 exclusive), the head height and the centroid."""

    indices: np.ndarray
    mask: np.ndarray
    roi: tuple[int, int, int, int]
    height: float
    centroid: np.ndarray


def ground_plane(
    points: np.ndarray, mask: np.ndarray, up: np.ndarray, parameters: PeopleParameters
) -> np.ndarray | None:
    """The ground plane model (unit normal pointing up) among the lower half of the image, or None."""
    lower = mask.copy()
    lower[: points.shape[0] // 2] = False
    fit = ransac_support_plane(
        points,
        lower,
        distance=parameters.ground_distance,
        up=up,
        max_tilt_degrees=parameters.max_ground_tilt_degrees,
    )
    if fit is None:
        return None
    model = fit.model if fit.model[:3] @ up >= 0 else -fit.model
    return model


def find_people(
    points: np.ndarray, mask: np.ndarray, up: np.ndarray, parameters: PeopleParameters | None = None
) -> list[PersonSegment]:
    """The people standing on the ground in an organized cloud (camera frame), left to right in the image.

    The ground and the people are found among all valid points, since a crop of the cloud to a working range
    or region may cut the ground and people in two; a person is kept when some of its points are in ``mask``.
    """
    parameters = parameters or PeopleParameters()
    rows, cols = mask.shape
    valid = np.isfinite(points[..., 2])
    model = ground_plane(points, valid, up, parameters)
    if model is None:
        return []
    with np.errstate(invalid="ignore"):
        height = plane_distances(points, model)
        standing = valid & np.isfinite(height) & (height > parameters.min_height)
    flat = np.flatnonzero(standing)
    if flat.size < parameters.min_points:
        return []
    xyz = points.reshape(-1, 3)[flat]
    h = height.reshape(-1)[flat]
    feet = xyz @ plane_basis(model[:3]).T.astype(np.float32)  # Nx2 ground coordinates
    origin = feet.min(axis=0)
    cells = ((feet - origin) / np.float32(parameters.cell)).astype(np.int64)
    shape = (int(cells[:, 0].max()) + 1, int(cells[:, 1].max()) + 1)
    cell_index = cells[:, 0] * shape[1] + cells[:, 1]
    top = np.zeros(shape[0] * shape[1], dtype=np.float32)
    np.maximum.at(top, cell_index, h)
    top = top.reshape(shape)
    tall = top > parameters.max_structure_height
    reach = max(1, round(parameters.column_radius / parameters.cell))
    tall = cv2.dilate(tall.astype(np.uint8), np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)) > 0
    person_top = np.where(tall | (top > parameters.max_head_height), 0.0, top)
    heads = _heads(person_top, parameters)
    if not heads:
        return []
    # each ground cell joins the nearest head whose column it lies in (-1: none); points take their cell's head
    grid = np.indices(shape).reshape(2, -1).T
    squared = ((grid[:, None, :] - np.array(heads)[None, :, :]) ** 2).sum(axis=2)
    cell_head = np.argmin(squared, axis=1)
    cell_head[squared[np.arange(grid.shape[0]), cell_head] * parameters.cell**2 >= parameters.column_radius**2] = -1
    heads_height = np.array([person_top[i, j] for i, j in heads], dtype=np.float32)
    label = cell_head[cell_index]
    label[(label >= 0) & (h > heads_height[label] + parameters.cell)] = -1  # above the head: not this person
    order = np.argsort(label, kind="stable")
    bounds = np.searchsorted(label[order], np.arange(len(heads) + 1))
    people: list[PersonSegment] = []
    for number, head_height in enumerate(heads_height):
        member = order[bounds[number] : bounds[number + 1]]
        if member.size < parameters.min_points:
            continue
        if head_height - np.percentile(h[member], 2) < parameters.min_vertical_extent:
            continue
        indices = np.sort(flat[member])
        if not mask.reshape(-1)[indices].any():
            continue  # no part of this person is where the search looks
        person_mask = np.zeros(rows * cols, dtype=bool)
        person_mask[indices] = True
        person_mask = person_mask.reshape(rows, cols)
        r, c = np.divmod(indices, cols)
        roi = (int(c.min()), int(r.min()), int(c.max()) + 1, int(r.max()) + 1)
        centroid = xyz[member].mean(axis=0, dtype=np.float64)
        people.append(PersonSegment(indices, person_mask, roi, float(head_height), centroid))
    return sorted(people, key=lambda p: p.roi[0])


def _heads(top: np.ndarray, parameters: PeopleParameters) -> list[tuple[int, int]]:
    """Height-map cells that are the highest at person height within ``head_separation``, highest first."""
    radius = max(1, round(parameters.head_separation / parameters.cell))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    smooth = cv2.GaussianBlur(top.astype(np.float32), (3, 3), 0)
    local_max = cv2.dilate(smooth, kernel)
    candidates = np.argwhere((smooth >= local_max) & (top >= parameters.min_head_height))
    order = np.argsort(-top[candidates[:, 0], candidates[:, 1]], kind="stable")
    chosen: list[tuple[int, int]] = []
    for i, j in candidates[order]:
        if all((i - a) ** 2 + (j - b) ** 2 > radius**2 for a, b in chosen):
            chosen.append((int(i), int(j)))
    return chosen


def person_hypothesis(segment: PersonSegment, source: str, confidence: float) -> PersonHypothesis:
    """A PersonHypothesis for a segment, with the Pose at its centroid and the class Human attached."""
    hypothesis = PersonHypothesis(
        point_indices=segment.indices, mask=segment.mask, roi=segment.roi, source=source, confidence=confidence
    )
    hypothesis.annotations.append(
        Pose(position=segment.centroid, orientation=np.array([0.0, 0.0, 0.0, 1.0]), source=source)
    )
    hypothesis.annotations.append(Classification(class_name=PERSON_CLASS, source=source, confidence=confidence))
    return hypothesis


class DepthPeopleDetector(Annotator):
    """Finds people in depth alone: person-sized columns standing on the ground (no colour, no model)."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PersonHypothesis,)
    capability: ClassVar[Capability] = Capability(
        label="depth people detector",
        synonyms=("ground-based people detector",),
        classes=(PERSON_CLASS,),
        preconditions=("NeedsDepth",),
        cost_ms=130.0,
        reliability=0.6,
    )

    def __init__(self, parameters: PeopleParameters | None = None, name: str | None = None) -> None:
        super().__init__(name=name)
        self.parameters = parameters or PeopleParameters()

    def analyse(self) -> None:
        """Write a PersonHypothesis per person found; fail when the ground or no person is found."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        up = up_in_camera(self.optional_view(CameraInfo))
        people = find_people(cloud.points, cloud.mask, IMAGE_UP if up is None else up, self.parameters)
        if not people:
            self.fail("no person-sized column stands on a ground plane in the cloud")
        for segment in people:
            self.write(person_hypothesis(segment, self.name, confidence=0.6))
