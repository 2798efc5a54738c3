"""What a person points at: the arm's 3-D ray intersected with the object hypotheses or the map's regions.

The ray has the pointing arm's shoulder-to-wrist direction and starts at the wrist; the elbow-to-wrist direction
is a second estimate, and the angle between the two (``spread``) says how well the arm pose is known. Objects are
the frame's object hypotheses that are not part of a person (their centroid from the cloud); regions are the
semantic-map boxes the plan hands over (world frame, so they need the camera pose). The target is the candidate
with the least angle between the ray and the direction to it (for a region: to its nearest point to the ray);
the confidence falls with that angle and rises with the margin to the next-best candidate.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from annotators.people.keypoints import Arm, angle, arms
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import (
    Activity,
    BodyKeypoints,
    CameraInfo,
    CasType,
    ObjectHypothesis,
    PersonHypothesis,
    PointCloud,
    PointingTarget,
)

TARGET_KINDS: tuple[str, ...] = ("object", "region")


@dataclass(frozen=True)
class Ray:
    """A pointing ray: ``origin``, unit ``direction`` and the unit ``second`` (elbow-to-wrist) estimate."""

    origin: np.ndarray
    direction: np.ndarray
    second: np.ndarray

    @property
    def spread(self) -> float:
        """The angle between the two estimates, radians."""
        return angle(self.direction, self.second)


def arm_ray(arm: Arm) -> Ray:
    """The ray of a pointing arm: shoulder through wrist, and elbow through wrist as the second estimate."""
    reach = arm.wrist - arm.shoulder
    fore = arm.wrist - arm.elbow
    if np.linalg.norm(fore) < 1e-6:
        fore = reach
    return Ray(arm.wrist, reach / np.linalg.norm(reach), fore / np.linalg.norm(fore))


def box_point_nearest_ray(ray: Ray, pose: np.ndarray, size: np.ndarray, reach: float = 6.0) -> np.ndarray:
    """The point of a box (4x4 pose of its centre, full size) nearest to the ray within ``reach`` metres."""
    half = np.asarray(size, dtype=np.float64) / 2
    rotation, centre = pose[:3, :3], pose[:3, 3]
    steps = np.linspace(0.0, reach, 241)[:, None]
    along = ray.origin + steps * ray.direction
    local = (along - centre) @ rotation
    clamped = np.clip(local, -half, half)
    distances = np.linalg.norm(local - clamped, axis=1)
    nearest = int(np.argmin(distances))
    return centre + rotation @ clamped[nearest]


def segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The distance of a point from the segment a-b."""
    ab = b - a
    t = float(np.clip(np.dot(point - a, ab) / max(float(np.dot(ab, ab)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(point - (a + t * ab)))


def segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The distance of each of the Nx3 points from the segment a-b."""
    ab = b - a
    t = np.clip((points - a) @ ab / max(float(np.dot(ab, ab)), 1e-12), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def ranked(ray: Ray, candidates: Sequence[tuple[str, np.ndarray]]) -> list[tuple[float, str, np.ndarray]]:
    """Candidates (name, point) by the angle between the ray and the direction from its origin to the point (the
    nearer first among equal angles: of two regions the ray passes through, the one it enters first)."""
    scored = [(angle(ray.direction, p - ray.origin), name, p) for name, p in candidates]
    return sorted(scored, key=lambda item: (round(item[0], 6), float(np.linalg.norm(item[2] - ray.origin))))


def confidence(error: float, margin: float, spread: float, pointing: float) -> float:
    """How sure the choice is: falls with the angular error, rises with the margin to the next candidate, both
    relative to the arm's uncertainty (at least 6 degrees), times how surely the person points."""
    sigma = max(math.radians(6.0), spread)
    return float(pointing * math.exp(-0.5 * (error / sigma) ** 2) * min(1.0, margin / sigma))


class PointingEstimator(Annotator):
    """Finds what a pointing person points at: a 3-D arm ray against the object hypotheses or the map's regions."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PersonHypothesis, BodyKeypoints, Activity, PointCloud)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, CameraInfo)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PointingTarget,)
    capability: ClassVar[Capability] = Capability(
        label="pointing estimator",
        synonyms=("pointing gesture estimator", "deictic gesture estimator"),
        cost_ms=2.0,
        reliability=0.85,
    )

    def __init__(
        self,
        target: str = "object",
        regions: Sequence[Mapping[str, object]] = (),
        max_error_degrees: float = 20.0,
        body_clearance: float = 0.08,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        if target not in TARGET_KINDS:
            raise ValueError(f"pointing target must be one of {', '.join(TARGET_KINDS)}, not {target!r}")
        self.target = target
        self.regions = tuple(regions)
        self.max_error = math.radians(max_error_degrees)
        self.body_clearance = body_clearance

    def analyse(self) -> None:
        """Write the PointingTarget of the most surely pointing person."""
        pointing = self._pointing_person()
        if pointing is None:
            self.fail("no person with body keypoints is pointing")
        person, arm, score = pointing
        ray = arm_ray(arm)
        if self.target == "object":
            candidates, rois = self._objects(person)
        else:
            candidates, rois = self._regions(ray), {}
        if not candidates:
            self.fail(f"no {self.target} to point at is in view")
        order = ranked(ray, candidates)
        error, name, aimed = order[0]
        if error > self.max_error:
            self.fail(f"the person points at no {self.target}: the nearest, {name}, is {math.degrees(error):.0f}° off")
        margin = order[1][0] - error if len(order) > 1 else math.pi
        self.write(
            PointingTarget(
                kind=self.target,
                origin=ray.origin,
                direction=ray.direction,
                second_direction=ray.second,
                point=aimed,
                angular_error=error,
                spread=ray.spread,
                margin=margin,
                name=name if self.target == "region" else "",
                roi=rois.get(name),
                confidence=confidence(error, margin, ray.spread, score),
            )
        )

    def _pointing_person(self) -> tuple[PersonHypothesis, Arm, float] | None:
        best: tuple[PersonHypothesis, Arm, float] | None = None
        for person in self.annotations(PersonHypothesis):
            activities = [a for a in self.attached(person, Activity) if a.activity == "pointing"]
            keypoints = self.attached(person, BodyKeypoints)
            if not activities or not keypoints:
                continue
            activity = max(activities, key=lambda a: a.confidence)
            found = [a for a in arms(keypoints[0]) if a.side == activity.arm]
            if found and (best is None or activity.confidence > best[2]):
                best = (person, found[0], activity.confidence)
        return best

    def _objects(self, person: PersonHypothesis) -> tuple[list[tuple[str, np.ndarray]], dict[str, tuple]]:
        """The centroids of the object hypotheses that are not part of the person (not mostly within
        ``body_clearance`` of its arms' bones), named by their index."""
        points = self.view(PointCloud).points.reshape(-1, 3)
        keypoints = self.attached(person, BodyKeypoints)
        bones = [
            (a, b + 0.12 * (b - a) / max(float(np.linalg.norm(b - a)), 1e-9) if b is arm.wrist else b)
            for arm in (arms(keypoints[0]) if keypoints else [])
            for a, b in ((arm.shoulder, arm.elbow), (arm.elbow, arm.wrist))
        ]
        candidates, rois = [], {}
        for number, hypothesis in enumerate(self.annotations(ObjectHypothesis)):
            if isinstance(hypothesis, PersonHypothesis) or not hypothesis.point_indices.size:
                continue
            own = points[hypothesis.point_indices]
            own = own[np.isfinite(own[:, 2])]
            if not own.shape[0]:
                continue
            sample = own[:: max(1, own.shape[0] // 500)]
            near = np.zeros(sample.shape[0], dtype=bool)
            for a, b in bones:
                near |= segment_distances(sample, a, b) < self.body_clearance
            if bones and np.mean(near) > 0.5:
                continue  # most of it lies on the arm: the hand or forearm, segmented as an object
            centre = own.mean(axis=0)
            key = f"hypothesis {number}"
            candidates.append((key, centre))
            rois[key] = hypothesis.roi
        return candidates, rois

    def _regions(self, ray: Ray) -> list[tuple[str, np.ndarray]]:
        """Each region's point nearest to the ray, in the camera frame (needs the camera pose)."""
        info = self.optional_view(CameraInfo)
        if info is None or info.cam_to_world is None or not self.regions:
            return []
        to_world = np.asarray(info.cam_to_world, dtype=np.float64)
        to_camera = np.linalg.inv(to_world)
        world = Ray(to_world[:3, :3] @ ray.origin + to_world[:3, 3], to_world[:3, :3] @ ray.direction, ray.second)
        found = []
        for region in self.regions:
            pose = np.asarray(region["box_pose"], dtype=np.float64).reshape(4, 4)
            nearest = box_point_nearest_ray(world, pose, np.asarray(region["box_size"], dtype=np.float64))
            found.append((str(region["region"]), to_camera[:3, :3] @ nearest + to_camera[:3, 3]))
        return found
