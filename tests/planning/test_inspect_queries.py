"""Inspect queries: ``inspect object 3`` parses alike in all three forms; with the box around the believed object
(``object_focus``) the planner narrows the points to that box with the region filter and runs every expert the
ontology marks as refined by inspection (``rk:refinedByInspection``); the synthesized tree is validator-clean."""

from __future__ import annotations

import numpy as np
import pytest

from queries import format_query, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.focus import FOCUS_MARGIN, SUPPORT_DEPTH, object_focus
from reasoning.planning.query_planner import QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.pipeline import Pipeline
from trees.synthesis import build_task_tree

FORMS = ("inspect object 3", "inspect { obj: { id: 3 } }", '{"inspect": {"obj": {"id": 3}}}')
CUP_POSITION, CUP_SIZE = (0.0, -0.12, 0.805), (0.07, 0.07, 0.11)


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


def test_the_three_forms_are_one_query() -> None:
    queries = [parse_query(text) for text in FORMS]
    assert {q.kind for q in queries} == {"inspect"}
    assert queries[0] == queries[1] == queries[2] and parse_query(format_query(queries[0])) == queries[0]


def test_the_ontology_says_what_an_inspection_refines(kb: KnowledgeBase) -> None:
    assert kb.inspected_types() == ("Classification", "Pose", "SemanticColor", "Shape", "Size")


@pytest.mark.parametrize("text", FORMS)
def test_each_form_plans_a_clean_tree_narrowed_to_the_object(kb: KnowledgeBase, text: str) -> None:
    focus = object_focus(3, CUP_POSITION, CUP_SIZE, "world")
    assert focus is not None
    query = parse_query(text)
    query_plan = QueryPlanner(kb).plan(query, sensor_source(kb, None), focus)
    task = query_plan.plan.task
    assert (task.kind, task.object_id) == ("inspect", 3)
    assert any("around object 3" in note for note in task.inferences)
    names = query_plan.plan.annotator_names()
    for expert in ("RegionFilter", "PoseAnnotator", "SemanticColorAnnotator", "ShapeAnnotator", "SizeAnnotator",
                   "KnowledgeClassifier"):  # fmt: skip
        assert expert in names, expert
    (region_filter,) = [s for s in query_plan.plan.steps() if s.annotator == "RegionFilter"]
    parameters = dict(region_filter.parameters)
    assert parameters["region"] == "object 3"
    assert np.allclose(np.reshape(parameters["box_pose"], (4, 4))[:2, 3], CUP_POSITION[:2])
    assert np.allclose(parameters["box_size"][:2], 0.11 + 2 * FOCUS_MARGIN)
    tree = build_task_tree(query_plan.plan, query=query)
    assert isinstance(tree, Pipeline)
    validate_data_flow(tree)


def test_the_box_holds_the_object_and_the_surface_it_stands_on() -> None:
    box = object_focus(3, CUP_POSITION, CUP_SIZE, "world")
    assert box is not None and box.frame == "world" and box.name == "object 3"
    bottom = CUP_POSITION[2] - CUP_SIZE[2] / 2
    assert box.contains((CUP_POSITION[0], CUP_POSITION[1], bottom - SUPPORT_DEPTH + 0.01))  # the table under it
    tall = object_focus(1, (1.3, 0.8, 1.055), (0.2, 0.068, 0.056), "world")  # extents largest first: a milk carton
    assert tall is not None and tall.contains((1.3, 0.8, 1.055 - 0.1 - 0.01))  # the shelf under it
    assert box.contains((CUP_POSITION[0] + 0.07, CUP_POSITION[1] - 0.07, CUP_POSITION[2]))  # a pose a bit off
    assert not box.contains((CUP_POSITION[0] + 0.25, CUP_POSITION[1], CUP_POSITION[2]))  # the bowl beside it
    assert object_focus(3, CUP_POSITION, CUP_SIZE, "camera") is None  # no camera pose to place the points
    assert object_focus(3, CUP_POSITION, None, "world") is not None
    with pytest.raises(ValueError, match="object 3 has no finite position"):
        object_focus(3, (np.nan, 0.0, 0.0), CUP_SIZE, "world")


def test_without_a_focus_or_camera_pose_the_whole_view_is_searched(kb: KnowledgeBase) -> None:
    query = parse_query("inspect object 3")
    plain = QueryPlanner(kb).plan(query, sensor_source(kb, None))
    assert "RegionFilter" not in plain.plan.annotator_names()
    assert "SizeAnnotator" in plain.plan.annotator_names()  # still refines every attribute
    focus = object_focus(3, CUP_POSITION, CUP_SIZE, "world")
    recorded = sensor_source(kb, "../shared/data/uoc_tabletop_realsense", 3)
    assert not recorded.camera_pose
    query_plan = QueryPlanner(kb).plan(query, recorded, focus)
    assert "RegionFilter" not in query_plan.plan.annotator_names()
    assert any("whole view is searched" in note for note in query_plan.plan.task.inferences)


def test_a_detect_query_ignores_a_focus(kb: KnowledgeBase) -> None:
    focus = object_focus(3, CUP_POSITION, CUP_SIZE, "world")
    query_plan = QueryPlanner(kb).plan(parse_query("find the red cup"), sensor_source(kb, None), focus)
    assert "RegionFilter" not in query_plan.plan.annotator_names()


def test_an_inspection_asking_for_one_attribute_refines_only_that(kb: KnowledgeBase) -> None:
    focus = object_focus(3, CUP_POSITION, CUP_SIZE, "world")
    query = parse_query("inspect { obj: { id: 3, color: ? } }")
    names = QueryPlanner(kb).plan(query, sensor_source(kb, None), focus).plan.annotator_names()
    assert "SemanticColorAnnotator" in names and "RegionFilter" in names
    assert not {"SizeAnnotator", "ShapeAnnotator", "KnowledgeClassifier"} & set(names)
