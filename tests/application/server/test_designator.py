"""RoboKudo's object designator as a query: each field's mapping, several values as alternatives, and a clear
refusal naming the field for what a query cannot hold (several classes or regions, a point, unknown fields)."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from queries import ListValue, Number, String, Symbol, format_query, parse_query
from robokudo.application.server.designator import GoalError, MissingQueryError, goal_query

WORD = st.from_regex(r"[a-z][a-z0-9_]{0,11}", fullmatch=True)


def mapped(designator: dict[str, Any], kind: str | None = None) -> Any:
    args: dict[str, Any] = {"obj": designator}
    if kind is not None:
        args["type"] = kind
    query = goal_query(args)
    assert not isinstance(query, str)
    return query


def stamped(frame: str, x: float, y: float, z: float) -> dict[str, Any]:
    """A geometry_msgs/PoseStamped as rosbridge sends it."""
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": frame},
        "pose": {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
    }


def test_query_text_is_used_as_it_is() -> None:
    assert goal_query({"query": "find milk in fridge", "obj": {"type": "Cup"}}) == "find milk in fridge"


def test_every_mapped_field_lands_in_the_obj_block() -> None:
    query = mapped(
        {
            "type": "Milk",
            "color": ["white"],
            "shape": "box",
            "size": "medium",
            "location": "fridge",
            "attribute": ["lactose free"],
            "uid": "4",
        },
        kind="inspect",
    )
    assert query.kind == "inspect"
    assert query.get("obj.type") == Symbol("Milk") and query.get("obj.location") == Symbol("fridge")
    assert query.get("obj.color") == Symbol("white") and query.get("obj.shape") == Symbol("box")
    assert query.get("obj.size") == Symbol("medium") and query.get("obj.text") == String("lactose free")
    assert query.get("obj.id") == Number(4.0)


def test_several_values_become_a_list_of_alternatives() -> None:
    query = mapped({"color": ["red", "blue"], "shape": ["box", "cylinder"], "size": ["small", "large"]})
    assert format_query(query) == "detect { obj: { color: [red, blue], shape: [box, cylinder], size: [small, large] } }"


def test_text_from_attribute_and_text_fields_is_merged_into_alternatives() -> None:
    query = mapped({"type": "Milk", "attribute": ["lactose free", "oat"], "text": "oat"})
    assert query.get("obj.text") == ListValue((String("lactose free"), String("oat")))


def test_empty_fields_and_a_default_pose_ask_for_nothing() -> None:
    full_message = {
        "uid": "",
        "type": "Milk",
        "color": [],
        "shape": [""],
        "size": "",
        "location": None,
        "attribute": [],
        "description": [],
        "shape_size": [],
        "pose": [stamped("", 0.0, 0.0, 0.0)],
    }
    assert format_query(mapped(full_message)) == "detect { obj: { type: Milk } }"


@pytest.mark.parametrize(
    ("designator", "problem"),
    [
        ({"type": ["Milk", "Cup"]}, "designator field 'type' has 2 values, but a query asks for one class"),
        ({"location": ["fridge", "table"]}, "designator field 'location' has 2 values"),
        ({"uid": ["3", "4"]}, "designator field 'uid' has 2 values"),
        ({"uid": "milk-1"}, "designator field 'uid' must be a belief id"),
        ({"color": ["red", 3]}, "designator field 'color' must be a string or a list of strings"),
        ({"shape_size": [{"radius": 0.1}]}, "designator field 'shape_size' is not mapped onto a query"),
        ({"weight": "1kg"}, "unknown designator field 'weight'"),
        ({"type": "lactose free"}, "expected an identifier"),
        ({"pose": {"x": 1}}, "designator field 'pose' must be a geometry_msgs/PoseStamped"),
        ({"pose": [stamped("map", 1.0, 0.5, 0.75)]}, "the point (1, 0.5, 0.75) in frame 'map'"),
        ({}, "the goal's designator is empty"),
    ],
    ids=[
        "classes",
        "regions",
        "uids",
        "uid-not-a-number",
        "not-a-string",
        "shape-size",
        "unknown",
        "not-a-name",
        "pose-shape",
        "pose",
        "empty",
    ],
)
def test_a_designator_a_query_cannot_hold_is_refused_naming_the_field(designator: dict[str, Any], problem: str) -> None:
    with pytest.raises(GoalError) as refused:
        mapped(designator)
    assert problem in str(refused.value)


def test_a_goal_without_text_or_designator_is_missing_its_query() -> None:
    with pytest.raises(MissingQueryError, match="'query'"):
        goal_query({"query": "  "})


@given(
    colors=st.lists(WORD, min_size=1, max_size=4, unique=True),
    shapes=st.lists(WORD, min_size=1, max_size=4, unique=True),
    name=WORD,
)
def test_any_lists_of_names_map_to_those_alternatives_and_print_as_a_query_that_parses_back(
    colors: list[str], shapes: list[str], name: str
) -> None:
    query = mapped({"type": name, "color": colors, "shape": shapes})

    def values(key: str) -> list[str]:
        value = query.get(f"obj.{key}")
        items = value.items if isinstance(value, ListValue) else (value,)
        return [item.name for item in items]

    assert values("color") == colors and values("shape") == shapes and values("type") == [name]
    assert parse_query(format_query(query)) == query
