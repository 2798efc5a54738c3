"""A robot asking twice gets one answer: a class query answered live (perceiving a frame) and the same query answered
from memory (the belief store alone) take the same beliefs, by the one rule of
:mod:`reasoning.beliefs.class_candidates` (an object whose leading class is only a guess of the asked class, shown
with "?", is counted by both)."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder


def _object(x: float, statements: list[tuple[str, float]]) -> FrameObject:
    return FrameObject(
        position=np.array([x, 0.0, 1.0]),
        frame="camera",
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
