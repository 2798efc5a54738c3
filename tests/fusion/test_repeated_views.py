"""Repeated views (reasoning/fusion/views.py): a static object seen again from the same camera place, in the same
recording, at the same image box is one piece of evidence, not N; a moved camera, a moved object or another
recording is a new view and adds evidence as before. The same on every update path (row-level, general, write-behind).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence, logit, repeated_log_odds, sigmoid
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief, TrackerConfig
from reasoning.fusion.views import SAME_BOX_IOU, box_iou, repeats_view

BOX = (200, 150, 300, 250)
"""A mug's image box (100 x 100 pixels)."""


class GeneralTracker(BeliefTracker):
    """The plain tracker, under another type: the store updates its beliefs the general way (decoded beliefs)."""


def sighting(
    roi: tuple[int, int, int, int] | None = BOX,
    recording: str = "kitchen",
    position: tuple[float, float, float] = (0.5, 0.2, 0.8),
    experts: tuple[str, ...] = ("Detector",),
) -> FrameObject:
    """One mug seen at ``roi``: class Mug 0.7 from each of ``experts``, colour red 0.6."""
    evidence = [Evidence("class", "Mug", 0.7, e) for e in experts] + [Evidence("color", "red", 0.6, "Colors")]
    return FrameObject(
        position=np.array(position),
        frame="world",
        dimensions=np.array([0.1, 0.08, 0.08]),
        evidence=evidence,
        sources={*experts, "Colors"},
        roi=roi,
        recording=recording,
    )


def fuse(
    path: Path, frames: list[FrameObject], tracker: BeliefTracker | None = None, write_behind: int = 0
) -> ObjectBelief:
    """The one belief ``frames`` (one sighting each, 0.5 s apart) leave in a new store."""
    with BeliefStore(path, tracker=tracker, write_behind=write_behind) as store:
        for index, frame in enumerate(frames):
            store.integrate([frame], 10.0 + 0.5 * index, wait=True)
        (belief,) = store.beliefs()
    assert belief is not None
    return belief


def class_confidence(belief: ObjectBelief) -> float:
    return belief.fused()["class"].confidence


@pytest.mark.parametrize("path_kind", ["rows", "general", "write-behind"])
def test_identical_sightings_are_one_view_on_every_update_path(tmp_path: Path, path_kind: str) -> None:
    tracker = GeneralTracker() if path_kind == "general" else None
    write_behind = 1 if path_kind == "write-behind" else 0
    repeated = fuse(tmp_path / "same.sqlite", [sighting()] * 10, tracker, write_behind)
    assert class_confidence(repeated) == pytest.approx(0.7)  # today's 0.999
    assert repeated.fused()["color"].confidence == pytest.approx(0.6)
    assert repeated.observations == 10 and repeated.attributes["class"].values["Mug"].count == 10
    # the object is still there, but ten looks at one view are no surer of it than one look
    assert repeated.confidence == pytest.approx(sigmoid(TrackerConfig().hit_log_odds))
    boxes = [(200 + 40 * (i % 2), 150, 300 + 40 * (i % 2), 250) for i in range(10)]  # the camera moves to and fro
    independent = fuse(tmp_path / "moved.sqlite", [sighting(box) for box in boxes], tracker, write_behind)
    assert class_confidence(independent) > 0.99
    assert independent.confidence > 0.99


def test_a_box_within_segmentation_jitter_is_the_same_view(tmp_path: Path) -> None:
    jittered = [BOX, (203, 148, 302, 251), (198, 152, 297, 249), (201, 151, 304, 248)]
    assert min(box_iou(BOX, b) for b in jittered) >= SAME_BOX_IOU
    belief = fuse(tmp_path / "jitter.sqlite", [sighting(b) for b in jittered])
    assert class_confidence(belief) == pytest.approx(0.7)


@pytest.mark.parametrize(
    "second",
    [
        sighting((240, 150, 340, 250)),  # the camera turned: the mug moved 40 % of its width in the image
        sighting(position=(0.52, 0.2, 0.8), roi=(230, 150, 330, 250)),  # the mug was moved (2 cm, 30 pixels)
        sighting(recording="kitchen-2"),  # another recording: another occasion, whatever the box
        sighting(roi=None),  # no image box: nothing tells the views apart
    ],
    ids=["camera moved", "object moved", "other recording", "no box"],
)
def test_a_new_viewpoint_adds_evidence_as_an_independent_view(tmp_path: Path, second: FrameObject) -> None:
    belief = fuse(tmp_path / "two.sqlite", [sighting(), second])
    assert class_confidence(belief) == pytest.approx(sigmoid(2 * logit(0.7)))  # 0.845, as before repeats
    assert belief.confidence == pytest.approx(sigmoid(2 * TrackerConfig().hit_log_odds))


def test_a_repeat_after_new_views_keeps_what_they_gave_and_new_experts_in_it_count(tmp_path: Path) -> None:
    frames = [sighting(), sighting((240, 150, 340, 250)), sighting((240, 150, 340, 250))]
    belief = fuse(tmp_path / "three.sqlite", frames)
    assert class_confidence(belief) == pytest.approx(sigmoid(2 * logit(0.7)))  # two views, the third repeats one
    more = fuse(tmp_path / "experts.sqlite", [sighting(), sighting(experts=("Detector", "Detector2"))])
    # the repeated view holds two experts' statements: what that view says (both of them), not three statements
    assert class_confidence(more) == pytest.approx(sigmoid(2 * logit(0.7)))
    assert more.attributes["class"].values["Mug"].sources == {"Detector", "Detector2"}


def test_existence_after_misses_comes_back_to_one_sighting_when_the_view_repeats() -> None:
    tracker = BeliefTracker()
    belief = tracker.create(sighting(), 0.0, 1)
    belief.existence = -1.0  # missed a few times (occluded)
    tracker.update(belief, sighting(), 1.0)
    assert belief.existence == pytest.approx(TrackerConfig().hit_log_odds)
    assert belief.misses == 0 and belief.status == "present"


def test_dependent_evidence_takes_the_stronger_view_and_sums_disagreement() -> None:
    assert repeated_log_odds(1.0, 2.0) == 2.0 and repeated_log_odds(2.0, 1.0) == 2.0
    assert repeated_log_odds(-1.0, -2.0) == -2.0 and repeated_log_odds(-2.0, -1.0) == -2.0
    assert repeated_log_odds(1.5, -0.5) == pytest.approx(1.0)  # the same view now says less: both count
    assert repeated_log_odds(6.0, 6.0) == 6.0
    assert repeated_log_odds(-6.5, 2.0) == pytest.approx(-4.5)
    assert math.isclose(repeated_log_odds(0.0, logit(0.7)), logit(0.7))


def test_a_view_repeats_only_in_the_same_frame_recording_and_box() -> None:
    assert repeats_view(BOX, "world", "r", BOX, "world", "r")
    assert not repeats_view(BOX, "world", "r", BOX, "camera", "r")
    assert not repeats_view(BOX, "world", "r", BOX, "world", "s")
    assert not repeats_view(None, "world", "r", BOX, "world", "r")
    assert not repeats_view(BOX, "world", "r", (300, 150, 400, 250), "world", "r")
    assert box_iou(BOX, (300, 150, 400, 250)) == 0.0
