"""A word the knowledge base does not know is reported where the query said it (line, column and excerpt),
so a mistake deep in a nested query is found at once."""

from __future__ import annotations

from pathlib import Path

import pytest

from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.planner import PlanningError
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.mark.parametrize(
    ("query", "message", "line", "column"),
    [
        ("detect {\n  obj: {\n    type: Mlik\n  }\n}", "unknown object class 'Mlik'", 3, 5),
        ("detect {\n  obj: {\n    type: Milk,\n    colr: red\n  }\n}", "unknown query key 'colr'", 4, 5),
        ("detect {\n  obj: {\n    type: Milk,\n    color: [white, rde]\n  }\n}", "unknown colour 'rde'", 4, 5),
        ("detect { obj: { type: Milk, size: huge } }", "unknown size class 'huge'", 1, 29),
        ("detect {\n  obj: {\n    type: Milk,\n    location: { in: frige }\n  }\n}", "'frige'", 4, 17),
        ("find the rde mug", "unknown object class 'rde_mug'", 1, 10),
        ("find milk in the frige", "'frige'", 1, 11),
        ("find free space on the tabel", "'tabel'", 1, 17),
        ("scan {\n  free_space: { region: tabel } }", "'tabel'", 2, 17),
    ],
)
def test_an_unknown_word_is_reported_at_its_line_and_column(
    query: str, message: str, line: int, column: int, kb: KnowledgeBase
) -> None:
    with pytest.raises(PlanningError) as caught:
        plan_query(parse_query(query), kb, sensor_source(kb, None))
    text = str(caught.value)
    assert message in text
    assert f"at line {line}, column {column}" in text
    shown_line, caret = text.splitlines()[-2:]
    assert caret.strip() == "^"
    assert shown_line.strip() == query.splitlines()[line - 1].strip()


@pytest.mark.parametrize(
    ("query", "label", "column"),
    [("find the can in the bowl", "bowl", 14), ("find the cup next to the cheez-it box", "Cheez-It crackers", 14)],
)
def test_an_object_named_as_a_place_is_told_apart_from_an_unknown_word(
    query: str, label: str, column: int, kb: KnowledgeBase
) -> None:
    """``find the can in the bowl`` on uoc frame 2 (a can standing in the teal bowl) said "unknown region or region
    class 'bowl'", as if the robot did not know bowls."""
    with pytest.raises(PlanningError) as caught:
        plan_query(parse_query(query), kb, sensor_source(kb, None))
    text = str(caught.value)
    assert "unknown region" not in text
    assert f"is an object, not a place ({label})" in text
    assert "leave the place out" in text
    assert f"at line 1, column {column}" in text


@pytest.mark.real_data
def test_a_scan_of_a_region_an_input_cannot_place_is_refused_where_it_names_it(kb: KnowledgeBase) -> None:
    """``find free space on the table`` on a frame without a camera pose said why without saying where."""
    uoc = str(Path(__file__).resolve().parents[2].parent / "shared" / "data" / "uoc_tabletop_realsense")
    with pytest.raises(PlanningError) as caught:
        plan_query(parse_query("find free space on the table"), kb, sensor_source(kb, uoc))
    text = str(caught.value)
    assert "region 'table' cannot be searched: the input gives no camera pose" in text
    assert "at line 1, column 17" in text and text.splitlines()[-1].strip() == "^"
