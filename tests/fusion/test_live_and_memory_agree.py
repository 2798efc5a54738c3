"""A robot asking twice gets one answer: a class query answered live (perceiving a frame) and the same query answered
from memory (the belief store alone) take the same beliefs, by the one rule of
:mod:`reasoning.beliefs.class_candidates` (an object whose leading class is only a guess of the asked class, shown
with "?", is counted by both)."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.answer import answer_from_memory
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker
from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder


def _object(x: float, statements: list[tuple[str, float]], frame: str = "camera") -> FrameObject:
    return FrameObject(
        position=np.array([x, 0.0, 1.0]),
        frame=frame,
        dimensions=np.array([0.07, 0.07, 0.12]),
        evidence=[Evidence("class", value, confidence, "KnowledgeClassifier", 0.0) for value, confidence in statements],
        sources={"KnowledgeClassifier"},
        recording="scene",
    )


def test_a_class_guessed_below_one_half_is_found_from_memory_and_a_supported_rival_is_not(tmp_path: Path) -> None:
    """A can stated at 0.3 (no other class stated) answers "cans" from memory; an object whose supported class is a
    mug does not, though a can was stated for it too; an object with no class stated answers to no class."""
    with BeliefStore(tmp_path / "b.sqlite") as store:
        step = store.integrate(
            [
                _object(0.0, [("CannedFood", 0.3)]),
                _object(0.5, [("Mug", 0.8), ("CannedFood", 0.3)]),
                _object(1.0, []),
            ],
            1.0,
        )
        guessed, mug, _ = step.assigned
        assert [b.id for b in store.query(BeliefFilter(object_class="CannedFood"))] == [guessed]
        assert [b.id for b in store.query(BeliefFilter(object_class="Mug"))] == [mug]
        assert store.get(guessed).class_name is None  # the guess is a candidate, never the belief's class


SUBCLASSES = {("CannedFood", "Food"), ("Mug", "Cup")}
"""A few subclass pairs, for a store that fuses with subsumption."""


def _is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


def test_a_general_class_whose_refinement_answers_is_a_candidate_everywhere_and_keeps_its_class(
    tmp_path: Path,
) -> None:
    """An object the experts called food (0.6) and, this time, canned food (0.4) answers "canned food" from memory,
    anywhere, in a region by name, in a region box and by id, named by the refinement and shown with "?"; its stored
    class stays food. An object whose supported class is unrelated (a mug) still does not answer, and a food with
    no refinement stated does not either."""
    from robokudo.core.regions import RegionBox

    box = RegionBox("shelf", "Shelf", "world", (0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0), (0.2, 0.2, 0.2))
    tracker = BeliefTracker(class_test=_is_subclass, regions=(box,))
    with BeliefStore(tmp_path / "b.sqlite", tracker=tracker) as store:
        step = store.integrate(
            [
                _object(0.0, [("Food", 0.6), ("CannedFood", 0.4)], "world"),
                _object(0.5, [("Mug", 0.8), ("CannedFood", 0.3)], "world"),
                _object(1.0, [("Food", 0.7)], "world"),
            ],
            1.0,
        )
        can, mug, food = step.assigned
        asked = BeliefFilter(object_class="CannedFood", class_test=_is_subclass)
        assert [b.id for b in store.query(asked)] == [can]
        assert [b.id for b in store.query(replace(asked, ids=(can, mug, food)))] == [can]
        assert [b.id for b in store.query(replace(asked, region="shelf", region_boxes=(box,)))] == [can]
        assert store.get(can).region == "shelf"
        assert [b.id for b in store.query(replace(asked, region="shelf"))] == [can]
        assert sorted(b.id for b in store.query(BeliefFilter(object_class="Food", class_test=_is_subclass))) == [
            can,
            food,
        ]
        assert store.get(can).class_name == "Food"
        (shown,) = answer_from_memory(store, asked).objects
        assert shown.class_label == "canned food" and shown.shown_label() == "canned food?"
        assert shown.answers is not None and 0.3 < shown.answers < 0.5


def _count(capsys: pytest.CaptureFixture, argv: list[str]) -> tuple[int, list[int]]:
    assert cli.main([*argv, "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    return answer["count"], sorted(o["id"] for o in answer["objects"])


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [0, 1])
def test_how_many_cans_live_and_from_memory_on_a_real_frame(
    capsys: pytest.CaptureFixture, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, frame: int
) -> None:
    """On a real tabletop frame the cans are classified only as guesses ("canned food?"): the live answer counts
    them, and so does the answer from memory right after (before, memory said 0 where live said 3)."""
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    uoc = require_folder(SHARED_DATA / "uoc_tabletop_realsense")
    store = str(tmp_path / "beliefs.sqlite")
    question = "how many cans are there"
    live, live_ids = _count(capsys, ["query", question, "--input", str(uoc), "--frame", str(frame), "--store", store])
    remembered, remembered_ids = _count(capsys, ["beliefs", question, "--store", store])
    assert live > 0
    assert (remembered, remembered_ids) == (live, live_ids)


def test_a_guess_is_found_in_a_named_region_in_a_box_and_anywhere(tmp_path: Path) -> None:
    """Each way of reading the store (a class anywhere, in a region by name, in a region box) finds the guessed can
    and no guess of another class or place."""
    from robokudo.core.regions import RegionBox

    with BeliefStore(tmp_path / "b.sqlite") as store:
        step = store.integrate(
            [_object(0.0, [("CannedFood", 0.3)]), _object(3.0, [("CannedFood", 0.3)]), _object(0.5, [("Jar", 0.3)])],
            1.0,
        )
        near, far, jar = step.assigned
        box = RegionBox("shelf", "Shelf", "camera", (0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0))
        assert [b.id for b in store.query(BeliefFilter(object_class="CannedFood"))] == sorted([near, far])
        assert [b.id for b in store.query(BeliefFilter(object_class="Jar"))] == [jar]
        in_box = BeliefFilter(object_class="CannedFood", region="shelf", region_boxes=(box,))
        assert [b.id for b in store.query(in_box)] == [near]
        region = store.get(near).region
        by_name = [b.id for b in store.query(BeliefFilter(object_class="CannedFood", region=region or "nowhere"))]
        assert by_name == ([near, far] if region and store.get(far).region == region else [near] if region else [])


def test_a_store_written_before_guesses_were_answered_finds_them_when_opened(tmp_path: Path) -> None:
    """A store of schema 3 never listed a guessed class among its classes; opened again it answers the guess."""
    path = tmp_path / "old.sqlite"
    with BeliefStore(path) as store:
        (guessed,) = store.integrate([_object(0.0, [("CannedFood", 0.3)])], 1.0).assigned
    with sqlite3.connect(path) as conn:  # as an older robokudo left it
        conn.execute("DELETE FROM classes WHERE name = 'CannedFood'")
        conn.execute("UPDATE meta SET value = '3' WHERE key = 'version'")
    with BeliefStore(path) as store:
        assert [b.id for b in store.query(BeliefFilter(object_class="CannedFood"))] == [guessed]


def _answer(capsys: pytest.CaptureFixture, argv: list[str]) -> list[tuple[str, list[float]]]:
    assert cli.main([*argv, "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    return [(o["class"]["label"], [round(v, 2) for v in o["pose"]["position"]]) for o in answer["objects"]]


@pytest.mark.real_data
@pytest.mark.parametrize(("frame", "question"), [(1, "find the mug"), (0, "find the can")])
def test_asking_for_everything_first_does_not_hide_an_object_on_a_real_frame(
    capsys: pytest.CaptureFixture, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, frame: int, question: str
) -> None:
    """A robot that asks "find all objects" first and then "find the mug" gets the mug it gets when it asks for the
    mug alone (uoc frame 1's white mug, a cup by its cues and a mug only as a guess; frame 0's spam can, food by
    its cues). Before, the first question stored the object as a cup (food) and the second answered nothing."""
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    uoc = str(require_folder(SHARED_DATA / "uoc_tabletop_realsense"))
    seen = ["--input", uoc, "--frame", str(frame)]
    alone = _answer(capsys, ["query", question, *seen, "--store", str(tmp_path / "alone.sqlite")])
    after = str(tmp_path / "after.sqlite")
    _answer(capsys, ["query", "find all objects", *seen, "--store", after])
    assert alone
    assert _answer(capsys, ["query", question, *seen, "--store", after]) == alone
    assert _answer(capsys, ["beliefs", question, "--store", after]) == alone
