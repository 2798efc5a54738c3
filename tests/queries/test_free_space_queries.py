"""The free-space scan in all three query forms: one model, a validator-clean planned tree, located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from queries import QueryError, format_query, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.planner import PlanningError
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.dataflow import validate_data_flow
from trees.synthesis import build_tree

FORMS = [
    (
        "where can I put the cup in the fridge",
        "scan { free_space: { region: fridge, for: Cup } }",
        '{"scan": {"free_space": {"region": "fridge", "for": "Cup"}}}',
    ),
    (
        "where should we place a mug on the table",
        "scan { free_space: { region: table, for: mug } }",
        '{"scan": {"free_space": {"region": "table", "for": "mug"}}}',
    ),
]


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.mark.parametrize(("phrase", "nested", "json"), FORMS)
def test_the_three_forms_mean_the_same_and_plan_a_valid_tree(
    kb: KnowledgeBase, phrase: str, nested: str, json: str
) -> None:
    queries = [parse_query(text) for text in (phrase, nested, json)]
    normalised = {format_query(q).lower() for q in queries}
    assert len(normalised) == 1, normalised
    for query in queries:
        region = query.get("free_space.region")
        plan = plan_query(query, kb, sensor_source(kb, None, region=getattr(region, "name", None))).plan
        assert "FreeSpaceEstimator" in plan.annotator_names()
        assert plan.task.footprint == (0.12, 0.12)  # cups and mugs are small: largest extent below 12 cm
        step = next(s for s in plan.steps() if s.annotator == "FreeSpaceEstimator")
        assert dict(step.parameters)["footprint"] == (0.12, 0.12) and dict(step.parameters)["region"]
        validate_data_flow(build_tree(plan))


def test_a_given_footprint_and_the_short_form(kb: KnowledgeBase) -> None:
    query = parse_query("scan { free_space: { region: table, footprint: [30cm, 20cm] }, max_results: 3 }")
    plan = plan_query(query, kb, sensor_source(kb, None, region="table")).plan
    parameters = dict(next(s for s in plan.steps() if s.annotator == "FreeSpaceEstimator").parameters)
    assert parameters["footprint"] == (0.3, 0.2) and parameters["max_placements"] == 3
    assert parse_query('{"scan": {"free_space": {"footprint": 0.1}}}').get("free_space.footprint") is not None
    short = plan_query(parse_query("find free space on the table"), kb, sensor_source(kb, None, region="table")).plan
    assert short.task.footprint == (0.1, 0.1) and "FreeSpaceEstimator" in short.annotator_names()
    objects_only = plan_query(parse_query("scan the table"), kb, sensor_source(kb, None, region="table")).plan
    assert objects_only.task.footprint is None and "FreeSpaceEstimator" not in objects_only.annotator_names()


def test_a_recorded_input_scans_the_whole_view(kb: KnowledgeBase) -> None:
    source = sensor_source(kb, str(Path("../shared/data/pcl_mosd_tabletop/learn/learn0.pcd")))
    plan = plan_query(parse_query("scan { free_space: { footprint: 10cm } }"), kb, source).plan
    assert plan.task.region is None and "RegionFilter" not in plan.annotator_names()


@pytest.mark.parametrize(
    ("text", "column", "message"),
    [
        ("scan { free_space: { region: shelf, footprint: [10s, 8cm] } }", 37, "'footprint' takes one or two positive"),
        ("scan { free_space: { region: shelf, footprint: [1, 2, 3] } }", 37, "'footprint' takes one or two"),
        ("scan { free_space: { region: shelf, width: 3 } }", 37, "has no key 'width'"),
        ("detect { free_space: { region: shelf } }", 10, "belongs to a 'scan' query"),
        ("scan { free_space: shelf }", 8, "takes a block"),
        ("scan { region: table, free_space: { region: shelf } }", 23, "region is given twice"),
        ("scan { free_space: { for: [cup, mug] } }", 22, "names one object class"),
        ("where can I put the red cup on the shelf", 17, "only what to put"),
        ("where can I put something", 17, "or where"),
        ('{"scan": {"free_space": {"footprint": -1}}}', 26, "positive lengths"),
    ],
)
def test_bad_free_space_queries_get_located_errors(text: str, column: int, message: str) -> None:
    with pytest.raises(QueryError, match=message) as caught:
        parse_query(text)
    assert caught.value.column == column


def test_a_class_without_a_size_bound_needs_a_footprint(kb: KnowledgeBase) -> None:
    query = parse_query("scan { free_space: { region: table, for: CerealBox } }")
    with pytest.raises(PlanningError, match="give its footprint"):
        plan_query(query, kb, sensor_source(kb, None, region="table"))
