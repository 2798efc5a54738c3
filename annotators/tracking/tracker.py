"""What the trackers share: one target followed from run to run of a continuous task's loop.

A tracker keeps its :class:`~annotators.tracking.particle_filter.ParticleFilter` across the runs of its loop (the
node lives as long as the task's tree). Each run it turns this frame's hypotheses into candidate detections (a
3-D position each: the attached Pose, else the median of the hypothesis' points), locks onto the best candidate
on the first frame that has one, and afterwards predicts to the frame's time, associates the nearest candidate
within the gate and weights and resamples. It writes the track (:class:`~robokudo.core.types.TargetTrack`): the
estimate in the world frame when the frame carries the camera pose (else the camera frame), its image position,
whether the target was seen and for how long it has not been. Time is the frame's timestamp (CameraInfo), or
the monotonic clock when the frame has none.
"""

from __future__ import annotations

import time
from abc import ABCMeta, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from annotators.tracking.particle_filter import FilterSettings, ParticleFilter
from robokudo.core.annotator import Annotator
from robokudo.core.types import CameraInfo, ObjectHypothesis, PointCloud, Pose, TargetTrack


@dataclass(frozen=True, slots=True)
class Candidate:
    """A hypothesis of this frame that may be the target, with its camera-frame position."""

    hypothesis: ObjectHypothesis
    position: np.ndarray


class TargetTracker(Annotator, metaclass=ABCMeta):
    """Base of the trackers (see the module): subclasses say which hypotheses are candidates and which to lock on."""

    track_type: ClassVar[type[TargetTrack]] = TargetTrack
    hypothesis_type: ClassVar[type[ObjectHypothesis]] = ObjectHypothesis

    def __init__(self, settings: FilterSettings | None = None, seed: int = 0, name: str | None = None) -> None:
        super().__init__(name=name)
        self.filter = ParticleFilter(settings, np.random.default_rng(seed))
        self.last_seen: float | None = None
        self.frame = ""

    # ------------------------------------------------------------------ what subclasses decide

    @abstractmethod
    def target_name(self) -> str:
        """The class tracked ("" for any)."""

    def accepts(self, hypothesis: ObjectHypothesis) -> bool:
        """True when ``hypothesis`` may be the target (all by default)."""
        return True

    def lock_score(self, candidate: Candidate) -> float:
        """How well a candidate fits to be locked onto on the first sighting (higher is better)."""
        return candidate.hypothesis.confidence

    # ------------------------------------------------------------------ the run

    def analyse(self) -> None:
        """Predict, associate, weight, resample; write the track."""
        info = self.optional_view(CameraInfo)
        stamp = info.timestamp if info is not None and info.timestamp > 0 else time.monotonic()
        to_frame, frame = _frame_of(info)
        if self.frame and frame != self.frame:
            self.fail(f"the frames changed from {self.frame} to {frame} coordinates: the track cannot continue")
        self.frame = frame
        candidates = self.candidates()
        positions = np.array([_transform(to_frame, c.position) for c in candidates]).reshape(-1, 3)
        chosen: int | None = None
        if not self.filter.started:
            if candidates:
                chosen = max(range(len(candidates)), key=lambda i: self.lock_score(candidates[i]))
                self.filter.start(positions[chosen], stamp)
        else:
            self.filter.predict(stamp)
            chosen = self.filter.associate(positions)
            if chosen is not None:
                self.filter.update(positions[chosen])
        if chosen is not None:
            self.last_seen = stamp
        self.write(self._track(info, to_frame, stamp, None if chosen is None else candidates[chosen]))

    def candidates(self) -> list[Candidate]:
        """This frame's hypotheses of the tracker's type that it accepts and that have a 3-D position."""
        cloud = self.optional_view(PointCloud)
        size = cloud.points.shape[0] * cloud.points.shape[1] if cloud is not None else 0
        hypotheses = self.annotations(self.hypothesis_type)
        if not hypotheses:
            self.fail(f"no {self.hypothesis_type.__name__} in this frame: nothing to follow")
        found = []
        for number, hypothesis in enumerate(hypotheses, start=1):
            indices = hypothesis.point_indices
            if cloud is not None and indices.size and (indices.min() < 0 or indices.max() >= size):
                self.fail(f"hypothesis {number}'s point indices lie outside the cloud of {size} points")
            if not self.accepts(hypothesis):
                continue
            position = _position(hypothesis, cloud)
            if position is not None:
                found.append(Candidate(hypothesis, position))
        return found

    def _track(
        self, info: CameraInfo | None, to_frame: np.ndarray, stamp: float, seen: Candidate | None
    ) -> TargetTrack:
        if not self.filter.started:
            position = velocity = np.full(3, np.nan)
            spread, pixel = float("inf"), None
        else:
            estimate = self.filter.estimate()
            position, velocity, spread = estimate.position, estimate.velocity, estimate.spread
            pixel = _pixel(info, np.linalg.inv(to_frame), position)
        return self.track_type(
            target=self.target_name(),
            seen=seen is not None,
            position=position,
            velocity=velocity,
            pixel=pixel,
            spread=spread,
            unseen_for=0.0 if self.last_seen is None else max(0.0, stamp - self.last_seen),
            hypothesis=None if seen is None else seen.hypothesis,
            frame=self.frame,
            source=self.name,
            confidence=seen.hypothesis.confidence if seen is not None else 0.0,
        )


def _frame_of(info: CameraInfo | None) -> tuple[np.ndarray, str]:
    """The transform from the camera into the tracking frame and that frame's name."""
    if info is not None and info.cam_to_world is not None:
        return np.asarray(info.cam_to_world, dtype=np.float64), "world"
    return np.eye(4), info.frame_id if info is not None else "camera"


def _transform(matrix: np.ndarray, point: np.ndarray) -> np.ndarray:
    return matrix[:3, :3] @ np.asarray(point, dtype=np.float64) + matrix[:3, 3]


def _position(hypothesis: ObjectHypothesis, cloud: PointCloud | None) -> np.ndarray | None:
    """The hypothesis' camera-frame position: its most confident Pose, else the median of its points."""
    for pose in sorted(hypothesis.find(Pose), key=lambda p: -p.confidence):
        if pose.frame == "camera" and np.all(np.isfinite(pose.position)):
            return np.asarray(pose.position, dtype=np.float64)
    if cloud is None or hypothesis.point_indices.size == 0:
        return None
    points = cloud.points.reshape(-1, 3)[hypothesis.point_indices]
    points = points[np.isfinite(points[:, 2])]
    return np.median(points, axis=0).astype(np.float64) if points.shape[0] else None


def _pixel(info: CameraInfo | None, to_camera: np.ndarray, position: np.ndarray) -> tuple[float, float] | None:
    """The image position of a tracking-frame point (None without intrinsics or behind the camera)."""
    if info is None:
        return None
    camera = _transform(to_camera, position)
    if not np.isfinite(camera).all() or camera[2] <= 0:
        return None
    u, v = info.intrinsics.project(camera)[0]
    return float(u), float(v)
