"""Queries for people: ``detect { human: {} }``, its JSON form and "find the person" parse to one target and plan
a validator-clean tree whose people detectors come from their declarations (pose model first, depth as fallback)."""

from __future__ import annotations

import json
from dataclasses import replace
from itertools import pairwise
from pathlib import Path

import pytest

from queries import QueryError, format_query, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Alternatives
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import plan_query
from robokudo.application import cli
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.dataflow import validate_data_flow
from tests.annotators.conftest import SHARED_DATA, require_folder
from trees.synthesis import build_tree

FORMS = ("detect { human: {} }", '{"detect": {"human": {}}}', "find the person", "detect { obj: { type: Person } }")
PEOPLE = ("HumanPoseDetector", "DepthPeopleDetector")


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


def test_the_nested_and_json_forms_are_one_query_and_print_back() -> None:
    nested, as_json = parse_query(FORMS[0]), parse_query(FORMS[1])
    assert nested == as_json
    assert parse_query(format_query(nested)) == nested


@pytest.mark.parametrize(
    "text", ["detect { obj: {} }", "detect { human: { obj: {} } }", "detect { obj: { human: {} } }"]
)
def test_only_a_top_level_human_block_may_be_empty(text: str) -> None:
    with pytest.raises(QueryError, match="empty block"):
        parse_query(text)


@pytest.mark.parametrize("text", FORMS)
def test_every_form_plans_the_people_detectors_as_ranked_alternatives(kb: KnowledgeBase, text: str) -> None:
    query = parse_query(text)
    result = plan_query(query, kb, sensor_source(kb, None))
    assert result.plan.task.object_class == "Human"
    (people,) = [u for u in result.plan.units() if isinstance(u, Alternatives)]
    assert people.provides == "PersonHypothesis"
    assert tuple(step.annotator for step in people.providers) == PEOPLE
    assert not {"ClusterExtractor", "KnowledgeClassifier", "PoseAnnotator"} & set(result.plan.annotator_names())
    validate_data_flow(build_tree(result.plan, query=query))


def test_without_colour_only_the_depth_detector_and_without_depth_only_the_pose_model(kb: KnowledgeBase) -> None:
    kitchen = sensor_source(kb, None)
    query = parse_query("find the person")
    for dropped, expected in ((("ColorImage",), "DepthPeopleDetector"), (("DepthImage",), "HumanPoseDetector")):
        outputs = tuple(t for t in kitchen.step.outputs if t not in dropped)
        source = SensorSource(replace(kitchen.step, outputs=outputs), camera_pose=kitchen.camera_pose)
        names = plan_query(query, kb, source).plan.annotator_names()
        assert expected in names and not set(PEOPLE) - {expected} & set(names), names


def test_object_queries_do_not_use_the_people_detectors(kb: KnowledgeBase) -> None:
    for text in ("find something blue", "find milk in fridge", "detect { obj: { shape: box } }"):
        names = plan_query(parse_query(text), kb, sensor_source(kb, None)).plan.annotator_names()
        assert not set(PEOPLE) & set(names), (text, names)


@pytest.mark.parametrize("text", ["detect { human: { color: red } }", "detect { obj: { type: Human }, human: {} }"])
def test_what_cannot_be_asked_of_a_person_is_a_planning_error(kb: KnowledgeBase, text: str) -> None:
    with pytest.raises(PlanningError):
        plan_query(parse_query(text), kb, sensor_source(kb, None))


@pytest.mark.real_data
def test_find_the_person_on_a_real_frame_end_to_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = require_folder(SHARED_DATA / "pcl_people") / "five_people.pcd"
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    assert cli.main(["query", "find the person", "--input", str(path), "--json"]) == 0
    (person,) = json.loads(capsys.readouterr().out)["objects"]
    assert person["class"]["iri"].endswith("#Human") and person["experts"] == ["HumanPoseDetector"]
    assert 1.5 < person["pose"]["position"][2] < 3.0
    assert cli.main(["query", "detect { human: {} }", "--input", str(path), "--json"]) == 0
    people = json.loads(capsys.readouterr().out)["objects"]
    # the planned range filter keeps the cloud within 2.5 m: the four people nearer than that are found
    assert len(people) >= 4
    assert all(p["class"]["iri"].endswith("#Human") for p in people)
    xs = sorted(p["pose"]["position"][0] for p in people)
    assert all(b - a > 0.25 for a, b in pairwise(xs)), xs


@pytest.mark.parametrize("text", ["find all objects", "detect { obj: { type: PhysicalObject } }", "find the cup"])
def test_object_queries_plan_no_people_detector_and_a_valid_tree(kb: KnowledgeBase, text: str) -> None:
    source = sensor_source(kb, str(SHARED_DATA / "pcl_grabber_sequences"))
    query_plan = plan_query(parse_query(text), kb, source)
    steps = {step.annotator for step in query_plan.plan.steps()}
    assert steps.isdisjoint(PEOPLE), steps  # a person is not a segment of "all objects" on a table
    validate_data_flow(build_tree(query_plan.plan))
