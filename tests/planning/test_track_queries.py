"""Track queries: "track the person" and "track the blue cup" parse alike in all three forms and plan a
validator-clean Loop around the per-frame Pipeline, ending in the tracker the ontology declares for the target."""

from __future__ import annotations

import pytest

from queries import QueryError, format_query, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.loop import Loop
from robokudo.core.pipeline import Pipeline
from robokudo.core.render import tree_to_dict
from trees.synthesis import build_task_tree

PERSON = ("track { human: {} }", '{"track": {"human": {}}}', "track the person")
CUP = ('track { obj: { type: cup, color: blue } }', '{"track": {"obj": {"type": "cup", "color": "blue"}}}',
       "track the blue cup")  # fmt: skip


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.mark.parametrize("forms", [PERSON, CUP])
def test_the_three_forms_ask_for_the_same_target(kb: KnowledgeBase, forms: tuple[str, str, str]) -> None:
    queries = [parse_query(text) for text in forms]
    assert {q.kind for q in queries} == {"track"}
    assert queries[0] == queries[1] and parse_query(format_query(queries[0])) == queries[0]
    tasks = [plan_query(q, kb, sensor_source(kb, None)).plan.task for q in queries]
    assert len({(t.object_class, t.constraints) for t in tasks}) == 1, tasks


@pytest.mark.parametrize(("text", "tracker", "detector"), [
    *((t, "HumanTracker", "HumanPoseDetector") for t in PERSON),
    *((t, "ObjectTracker", "KnowledgeClassifier") for t in CUP),
])  # fmt: skip
def test_each_form_plans_a_loop_around_a_clean_frame_pipeline_ending_in_its_tracker(
    kb: KnowledgeBase, text: str, tracker: str, detector: str
) -> None:
    query_plan = plan_query(parse_query(text), kb, sensor_source(kb, None))
    names = query_plan.plan.annotator_names()
    assert names[-1] == tracker and detector in names
    assert not {"HumanTracker", "ObjectTracker"} - {tracker} & set(names)
    tree = build_task_tree(query_plan.plan, query=parse_query(text))
    assert isinstance(tree, Loop) and tree.runs is None and isinstance(tree.decorated, Pipeline)
    validate_data_flow(tree)
    assert tree_to_dict(tree)["type"] == "Loop"


def test_the_object_tracker_is_told_the_class_with_its_subclasses_and_the_colour(kb: KnowledgeBase) -> None:
    query_plan = plan_query(parse_query("track the blue cup"), kb, sensor_source(kb, None))
    (step,) = [s for s in query_plan.plan.steps() if s.annotator == "ObjectTracker"]
    parameters = dict(step.parameters)
    assert parameters["target_classes"][0] == "Cup" and set(kb.subclasses("Cup")) <= set(parameters["target_classes"])
    assert dict(parameters["target_values"]) == {"color": ("Blue",)}


def test_the_pose_detector_follows_only_the_target_in_a_track_and_everyone_in_a_detect(kb: KnowledgeBase) -> None:
    for text, follows in (("track the person", True), ("find the person", False)):
        query_plan = plan_query(parse_query(text), kb, sensor_source(kb, None))
        (step,) = [s for s in query_plan.plan.steps() if s.annotator == "HumanPoseDetector"]
        assert dict(step.parameters).get("follow_target", False) is follows, text


def test_one_shot_kinds_keep_a_plain_pipeline_and_plan_no_tracker(kb: KnowledgeBase) -> None:
    for text in ("find the person", "find the blue cup"):
        query_plan = plan_query(parse_query(text), kb, sensor_source(kb, None))
        assert not {"HumanTracker", "ObjectTracker"} & set(query_plan.plan.annotator_names())
        assert isinstance(build_task_tree(query_plan.plan), Pipeline)


def test_lost_after_is_a_duration() -> None:
    assert parse_query("track { human: {}, lost_after: 500ms }").get("lost_after").value == pytest.approx(0.5)
    with pytest.raises(QueryError, match="'lost_after' needs a unit of 's'"):
        parse_query("track { human: {}, lost_after: 2m }")
    with pytest.raises(QueryError, match="must not be negative"):
        parse_query("track { human: {}, lost_after: -1s }")
