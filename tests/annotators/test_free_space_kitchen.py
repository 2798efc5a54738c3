"""Free space on the built-in kitchen's storage shelf (the fridge's upper shelf), scored against the scene's geometry.

Perception sees only the rendered frames; the layout's ground truth (``StorageLayout.is_free``) only scores.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.simulation.kitchen_scene import fridge_shelf
from annotators.simulation.storage import StorageLayout, covers, half_blocked_layout, random_layout
from queries import parse_query
from reasoning.beliefs.answer import Answer, PlacementDesignator
from reasoning.beliefs.store import BeliefStore
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.application.service import AnsweringService
from robokudo.core.cas import CAS
from robokudo.core.engine import Engine
from robokudo.core.geometry import rotation_matrix
from robokudo.core.types import QueryAnswer
from trees.answer_step import AnswerStep
from trees.synthesis import build_tree

QUERY = "where can I put the cup in the fridge"


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


def placements_on(
    kb: KnowledgeBase, layout: StorageLayout, store_path: Path, seed: int = 0
) -> list[PlacementDesignator]:
    """The placements the planned tree of QUERY answers on the kitchen with ``layout`` on the fridge shelf."""
    return placements_tree(kb, layout, store_path, seed)[1]


def placements_tree(
    kb: KnowledgeBase, layout: StorageLayout, store_path: Path, seed: int = 0
) -> tuple[CAS, list[PlacementDesignator]]:
    """The CAS the planned tree of QUERY analysed (kitchen with ``layout`` on the fridge shelf) and its placements."""
    base = sensor_source(kb, None, region="fridge").step
    parameters = (*base.parameters, ("extra", layout.extra()), ("seed", seed))
    step = Step(base.annotator, base.implemented_by, base.inputs, base.outputs, parameters, base.reason)
    query = parse_query(QUERY)
    plan = QueryPlanner(kb).plan(query, SensorSource(step, camera_pose=True)).plan
    with BeliefStore(store_path) as store:
        tree = build_tree(plan, final_steps=[AnswerStep(store, free_space=True)], query=query)
        status = Engine(tree).run(until=lambda s: s in (Status.SUCCESS, Status.FAILURE))
        assert status is Status.SUCCESS, [(n.name, n.feedback_message) for n in tree.iterate()]
        found = tree.cas.view(QueryAnswer)
    assert found is not None and isinstance(found.answer, Answer)
    assert found.answer.placements is not None
    return tree.cas, list(found.answer.placements)


def rectangle(placement: PlacementDesignator) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    return np.array(placement.pose.position), rotation_matrix(placement.pose.orientation), placement.size


def test_half_blocked_shelf_free_places_are_free_and_blocked_ones_are_not_reported(
    kb: KnowledgeBase, tmp_path: Path
) -> None:
    layout = half_blocked_layout()
    placements = placements_on(kb, layout, tmp_path / "beliefs.sqlite")
    assert placements, "the right half of the shelf is free and in view"
    for placement in placements:
        centre, rotation, size = rectangle(placement)
        assert layout.is_free(centre, rotation, size), placement.summary()
        assert min(size) >= 0.12 and placement.footprint == (0.12, 0.12) and placement.fits >= 1
        assert placement.pose.frame == "world" and placement.region == "fridge"
    (cx, _, _), _ = fridge_shelf(0)
    assert any(p.pose.position[0] > cx for p in placements), "no place found in the free right half"
    for obj in layout.occupants():  # a blocked place: where an object stands is inside no placement
        for placement in placements:
            centre, rotation, size = rectangle(placement)
            local = (obj.position - centre) @ rotation
            assert not (abs(local[0]) <= size[0] / 2 and abs(local[1]) <= size[1] / 2), (obj.name, placement.summary())
    areas = [p.size[0] * p.size[1] for p in placements]
    assert areas == sorted(areas, reverse=True)


@pytest.mark.parametrize("seed", [3, 11])
def test_random_layouts_report_only_free_places(kb: KnowledgeBase, tmp_path: Path, seed: int) -> None:
    layout = random_layout(seed)
    for placement in placements_on(kb, layout, tmp_path / "beliefs.sqlite", seed=seed):
        assert layout.is_free(*rectangle(placement)), placement.summary()


def test_ground_truth_scoring_sees_objects_and_walls() -> None:
    layout = half_blocked_layout()
    cup = layout.objects[0]
    assert covers(cup, cup.position[None, :]).all()
    assert not layout.is_free(cup.position * np.array([1, 1, 0]) + np.array([0, 0, 0.95]), np.eye(3), (0.05, 0.05))
    (cx, cy, _), (sx, _, _) = fridge_shelf(0)
    assert not layout.is_free(np.array([cx + sx / 2, cy, 0.95]), np.eye(3), (0.1, 0.1)), "over the fridge wall"


def test_the_service_answers_free_space_in_the_default_kitchen(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    with AnsweringService.open(tmp_path / "beliefs.sqlite") as service:
        answer = service.answer(QUERY).answer
        detect = service.answer("find milk in fridge").answer
    assert answer.placements and "placements" in answer.to_dict()
    assert "free " in answer.summary() and "fits" in answer.summary()
    default = StorageLayout((), ())  # the kitchen as it is: only the milk on the shelf
    for placement in answer.placements:
        assert default.is_free(*rectangle(placement)), placement.summary()
    assert detect.placements is None and "placements" not in detect.to_dict()
