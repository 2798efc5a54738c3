"""An object with two colours answers to either: a red-and-white can is found by "red" and by "white", and the
answer says both (reasoning.beliefs.seen_together). The colour expert states both in one sighting, the second with
a confidence under 0.5 (its share of the object times its certainty), so the fusion alone finds it by its dominant
colour only."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reasoning.beliefs.answer import answer_from_memory
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker


def can(position: tuple[float, float, float], *colours: tuple[str, float]) -> FrameObject:
    """A can seen with the colours (name, confidence) the colour expert states, dominant first."""
    return FrameObject(
        position=np.array(position, dtype=float),
        frame="world",
        dimensions=np.array([0.07, 0.07, 0.1]),
        evidence=[Evidence("class", "Can", 0.8, "Detector")]
        + [Evidence("color", name, confidence, "ColorExpert") for name, confidence in colours],
        sources={"Segmenter", "Detector", "ColorExpert"},
        roi=(10, 20, 30, 40),
        confidence=0.9,
    )


def found(store: BeliefStore, colour: str) -> list[int]:
    return [b.id for b in store.query(BeliefFilter(attributes={"color": colour}))]


def test_a_two_coloured_object_answers_to_both_colours_as_last_seen(tmp_path: Path) -> None:
    with BeliefStore(tmp_path / "beliefs.sqlite", tracker=BeliefTracker()) as store:
        store.integrate(
            [can((0.0, 0.0, 0.8), ("white", 0.37), ("red", 0.27)), can((0.5, 0.0, 0.8), ("blue", 0.9))], 1.0
        )
        soup, other = sorted(b.id for b in store.beliefs())
        assert found(store, "white") == [soup] and found(store, "red") == [soup] and found(store, "blue") == [other]
        assert found(store, "green") == []
        answer = answer_from_memory(store, BeliefFilter(attributes={"color": "red"}), "find the red can")
        (shown,) = answer.objects
        assert shown.attributes["color"].value == "white" and shown.attributes["color"].seen_with == ("red",)
        assert "(white and red)" in answer.summary()
        assert answer.to_dict()["objects"][0]["attributes"]["color"]["seen_with"] == ["red"]

        # seen again with its white only (the red side turned away): no longer red, not said to be
        store.integrate([can((0.0, 0.0, 0.8), ("white", 0.53)), can((0.5, 0.0, 0.8), ("blue", 0.9))], 2.0)
        assert found(store, "white") == [soup] and found(store, "red") == []
        whites = answer_from_memory(store, BeliefFilter(attributes={"color": "white"}), "find the white can")
        assert (
            "(white)" in whites.summary() and "seen_with" not in whites.to_dict()["objects"][0]["attributes"]["color"]
        )


def test_a_sighting_without_colour_keeps_the_colours_last_stated(tmp_path: Path) -> None:
    """The colours are those of the last sighting that stated any: one where the colour expert said nothing (its
    region too small, say) leaves the can red and white."""
    with BeliefStore(tmp_path / "beliefs.sqlite", tracker=BeliefTracker()) as store:
        store.integrate([can((0.0, 0.0, 0.8), ("white", 0.37), ("red", 0.27))], 1.0)
        store.integrate([can((0.0, 0.0, 0.8))], 2.0)
        (soup,) = (b.id for b in store.beliefs())
        assert found(store, "red") == [soup] and found(store, "white") == [soup]
        answer = answer_from_memory(store, BeliefFilter(attributes={"color": "red"}), "find the red can")
        assert "(white and red)" in answer.summary()
