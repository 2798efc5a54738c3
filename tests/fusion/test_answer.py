"""Answers: object designators (Python and JSON), the AnswerStep leaf, query -> filter, and `robokudo beliefs`."""

from __future__ import annotations

import argparse
import json
from collections.abc import Collection
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from py_trees.common import Status

from queries import Query, parse_query
from reasoning.beliefs.answer import (
    Answer,
    AttributeDesignator,
    ObjectDesignator,
    PoseDesignator,
    answer_from_memory,
    class_iri,
    class_label,
    designator,
)
from reasoning.beliefs.filters import belief_filter
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker
from reasoning.knowledge.model import Resolved
from robokudo.application.commands import beliefs as beliefs_cli
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.regions import RegionBox
from robokudo.core.types import (
    ONTOLOGY_NAMESPACE,
    CameraInfo,
    CameraIntrinsics,
    CasType,
    Classification,
    ObjectHypothesis,
    Pose,
    QueryAnswer,
    SemanticColor,
)
from trees.answer_step import AnswerStep

SUBCLASSES = {("LactoseFreeMilk", "Milk")}


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


def box(name: str, centre: tuple[float, float, float], size: tuple[float, float, float]) -> RegionBox:
    region_class = "FridgeInterior" if name == "fridge" else "TableTop"
    return RegionBox(name, region_class, "world", centre, (0.0, 0.0, 0.0, 1.0), size)


FRIDGE = box("fridge", (1.3, 0.85, 0.8), (0.5, 0.5, 1.5))
TABLE = box("table", (0.0, 0.0, 0.95), (1.2, 0.8, 0.5))


def kitchen_objects() -> list[FrameObject]:
    def item(position: tuple[float, float, float], evidence: list[Evidence]) -> FrameObject:
        return FrameObject(
            position=np.array(position),
            frame="world",
            orientation=np.array([0.0, 0.0, 0.0, 1.0]),
            dimensions=np.array([0.2, 0.07, 0.07]),
            evidence=evidence,
            sources={"ClusterExtractor", *(e.source for e in evidence)},
            roi=(10, 20, 50, 90),
            confidence=0.9,
        )

    return [
        item(
            (1.3, 0.8, 1.05),
            [
                Evidence("class", "Milk", 0.8, "MilkDetector"),
                Evidence("class", "LactoseFreeMilk", 0.7, "TextReader"),
                Evidence("color", "white", 0.9, "SemanticColorAnnotator"),
            ],
        ),
        item(
            (0.0, -0.12, 0.8),
            [Evidence("class", "Cup", 0.9, "CupDetector"), Evidence("color", "red", 0.9, "SemanticColorAnnotator")],
        ),
    ]


@pytest.fixture
def filled(tmp_path: Path) -> Path:
    path = tmp_path / "beliefs.sqlite"
    with BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass, regions=(FRIDGE, TABLE))) as store:
        store.integrate(kitchen_objects(), 100.0)
    return path


def test_a_designator_has_everything_the_robot_needs(filled: Path) -> None:
    with BeliefStore(filled) as store:
        milk = store.query(BeliefFilter(object_class="Milk", class_test=is_subclass))[0]
    d = designator(milk, class_test=is_subclass, roi=(10, 20, 50, 90))
    assert d.class_iri == ONTOLOGY_NAMESPACE + "LactoseFreeMilk"
    assert d.class_label == "lactose free milk"
    assert d.pose.frame == "world" and d.pose.position == pytest.approx((1.3, 0.8, 1.05))
    assert d.pose.orientation == (0.0, 0.0, 0.0, 1.0)
    assert d.size == pytest.approx((0.2, 0.07, 0.07)) and d.region == "fridge"
    assert d.roi == (10, 20, 50, 90)
    assert {"ClusterExtractor", "MilkDetector", "TextReader", "SemanticColorAnnotator"} <= set(d.experts)
    classification = d.attributes["class"]
    assert classification.value == "LactoseFreeMilk" and not classification.conflict
    assert set(classification.experts) == {"MilkDetector", "TextReader"}
    assert {a.value for a in classification.alternatives} == {"Milk", "LactoseFreeMilk"}
    assert d.attributes["color"].value == "white" and d.attributes["color"].confidence == pytest.approx(0.9)

    data = json.loads(json.dumps(d.to_dict()))
    assert set(data) >= {"id", "class", "pose", "size", "region", "attributes", "roi", "experts", "confidence"}
    assert data["class"] == {"iri": d.class_iri, "label": "lactose free milk"}
    assert data["pose"]["frame"] == "world" and len(data["pose"]["orientation"]) == 4
    assert data["roi"] == [10, 20, 50, 90]
    assert data["attributes"]["color"]["experts"] == ["SemanticColorAnnotator"]


