"""A selection (``the top box``) is a step on the answer: the plan says so, the tree finds the same objects as without
it, and selecting needs depth to measure objects in 3-D."""

from __future__ import annotations

import pytest

from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.interpretation import interpret
from reasoning.planning.planner import PlanningError
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.mark.parametrize(
    ("selecting", "plain", "name"),
    [
        ("find the top box", "find the box", "top"),
        ("find the leftmost cup", "find the cup", "leftmost"),
        ("find the second biggest bowl", "find the bowl", "biggest"),
    ],
)
def test_the_plan_selects_on_the_answer_and_finds_the_same_objects(
    kb: KnowledgeBase, selecting: str, plain: str, name: str
) -> None:
    planned = plan_query(parse_query(selecting), kb, sensor_source(kb, None))
    without = plan_query(parse_query(plain), kb, sensor_source(kb, None))
    task = planned.plan.task
    assert task.selection is not None and task.selection.selection.name == name
    assert without.plan.task.selection is None
    assert any(f"the answer selects by '{name}'" in note for note in task.inferences)
    assert planned.plan.annotator_names() == without.plan.annotator_names()


def test_the_top_needs_the_support_plane(kb: KnowledgeBase) -> None:
    requirements = interpret(parse_query("find the top box"), kb).requirements
    assert any(r.annotation_type == "Plane" and "top" in r.reason for r in requirements)
    assert not any(
        r.annotation_type == "Plane" for r in interpret(parse_query("find the leftmost box"), kb).requirements
    )


def test_a_selection_without_depth_is_refused_where_it_was_said(kb: KnowledgeBase) -> None:
    query = parse_query("detect {\n  obj: { type: Cup },\n  select: closest\n}")
    with pytest.raises(PlanningError) as caught:
        interpret(query, kb, depth=False)
    assert "the sensor measures no depth" in str(caught.value)
    assert "line 3, column 3" in str(caught.value)
