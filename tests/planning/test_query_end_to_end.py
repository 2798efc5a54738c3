"""End to end through the CLI: plan, run in the engine's task slot, fuse, answer."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from annotators.simulation.kitchen_scene import render_kitchen
from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder


def run_query(arguments: list[str], capsys: pytest.CaptureFixture) -> dict:
    assert cli.main(["query", *arguments, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_find_milk_in_fridge_answers_with_the_milk_pose(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    answer = run_query(["find milk in fridge"], capsys)
    (milk,) = answer["objects"]
    truth = next(o for o in render_kitchen("fridge").objects if o.name == "milk")
    error = np.linalg.norm(np.asarray(milk["pose"]["position"]) - truth.pose[:3, 3])
    assert milk["pose"]["frame"] == "world"
    assert error < 0.02, f"milk found {error * 100:.1f} cm from its true position"
    assert milk["class"]["iri"].endswith("Milk") and milk["region"] == "fridge"


@pytest.mark.real_data
def test_red_box_on_a_real_frame_returns_the_cheez_it_roi(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    folder = require_folder(SHARED_DATA / "uoc_tabletop_realsense")
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    answer = run_query(["detect {obj: {color: red, shape: box}}", "--input", str(folder), "--frame", "3"], capsys)
    assert answer["objects"], "no red box found"
    x0, y0, x1, y1 = answer["objects"][0]["roi"]
    box = (200, 0, 325, 145)  # the Cheez-It box in 000003-color.png, read off the image
    inter = max(0, min(x1, box[2]) - max(x0, box[0])) * max(0, min(y1, box[3]) - max(y0, box[1]))
    union = (x1 - x0) * (y1 - y0) + (box[2] - box[0]) * (box[3] - box[1]) - inter
    assert inter / union > 0.7, (x0, y0, x1, y1)


def test_plan_cli_prints_the_tree_with_reasons_and_json(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["plan", "--explain", "detect { obj: { color: red } }"]) == 0
    text = capsys.readouterr().out
    assert "SemanticColorAnnotator" in text and "query asks color = Red" in text
    assert cli.main(["plan", "--json", "detect { obj: { color: red } }"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["tree"]["type"] == "Pipeline"
    classes = [node.get("class") for node in _walk(document["tree"])]
    assert "annotators.image.color.SemanticColorAnnotator" in classes
    assert all(node["reason"] for node in _walk(document["tree"]))


def test_bad_query_exits_2_with_the_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    assert cli.main(["plan", "detect { obj: { color: silver } }"]) == 2
    assert "SemanticColorAnnotator can report only" in capsys.readouterr().err
    assert cli.main(["query", "detect { obj: { type: Milk, } }"]) == 2
    assert "line 1, column" in capsys.readouterr().err


def _walk(node: dict) -> list[dict]:
    return [node, *(n for child in node.get("children", []) for n in _walk(child))]


@pytest.mark.parametrize(
    ("query", "name"),
    [("find a bowl", "bowl"), ("find the red cup on the table", "red_cup"), ("where is the cereal box?", "cereal_box")],
)
def test_kitchen_objects_are_found_by_class(
    query: str, name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    answer = run_query([query], capsys)
    truth = next(o for o in render_kitchen("table").objects if o.name == name)
    (found,) = answer["objects"]
    assert np.linalg.norm(np.asarray(found["pose"]["position"]) - truth.pose[:3, 3]) < 0.03
    assert "KnowledgeClassifier" in found["experts"]