def test_class_names_become_iris_and_labels() -> None:
    assert class_iri("Milk") == ONTOLOGY_NAMESPACE + "Milk"
    assert class_iri("http://example.org/onto#Cup") == "http://example.org/onto#Cup"
    assert class_label("LactoseFreeMilk") == "lactose free milk"
    assert class_label("http://example.org/onto#CerealBox") == "cereal box"
    assert class_label("RGBCamera") == "rgb camera"


def test_answers_from_memory_with_subsumption_and_region(filled: Path) -> None:
    with BeliefStore(filled) as store:
        answer = answer_from_memory(
            store, BeliefFilter(object_class="Milk", class_test=is_subclass, region="fridge"), "milk in fridge"
        )
        assert [o.class_label for o in answer.objects] == ["lactose free milk"]
        assert answer.from_memory and answer.objects[0].roi is None  # no current image
        assert json.loads(answer.to_json())["objects"][0]["region"] == "fridge"
        assert answer_from_memory(store, BeliefFilter(object_class="Milk", region="table")).objects == ()
        assert "lactose free milk" in answer.summary()


# ------------------------------------------------------------------------------------------- AnswerStep


class ScriptedExperts(Annotator):
    """Stands in for the readers and experts: writes camera info, two hypotheses and their annotations."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (
        CameraInfo,
        ObjectHypothesis,
        SemanticColor,
        Pose,
        Classification,
    )

    def __init__(self, stamp: float) -> None:
        super().__init__(name="ScriptedExperts")
        self.stamp = stamp

    def analyse(self) -> None:
        intrinsics = CameraIntrinsics(fx=500.0, fy=500.0, cx=32.0, cy=24.0, width=64, height=48)
        self.write(CameraInfo(intrinsics=intrinsics, cam_to_world=np.eye(4), timestamp=self.stamp))
        for index, (position, color, cls) in enumerate(
            [((0.0, 0.0, 1.0), "red", "Cup"), ((0.3, 0.0, 1.0), "blue", "Bowl")]
        ):
            mask = np.zeros((48, 64), bool)
            mask[10:20, 10 + 30 * index : 20 + 30 * index] = True
            roi = (10 + 30 * index, 10, 20 + 30 * index, 20)
            hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)
            self.write(hypothesis)
            self.attach(hypothesis, SemanticColor(color=color, confidence=0.8))
            self.attach(hypothesis, Pose(position=np.array(position), orientation=np.array([0.0, 0.0, 0.0, 1.0])))
            self.attach(hypothesis, Classification(class_name=cls, confidence=0.7, source="Detector"))


def test_the_answer_step_fuses_into_the_store_and_answers_with_rois(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    ids = []
    for stamp in (10.0, 11.0):
        step = AnswerStep(path, belief_filter=BeliefFilter(attributes={"color": "red"}))
        root = Pipeline("perceive", [ScriptedExperts(stamp), step])
        assert Engine(root).tick() is Status.SUCCESS
        (cup,) = root.cas.view(QueryAnswer).answer.objects
        assert cup.class_label == "cup" and cup.roi == (10, 10, 20, 20)
        assert cup.pose.frame == "world" and cup.pose.position == pytest.approx((0.0, 0.0, 1.0))
        assert {"ScriptedExperts", "Detector"} <= set(cup.experts)
        ids.append(cup.id)
        step.store.close()
    assert ids[0] == ids[1]  # the second run updates the same belief
    with BeliefStore(path) as store:
        assert store.count() == 2 and store.get(ids[0]).observations == 2  # type: ignore[union-attr]


def test_the_answer_step_can_fail_when_nothing_matches(tmp_path: Path) -> None:
    step = AnswerStep(
        tmp_path / "b.sqlite", belief_filter=BeliefFilter(attributes={"color": "green"}), fail_when_empty=True
    )
    root = Pipeline("perceive", [ScriptedExperts(5.0), step])
    assert Engine(root).tick() is Status.FAILURE
    assert "no object matches" in step.feedback_message
    step.store.close()


# --------------------------------------------------------------------------------------- query -> filter


class FakeKnowledgeBase:
    """A Vocabulary (what the belief filter asks the KnowledgeBase) over a few words."""

    words: ClassVar[dict[str, str]] = {"milk": "Milk", "cup": "Cup", "red": "Red", "teal": "Teal", "fridge": "fridge"}

    def resolve(self, word: str, kinds: Collection[str] | None = None) -> Resolved:
        if word.lower() not in self.words:
            raise KeyError(word)
        return Resolved(kind="class", name=self.words[word.lower()])

    def is_subclass(self, name: str, ancestor: str) -> bool:
        return is_subclass(name, ancestor)

    def answers_to(self, name: str, asked: str) -> bool:
        return is_subclass(name, asked)

    def annotation_type_for_key(self, key: str) -> str:
        types = {"color": "SemanticColor", "shape": "Shape", "size": "Size", "text": "Text"}
        if key not in types:
            raise KeyError(key)
        return types[key]

    def value_kind(self, annotation_type: str) -> str | None:
        return {"SemanticColor": "color", "Shape": "shape", "Size": "size"}.get(annotation_type)

    def reported_as(self, annotation_type: str, value: str) -> tuple[str, ...]:
        return ("Blue", "Green") if value == "Teal" else (value,)

    def region(self, name: str) -> RegionBox:
        if name.lower() != "fridge":
            raise KeyError(name)
        return FRIDGE

    def regions_of_class(self, name: str) -> list[RegionBox]:
        return [FRIDGE] if name == "FridgeInterior" else []


def parse(text: str) -> Query:
    return parse_query(text)


def test_query_to_filter_with_a_fake_knowledge_base() -> None:
    f = belief_filter(parse("find milk in fridge"), FakeKnowledgeBase())
    assert f.object_class == "Milk" and f.region == "fridge" and f.region_boxes == (FRIDGE,)
    assert f.class_test is not None and f.class_test("LactoseFreeMilk", "Milk")
    f = belief_filter(parse("find the red cup"), FakeKnowledgeBase())
    assert f.object_class == "Cup" and f.attributes == {"color": "Red"} and f.limit == 1
    teal = belief_filter(parse("find the teal cup"), FakeKnowledgeBase())  # no expert says teal: its basic colours
    assert teal.attributes == {"color": ("Blue", "Green")}
    nested = belief_filter(parse("detect { type: milk, location: { in: fridge }, color: white }"), None)
    assert nested.object_class == "milk" and nested.region == "fridge" and nested.attributes == {"color": "white"}


def test_query_to_filter_with_the_real_knowledge_base(filled: Path) -> None:
    knowledge_base = pytest.importorskip("reasoning.knowledge.knowledge_base")
    kb = knowledge_base.KnowledgeBase.load()
    f = belief_filter(parse("find milk in fridge"), kb)
    assert f.object_class == "Milk" and f.region == "fridge" and len(f.region_boxes) == 1
    with BeliefStore(filled) as store:
        (milk,) = store.query(f)
        assert milk.class_name == "LactoseFreeMilk"


def test_several_values_of_an_attribute_select_objects_with_any_of_them(filled: Path) -> None:
    f = belief_filter(parse("detect { obj: { color: [red, blue] } }"), None)
    assert f.attributes == {"color": ("red", "blue")}
    with BeliefStore(filled) as store:  # a white (lactose free) milk and a red cup
        assert [b.class_name for b in store.query(f)] == ["Cup"]
        either = store.query(BeliefFilter(attributes={"color": ("white", "RED")}))
        assert {b.class_name for b in either} == {"LactoseFreeMilk", "Cup"}
        milk = BeliefFilter(object_class="Milk", class_test=is_subclass, attributes={"color": ("red", "white")})
        assert [b.class_name for b in store.query(milk)] == ["LactoseFreeMilk"]
        assert store.query(BeliefFilter(object_class="Cup", attributes={"color": ("white", "blue")})) == []


def test_a_list_under_an_attribute_key_resolves_each_word_with_the_knowledge_base() -> None:
    f = belief_filter(parse("find the red or green cup"), FakeKnowledgeBase())
    assert f.attributes == {"color": ("Red", "green")}  # a word the knowledge base does not know stays as it is
    one = belief_filter(parse("detect { obj: { color: [red, Red] } }"), FakeKnowledgeBase())
    assert one.attributes == {"color": "Red"}


# -------------------------------------------------------------------------------------------------- CLI


def cli(store: Path, query: str | None = None, *, as_json: bool = False, clear: bool = False) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    beliefs_cli.add_arguments(parser)
    argv = ([query] if query else []) + (["--json"] if as_json else []) + (["--clear", "--yes"] if clear else [])
    return parser.parse_args([*argv, "--store", str(store)])


def test_beliefs_cli_lists_answers_and_clears(filled: Path, capsys: pytest.CaptureFixture) -> None:
    assert beliefs_cli.run(cli(filled)) == 0
    listing = capsys.readouterr().out
    assert "lactose free milk" in listing and "cup" in listing

    pytest.importorskip("queries.dispatch")
    assert beliefs_cli.run(cli(filled, "milk in fridge", as_json=True)) == 0
    answer = json.loads(capsys.readouterr().out)
    assert [o["class"]["label"] for o in answer["objects"]] == ["lactose free milk"]
    assert answer["objects"][0]["region"] == "fridge" and answer["from_memory"]

    assert beliefs_cli.run(cli(filled, "red cup on the table", as_json=True)) == 0
    assert [o["class"]["label"] for o in json.loads(capsys.readouterr().out)["objects"]] == ["cup"]

    assert beliefs_cli.run(cli(filled, clear=True)) == 0
    assert "forgot 2 object(s)" in capsys.readouterr().out
    assert beliefs_cli.run(cli(filled, as_json=True)) == 0
    assert json.loads(capsys.readouterr().out)["objects"] == []


def test_beliefs_cli_store_path_from_the_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    path = tmp_path / "env" / "beliefs.sqlite"
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(path))
    assert BeliefStore.default_path() == path
    parser = argparse.ArgumentParser()
    beliefs_cli.add_arguments(parser)
    assert beliefs_cli.run(parser.parse_args(["--json"])) == 0
    assert json.loads(capsys.readouterr().out)["objects"] == []
    assert not path.exists()  # reading an empty memory creates nothing


def test_beliefs_cli_reports_a_bad_query(filled: Path, capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("queries.dispatch")
    assert beliefs_cli.run(cli(filled, "detect { type: }")) == 2
    assert "robokudo beliefs:" in capsys.readouterr().err


def test_the_answer_step_answers_with_what_it_sees_even_under_a_limit(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    with BeliefStore(path) as store:  # a cup known from earlier, elsewhere, with a smaller id
        far = FrameObject(
            position=np.array([5.0, 5.0, 1.0]), frame="world", evidence=[Evidence("class", "Cup", 0.9, "X")]
        )
        store.integrate([far], 1.0)
    step = AnswerStep(path, belief_filter=BeliefFilter(object_class="Cup", limit=1))
    root = Pipeline("perceive", [ScriptedExperts(10.0), step])
    assert Engine(root).tick() is Status.SUCCESS
    (cup,) = root.cas.view(QueryAnswer).answer.objects
    assert cup.id != 1 and cup.roi == (10, 10, 20, 20)
    step.shutdown()


def test_the_summary_marks_a_doubtful_class_and_shows_both_confidences() -> None:
    def one(class_confidence: float) -> str:
        guessed = AttributeDesignator(value="Cup", confidence=class_confidence, experts=("KnowledgeClassifier",))
        cup = ObjectDesignator(
            id=7,
            class_iri=class_iri("Cup"),
            class_label="cup",
            pose=PoseDesignator(position=(0.1, 0.2, 0.3), orientation=(0.0, 0.0, 0.0, 1.0), frame="camera"),
            size=None,
            size_class=None,
            region=None,
            attributes={"class": guessed},
            experts=("KnowledgeClassifier",),
            confidence=0.9,
        )
        return Answer(query="find the cup", objects=(cup,)).summary()

    assert one(0.3).startswith("#7 cup? at") and ", class 0.30, exists 0.90" in one(0.3)
    assert one(0.8).startswith("#7 cup at") and ", class 0.80, exists 0.90" in one(0.8)


def test_the_summary_shows_no_class_confidence_for_an_unknown_object() -> None:
    """An object the classifier could give no class (it stays a PhysicalObject, "unknown object") was shown as
    ``unknown object (white) ..., class 0.99``, which reads as 99 % sure of a class (real uoc and PCL frames)."""
    stays_unknown = AttributeDesignator(value="PhysicalObject", confidence=0.99, experts=("KnowledgeClassifier",))
    unknown = ObjectDesignator(
        id=4,
        class_iri=class_iri("PhysicalObject"),
        class_label="unknown object",
        pose=PoseDesignator(position=(0.1, 0.2, 0.3), orientation=(0.0, 0.0, 0.0, 1.0), frame="camera"),
        size=None,
        size_class=None,
        region=None,
        attributes={"class": stays_unknown},
        experts=("KnowledgeClassifier",),
        confidence=0.8,
    )
    line = Answer(query="find all objects", objects=(unknown,)).summary()
    assert line.startswith("#4 unknown object at (0.100, 0.200, 0.300) [camera], exists 0.80")
    assert "class" not in line.split(" by ")[0]
