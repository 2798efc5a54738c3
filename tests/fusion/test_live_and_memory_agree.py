"""A robot asking twice gets one answer: a class query answered live (perceiving a frame) and the same query answered
from memory (the belief store alone) take the same beliefs, by the one rule of
:mod:`reasoning.beliefs.class_candidates` (an object whose leading class is only a guess of the asked class, shown
with "?", is counted by both)."""

from __future__ import annotations

import json
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
