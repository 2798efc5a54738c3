"""Inspecting one believed object on the kitchen: ``inspect object N`` after a detect looks only around where the
object is believed to be, runs the attribute experts there and refines that belief (same id, more observations,
attributes the detect did not measure now with confidences, pose near the ground truth); an id the store does not
hold is refused before anything runs."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from annotators.simulation.kitchen_scene import kitchen_objects
from reasoning.fusion.rule import CLASS_ATTRIBUTE
from robokudo.application.service import AnsweringService, UnknownObjectError
from robokudo.core.annotator import Annotator
from robokudo.core.types import ObjectHypothesis, SemanticColor, Size


@pytest.fixture
def service(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[AnsweringService]:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    with AnsweringService.open(tmp_path / "beliefs.sqlite") as opened:
        yield opened


def test_inspecting_a_detected_cup_refines_the_same_belief(service: AnsweringService) -> None:
    found = service.answer("find red things")
    (cup,) = found.answer.objects
    before = service.store.get(cup.id)
    assert before is not None and Size.attribute not in before.attributes  # the detect did not measure its size

    outcome = service.answer(f"inspect object {cup.id}")
    (inspected,) = outcome.answer.objects
    assert inspected.id == cup.id  # the same belief, refined
    experts = {type(n).__name__ for n in outcome.tree.iterate() if isinstance(n, Annotator)}
    assert {
        "RegionFilter",
        "SizeAnnotator",
        "ShapeAnnotator",
        "SemanticColorAnnotator",
        "KnowledgeClassifier",
    } <= experts
    (region_filter,) = [n for n in outcome.tree.iterate() if type(n).__name__ == "RegionFilter"]
    assert region_filter.region == f"object {cup.id}"
    assert len(outcome.tree.cas.annotations(ObjectHypothesis)) == 1  # only the cup is in the box

    after = service.store.get(cup.id)
    assert after is not None and after.observations == before.observations + 1
    for attribute in (SemanticColor.attribute, Size.attribute, CLASS_ATTRIBUTE):
        assert attribute in inspected.attributes and inspected.attributes[attribute].confidence > 0.5, attribute
    assert inspected.attributes[SemanticColor.attribute].value == "red"
    assert (
        inspected.attributes[SemanticColor.attribute].confidence >= cup.attributes[SemanticColor.attribute].confidence
    )
    (truth,) = [o for o in kitchen_objects() if o.name == "red_cup"]
    assert np.linalg.norm(np.asarray(inspected.pose.position) - truth.position) < 0.03
    assert service.store.count() == len(service.store.beliefs())  # nothing new was created


def test_inspecting_an_unknown_id_names_it_and_runs_nothing(service: AnsweringService) -> None:
    with pytest.raises(UnknownObjectError, match=r"^no object 41$"):
        service.answer("inspect object 41")
    assert service.store.count() == 0
