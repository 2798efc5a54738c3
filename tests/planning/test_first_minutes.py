"""A new user's first queries: default places are hints, 'anywhere' and the floor, properties, confidence."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder

FLOOR_MAP = """@prefix rk: <http://robokudo.org/ontology#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
rk:kitchen_floor a owl:NamedIndividual , rk:Floor ;
    rdfs:label "kitchen floor"@en ;
    rk:partOfMap rk:BuiltInKitchen ;
    rk:frame "world" ;
    rk:positionX 0.0 ; rk:positionY 0.0 ; rk:positionZ 0.15 ;
    rk:orientationX 0.0 ; rk:orientationY 0.0 ; rk:orientationZ 0.0 ; rk:orientationW 1.0 ;
    rk:sizeX 4.0 ; rk:sizeY 4.0 ; rk:sizeZ 0.3 .
"""


@pytest.fixture(autouse=True)
def private_data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path


def plan(capsys: pytest.CaptureFixture[str], query: str, *options: str) -> dict:
    assert cli.main(["plan", "--json", query, *options]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def annotators(document: dict) -> str:
    return json.dumps(document["tree"]) if "tree" in document else json.dumps(document)


def uoc() -> str:
    return str(require_folder(SHARED_DATA / "uoc_tabletop_realsense"))


@pytest.mark.real_data
def test_the_default_place_is_dropped_without_a_camera_pose_and_the_query_answers(
    capsys: pytest.CaptureFixture[str],
) -> None:
    document = plan(capsys, "find the mustard bottle", "--input", uoc())
    assert document["task"]["region"] is None
    assert "RegionFilter" not in annotators(document)
    assert any(
        "typically stored in the Fridge" in note and "no camera pose" in note and "whole view" in note
        for note in document["task"]["inferences"]
    )
    assert cli.main(["query", "find the mustard bottle", "--input", uoc(), "--frame", "0"]) == 0
    assert "perception failed" not in capsys.readouterr().err


@pytest.mark.real_data
def test_a_named_region_without_a_camera_pose_is_a_planning_error_that_says_how_to_go_on(
    capsys: pytest.CaptureFixture[str],
) -> None:
    for command in ("plan", "query"):
        assert cli.main([command, "find the mustard bottle in the fridge", "--input", uoc()]) == 2
        err = capsys.readouterr().err
        assert "region 'fridge' cannot be searched: the input gives no camera pose" in err
        assert "anywhere" in err and "perception failed" not in err


def test_the_kitchen_keeps_the_default_place_and_anywhere_overrides_it(capsys: pytest.CaptureFixture[str]) -> None:
    assert plan(capsys, "find the mustard bottle")["task"]["region"] == "fridge"
    for query in ("find the mustard bottle anywhere", "detect { obj: { type: Mustard, location: anywhere } }"):
        document = plan(capsys, query)
        assert document["task"]["region"] is None
        assert "RegionFilter" not in annotators(document)
        assert "the query says anywhere, so the search covers the whole view" in document["task"]["inferences"]


def test_on_the_floor_needs_a_floor_region_in_the_map(capsys: pytest.CaptureFixture[str], private_data: Path) -> None:
    assert cli.main(["plan", "find the cup on the floor"]) == 2
    assert "the semantic map has no region of class Floor" in capsys.readouterr().err
    (private_data / "user.ttl").write_text(FLOOR_MAP, encoding="utf-8")
    document = plan(capsys, "find the cup on the floor")
    assert document["task"]["region"] == "kitchen_floor"
    assert "RegionFilter" in annotators(document)


@pytest.mark.parametrize(
    ("phrase", "constraints"),
    [
        ("find something blue", {("color", "Blue")}),
        ("find the big yellow box", {("color", "Yellow"), ("size", "Large"), ("shape", "Box")}),
        ("find a small red cylinder", {("color", "Red"), ("size", "Small"), ("shape", "Cylinder")}),
    ],
)
def test_first_phrases_plan_with_shapes_as_shapes(
    capsys: pytest.CaptureFixture[str], phrase: str, constraints: set[tuple[str, str]]
) -> None:
    task = plan(capsys, phrase)["task"]
    assert task["object_class"] is None
    assert {(c["key"], c["value"]) for c in task["constraints"]} == constraints


def test_a_transparent_glass_is_the_class_glass_and_leaves_out_experts_for_opaque_objects(
    capsys: pytest.CaptureFixture[str],
) -> None:
    document = plan(capsys, "find a transparent glass")
    assert document["task"]["object_class"] == "Glass"
    something = plan(capsys, "find something transparent")
    assert "the query asks for a transparent object" in " ".join(something["task"]["inferences"])
    assert "ClusterExtractor" in annotators(plan(capsys, "find something blue"))
    assert "ClusterExtractor" not in annotators(something)  # NotForTransparentObjects


def test_a_metric_size_is_refused_at_parse_time_with_its_position(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["plan", "detect { obj: { type: Box, size: 5cm..12cm } }"]) == 2
    err = capsys.readouterr().err
    assert "'size' takes a size word" in err and "line 1, column 28" in err


def test_a_minimum_confidence_keeps_only_objects_believed_that_much(capsys: pytest.CaptureFixture[str]) -> None:
    document = plan(capsys, "detect { obj: { type: Milk, confidence: 0.75 } }")
    assert "the answer keeps only objects believed with confidence at least 0.75" in document["task"]["inferences"]
    assert cli.main(["query", "--json", "find milk in the fridge"]) == 0
    (milk,) = json.loads(capsys.readouterr().out)["objects"]
    below, above = milk["confidence"] / 2, 1.0
    assert cli.main(["beliefs", "--json", f"detect {{ obj: {{ type: Milk, confidence: {below:.3f} }} }}"]) == 0
    assert len(json.loads(capsys.readouterr().out)["objects"]) == 1
    assert cli.main(["beliefs", "--json", f"detect {{ obj: {{ type: Milk, confidence: {above} }} }}"]) == 0
    assert json.loads(capsys.readouterr().out)["objects"] == []
