"""Pointing queries: the three forms are one query, plan a validator-clean tree from the experts' declarations,
and the pointing detection is one planned unit another tree can embed (here beside a people detector in a
Parallel, as a tracking tree would)."""

from __future__ import annotations

import json
from dataclasses import replace

import py_trees
import pytest

from annotators.catalog import AnnotatorCatalog
from annotators.image.human_pose import PoseModelError, load_pose_model
from queries import QueryError, format_query, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import QueryPlanner, plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import PointingTarget
from tests.annotators.conftest import SHARED_DATA
from trees.pointing import UNIT_NAME, pointing_plan, pointing_query, pointing_unit
from trees.synthesis import build_tree, instantiate

OBJECT_FORMS = (
    "detect { pointing: { target: object } }",
    '{"detect": {"pointing": {"target": "object"}}}',
    "which object is the person pointing at",
    "what is the woman pointing at",
)
REGION_FORMS = (
    "detect { pointing: { target: region } }",
    '{"detect": {"pointing": {"target": "region"}}}',
    "where is the person pointing",
    "which storage place is the person pointing at",
)
CHAIN = ("HumanPoseDetector", "ActivityRecognizer", "PointingEstimator")


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.mark.parametrize("forms", [OBJECT_FORMS, REGION_FORMS])
def test_the_three_forms_are_one_query_and_print_back(forms: tuple[str, ...]) -> None:
    queries = [parse_query(text) for text in forms]
    assert all(q == queries[0] for q in queries)
    assert parse_query(format_query(queries[0])) == queries[0]
    assert (
        parse_query(json.dumps({"detect": {"pointing": {"target": queries[0].get("pointing.target").name}}}))
        == (queries[0])
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("detect { pointing: { target: cup } }", "object or region"),
        ("detect { pointing: {} }", "needs a target"),
        ("detect { pointing: { target: object, color: red } }", "only a target"),
        ("which cup is pointing", "names the person"),
    ],
)
def test_a_bad_pointing_query_is_a_located_error(text: str, message: str) -> None:
    with pytest.raises(QueryError, match=message):
        parse_query(text)


@pytest.mark.parametrize("text", OBJECT_FORMS + REGION_FORMS)
def test_every_form_plans_the_people_chain_and_a_valid_tree(kb: KnowledgeBase, text: str) -> None:
    query = parse_query(text)
    source = sensor_source(kb, None, person="point:bowl")
    result = plan_query(query, kb, source)
    names = result.plan.annotator_names()
    assert [n for n in names if n in CHAIN] == list(CHAIN)
    target = query.get("pointing.target").name
    assert result.plan.task.pointing == target
    (estimator,) = [s for s in result.plan.steps() if s.annotator == "PointingEstimator"]
    parameters = dict(estimator.parameters)
    assert parameters["target"] == target
    if target == "region":
        assert {r["region"] for r in parameters["regions"]} >= {"table", "fridge"}
        assert "PoseAnnotator" not in names  # no object segmentation for a region
    else:
        assert parameters["regions"] == () and "PoseAnnotator" in names
    validate_data_flow(build_tree(result.plan, query=query))


def test_pointing_needs_what_it_measures(kb: KnowledgeBase) -> None:
    recorded = sensor_source(kb, str(SHARED_DATA / "pcl_grabber_sequences"))
    with pytest.raises(PlanningError, match="camera pose"):
        plan_query(parse_query("where is the person pointing"), kb, recorded)
    kitchen = sensor_source(kb, None)
    no_depth = tuple(t for t in kitchen.step.outputs if t != "DepthImage")
    flat = SensorSource(replace(kitchen.step, outputs=no_depth), camera_pose=True)
    with pytest.raises(PlanningError, match="depth"):
        plan_query(parse_query("which object is the person pointing at"), kb, flat)
    with pytest.raises(PlanningError, match="not asked by track"):
        plan_query(parse_query("track { pointing: { target: object } }"), kb, kitchen)


def test_a_person_goes_only_into_the_kitchen(kb: KnowledgeBase) -> None:
    with pytest.raises(ValueError, match="built-in kitchen"):
        sensor_source(kb, str(SHARED_DATA / "pcl_grabber_sequences"), person="stand")
    with pytest.raises(ValueError, match="person spec"):
        sensor_source(kb, None, person="dance")


def test_object_queries_still_plan_no_pointing_experts(kb: KnowledgeBase) -> None:
    for text in ("find the cup", "find the person", "find milk in fridge"):
        names = plan_query(parse_query(text), kb, sensor_source(kb, None)).plan.annotator_names()
        assert not {"ActivityRecognizer", "PointingEstimator"} & set(names), text


def test_the_pointing_unit_runs_embedded_in_a_parallel_beside_another_expert(kb: KnowledgeBase) -> None:
    try:
        load_pose_model()
    except PoseModelError as error:
        pytest.skip(str(error))
    catalog = AnnotatorCatalog.discover()
    source = sensor_source(kb, None, person="point:fridge@-0.2,0.7")
    plan = pointing_plan(QueryPlanner(kb), source, "region")
    # the embedding tree reads the frame and builds the cloud itself; the unit brings the rest
    reader, cloud = (step for stage in plan.stages[:2] for step in stage)
    assert (reader.annotator, cloud.annotator) == ("KitchenSceneReader", "PointCloudGenerator")
    unit = pointing_unit(plan, (*reader.outputs, *cloud.outputs), catalog=catalog)
    assert unit.name == UNIT_NAME
    assert {n.name for n in unit.iterate()} >= set(CHAIN) and "KitchenSceneReader" not in {
        n.name for n in unit.iterate()
    }
    beside = instantiate(replace(reader, annotator="DepthPeopleDetector", implemented_by="", parameters=()), catalog)
    both = ThresholdParallel("track and detect", [unit, beside], n_success=0, reason="a unit beside an expert")
    tree = Pipeline("track", [instantiate(reader, catalog), instantiate(cloud, catalog), both])
    validate_data_flow(tree)
    tree.tick_once()
    while tree.status == py_trees.common.Status.RUNNING:
        tree.tick_once()
    (target,) = tree.cas.annotations(PointingTarget)
    assert (target.kind, target.name) == ("region", "fridge")
    assert pointing_query("region") == parse_query("where is the person pointing")
