"""A query for N objects ("find a cup": ``max_results: 1``) answers the N most likely to be what was asked, not the
N stored first: from memory and from the frame the tree just saw."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import numpy as np
from py_trees.common import Status

from reasoning.beliefs.answer import answer_from_memory
from reasoning.beliefs.ranking import best_first, match_probability
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import (
    CameraInfo,
    CameraIntrinsics,
    CasType,
    Classification,
    ObjectHypothesis,
    Pose,
    QueryAnswer,
)
from trees.answer_step import AnswerStep

SUBCLASSES = {("PaperCup", "Cup")}


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


def thing(x: float, *evidence: Evidence) -> FrameObject:
    return FrameObject(
        position=np.array([x, 0.0, 1.0]), frame="world", evidence=list(evidence), sources={"Seg"}, confidence=0.9
    )


def stored(path: Path, *objects: FrameObject) -> None:
    with BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass)) as store:
        store.integrate(list(objects), 1.0)


def test_a_singular_query_answers_the_likeliest_cup_not_the_first_stored(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(
        path,
        thing(0.0, Evidence("class", "Cup", 0.55, "Classifier")),  # id 1: barely a cup
        thing(1.0, Evidence("class", "Cup", 0.95, "Classifier")),  # id 2: surely one
    )
    with BeliefStore(path) as store:
        (best,) = answer_from_memory(store, BeliefFilter(object_class="Cup", limit=1)).objects
        both = answer_from_memory(store, BeliefFilter(object_class="Cup")).objects
    assert best.id == 2
    assert [o.id for o in both] == [1, 2]  # no limit: every cup, most confident first (equal here), then by id


def test_a_subclass_counts_for_the_asked_class(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(
        path,
        thing(0.0, Evidence("class", "Cup", 0.6, "Classifier")),
        thing(1.0, Evidence("class", "PaperCup", 0.9, "Classifier")),
    )
    with BeliefStore(path) as store:
        (best,) = answer_from_memory(store, BeliefFilter(object_class="Cup", class_test=is_subclass, limit=1)).objects
    assert best.id == 2 and best.class_label == "paper cup"


def test_an_asked_colour_ranks_like_the_class(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(
        path,
        thing(0.0, Evidence("class", "Cup", 0.9, "C"), Evidence("color", "red", 0.6, "Colour")),
        thing(1.0, Evidence("class", "Cup", 0.9, "C"), Evidence("color", "Red", 0.95, "Colour")),
        thing(2.0, Evidence("class", "Cup", 0.99, "C"), Evidence("color", "blue", 0.99, "Colour")),
    )
    with BeliefStore(path) as store:
        wanted = BeliefFilter(object_class="Cup", attributes={"color": "red"}, limit=2)
        answer = answer_from_memory(store, wanted).objects
        cups = store.query(BeliefFilter(object_class="Cup"))
    assert [o.id for o in answer] == [2, 1]
    assert match_probability(cups[2], wanted) == 0.0  # never said to be red
    assert [b.id for b in best_first(cups, wanted)] == [2, 1]


class TwoCups(Annotator):
    """Writes two cup hypotheses side by side: the first barely a cup, the second surely one."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, ObjectHypothesis, Pose, Classification)

    def analyse(self) -> None:
        intrinsics = CameraIntrinsics(fx=500.0, fy=500.0, cx=32.0, cy=24.0, width=64, height=48)
        self.write(CameraInfo(intrinsics=intrinsics, cam_to_world=np.eye(4), timestamp=5.0))
        for index, confidence in enumerate((0.55, 0.95)):
            mask = np.zeros((48, 64), bool)
            mask[10:20, 10 + 30 * index : 20 + 30 * index] = True
            hypothesis = ObjectHypothesis(
                point_indices=np.flatnonzero(mask), mask=mask, roi=(10 + 30 * index, 10, 20 + 30 * index, 20)
            )
            self.write(hypothesis)
            position = np.array([0.3 * index, 0.0, 1.0])
            self.attach(hypothesis, Pose(position=position, orientation=np.array([0.0, 0.0, 0.0, 1.0])))
            self.attach(hypothesis, Classification(class_name="Cup", confidence=confidence, source="Detector"))


def test_the_answer_step_answers_the_likeliest_cup_it_sees(tmp_path: Path) -> None:
    step = AnswerStep(tmp_path / "beliefs.sqlite", belief_filter=BeliefFilter(object_class="Cup", limit=1))
    root = Pipeline("perceive", [TwoCups(name="TwoCups"), step])
    assert Engine(root).tick() is Status.SUCCESS
    (cup,) = root.cas.view(QueryAnswer).answer.objects
    assert cup.roi == (40, 10, 50, 20) and cup.attributes["class"].confidence > 0.9
    step.shutdown()
