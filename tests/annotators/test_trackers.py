"""HumanTracker and ObjectTracker in a looped pipeline: a scripted frame source writes one frame's hypotheses per
run (a person walking past a standing one, detections noisy and sometimes missing); the tracker follows the
walker in the world frame with its image position, and the object tracker follows only what the query describes."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from annotators.tracking.human_tracker import HumanTracker
from annotators.tracking.object_tracker import ObjectTracker
from robokudo.core.annotator import Annotator
from robokudo.core.loop import Loop
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import (
    CameraInfo,
    CameraIntrinsics,
    CasType,
    Classification,
    ObjectHypothesis,
    PersonHypothesis,
    PersonTrack,
    Pose,
    SemanticColor,
    TargetTrack,
)

INTRINSICS = CameraIntrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
CAM_TO_WORLD = np.array([[1.0, 0, 0, 0.5], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])


class ScriptedFrames(Annotator):
    """Writes the next scripted frame: camera info and hypotheses (camera-frame positions)."""

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, PersonHypothesis, ObjectHypothesis)

    def __init__(self, frames: list[tuple[float, list[ObjectHypothesis]]]) -> None:
        super().__init__(name="frames")
        self.frames = frames

    def analyse(self) -> None:
        stamp, hypotheses = self.frames.pop(0)
        self.write(CameraInfo(intrinsics=INTRINSICS, cam_to_world=CAM_TO_WORLD, timestamp=stamp))
        for hypothesis in hypotheses:
            self.write(hypothesis)


def hypothesis(kind: type[ObjectHypothesis], position: np.ndarray, *extra: object) -> ObjectHypothesis:
    u, v = INTRINSICS.project(position)[0]
    roi = (int(u) - 10, int(v) - 10, int(u) + 10, int(v) + 10)
    made = kind(point_indices=np.zeros(0, dtype=int), mask=np.zeros((1, 1), bool), roi=roi, confidence=0.8)
    made.annotations.append(Pose(position=position, orientation=np.array([0.0, 0, 0, 1])))
    made.annotations.extend(extra)  # type: ignore[arg-type]
    return made


def run_loop(tracker: Annotator, frames: list[tuple[float, list[ObjectHypothesis]]]) -> list[TargetTrack]:
    pipeline = Pipeline("every frame", [ScriptedFrames(frames), tracker])
    loop = Loop("track", pipeline)
    tracks = []
    for _ in range(len(frames)):
        loop.tick_once()
        tracks.append(pipeline.cas.annotations(TargetTrack)[0])
    return tracks


@pytest.mark.parametrize("seed", range(3))
def test_the_human_tracker_follows_the_walker_past_a_standing_person(seed: int) -> None:
    rng = np.random.default_rng(seed)
    frames, truth = [], []
    for step in range(90):
        t = 1000.0 + step / 15.0
        walker = np.array([-1.5 + 1.0 * step / 15.0 * 0.5, 0.0, 3.0])  # 0.5 m/s along x
        standing = np.array([0.4, 0.0, 3.8])  # 0.8 m behind the path
        seen = step == 0 or rng.random() > 0.2
        people = [hypothesis(PersonHypothesis, standing + rng.normal(0, 0.03, 3))]
        if seen:
            people.append(hypothesis(PersonHypothesis, walker + rng.normal(0, 0.04, 3)))
        if step == 0:
            people = people[::-1]  # the walker is the more confident first sighting
            people[0].confidence = 0.9
        frames.append((t, people))
        truth.append(walker + CAM_TO_WORLD[:3, 3])
    tracks = run_loop(HumanTracker(), frames)
    assert all(isinstance(t, PersonTrack) and t.frame == "world" and t.target == "Human" for t in tracks)
    errors = [np.linalg.norm(t.position - w) for t, w in zip(tracks, truth, strict=True)]
    assert np.median(errors) < 0.06 and max(errors) < 0.25, (np.median(errors), max(errors))
    misses = [i for i, (_, people) in enumerate(frames) if len(people) == 1]
    assert all(not tracks[i].seen and tracks[i].unseen_for > 0 for i in misses)
    assert all(tracks[i].seen and tracks[i].unseen_for == 0 for i in range(len(frames)) if i not in misses)
    last = tracks[-1]
    u, v = INTRINSICS.project(last.position - CAM_TO_WORLD[:3, 3])[0]
    assert last.pixel == pytest.approx((u, v))


def test_the_object_tracker_locks_onto_and_follows_only_the_described_object() -> None:
    blue, red = SemanticColor(color="blue"), SemanticColor(color="red")
    cup = Classification(class_name="Cup", confidence=0.9)
    frames = []
    for step in range(20):
        moving = np.array([0.01 * step, 0.0, 1.0])  # the blue cup slides; a red cup stands beside it
        frames.append(
            (
                5.0 + step / 10.0,
                [
                    hypothesis(ObjectHypothesis, np.array([0.02 + 0.01 * step, 0.0, 1.0]), red, cup),
                    hypothesis(ObjectHypothesis, moving, blue, cup),
                ],
            )
        )
    tracker = ObjectTracker(target_classes=("Cup", "PaperCup"), target_values={"color": ["Blue"]})
    tracks = run_loop(tracker, frames)
    assert all(t.seen for t in tracks)
    assert all(
        any(isinstance(a, SemanticColor) and a.color == "blue" for a in t.hypothesis.annotations) for t in tracks
    )
    assert tracks[-1].position[0] == pytest.approx(0.19 + 0.5, abs=0.03)
    with pytest.raises(ValueError, match="cannot match weight"):
        ObjectTracker(target_values={"weight": ["heavy"]})


def test_without_a_candidate_the_track_says_not_seen_and_has_no_position() -> None:
    nowhere = PersonHypothesis(point_indices=np.zeros(0, dtype=int), mask=np.zeros((1, 1), bool), roi=(0, 0, 1, 1))
    (track,) = run_loop(HumanTracker(), [(1.0, [nowhere])])  # a person without a position is no candidate
    assert not track.seen and track.pixel is None and np.isnan(track.position).all()
