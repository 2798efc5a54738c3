"""Pointing on the built-in kitchen, end to end: the planned tree sees the rendered person (mediapipe keypoints,
depth), recognises that it points and names the pointed table object or region; the ground truth only scores."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from annotators.simulation.kitchen_scene import kitchen_objects
from robokudo.application.service import AnsweringService, Outcome, PerceptionFailedError
from tests.kitchen_service import kitchen_service_with_pose

POSITIONS = ((-0.35, 0.7), (0.05, 0.75), (0.4, 0.65))
TABLE_OBJECTS = ("cereal_box", "red_cup", "bowl")


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[AnsweringService]:
    """One answering service on the kitchen for the module; each test puts its person in."""
    yield from kitchen_service_with_pose(tmp_path_factory, "pointing")


def _answer(service: AnsweringService, person: str, text: str) -> Outcome:
    service.person = person
    return service.answer(text)


@pytest.mark.parametrize("target", TABLE_OBJECTS)
def test_pointing_at_each_table_object_from_three_places_names_it(service: AnsweringService, target: str) -> None:
    truth = {o.name: o.position for o in kitchen_objects()}
    for x, y in POSITIONS:
        outcome = _answer(service, f"point:{target}@{x},{y}", "which object is the person pointing at")
        pointing = outcome.answer.pointing
        assert pointing is not None and pointing.kind == "object" and pointing.object_id is not None, (x, y)
        (pointed,) = outcome.answer.objects
        assert pointed.id == pointing.object_id
        position = np.asarray(pointed.pose.position)
        nearest = min(truth, key=lambda name: np.linalg.norm(truth[name] - position))
        assert nearest == target, (x, y, nearest)
        assert pointing.angular_error_degrees < 10.0 and 0.0 < pointing.confidence <= 1.0


@pytest.mark.parametrize(("region", "place"), [("fridge", (-0.2, 0.7)), ("fridge", (0.3, 0.75))])
def test_pointing_at_a_storage_region_names_the_region(service: AnsweringService, region: str, place: tuple) -> None:
    x, y = place
    outcome = _answer(service, f"point:{region}@{x},{y}", "where is the person pointing")
    pointing = outcome.answer.pointing
    assert pointing is not None and (pointing.kind, pointing.region) == ("region", region)
    assert outcome.answer.objects == ()
    assert pointing.frame == "world" and abs(np.linalg.norm(pointing.direction) - 1.0) < 1e-6
    assert "region fridge" in outcome.answer.summary()


def test_a_person_who_only_stands_points_at_nothing(service: AnsweringService) -> None:
    with pytest.raises(PerceptionFailedError, match="no person with body keypoints is pointing"):
        _answer(service, "stand@0.0,0.7", "which object is the person pointing at")
