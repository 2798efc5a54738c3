"""Capability questions: providers by annotation type, value domain under subsumption, preconditions."""

from __future__ import annotations

from pathlib import Path

import pytest

from reasoning.errors import OntologyError, UnknownTermError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import Conditions
from robokudo.application.knowledge import load_knowledge_base
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, Classification, ColorImage, ObjectHypothesis, PointCloud, SemanticColor
from tests.reasoning.helpers import write_ttl


class BowlDetector(Annotator):
    """Test-only: detects white ceramic bowls."""

    inputs = (ColorImage,)
    outputs = (ObjectHypothesis, Classification)
    capability = Capability(classes=("WhiteCeramicBowl",), cost_ms=40.0, reliability=0.95)


class MilkDetector(Annotator):
    """Test-only: detects milk."""

    inputs = (ColorImage,)
    outputs = (ObjectHypothesis, Classification)
    capability = Capability(classes=("Milk",), cost_ms=40.0, reliability=0.7)


class CheapColor(Annotator):
    """Test-only: a cheap colour namer for red and teal."""

    inputs = (ObjectHypothesis,)
    outputs = (SemanticColor,)
    capability = Capability(colors=("Red", "Teal"), cost_ms=1.0, reliability=0.8)


class RegionCropper(Annotator):
    """Test-only: crops the cloud to the query's region."""

    inputs = (PointCloud, CameraInfo)
    outputs = (PointCloud,)
    capability = Capability(preconditions=("NeedsRegion",), cost_ms=1.0, reliability=1.0)


@pytest.fixture(scope="module")
def test_kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The application's knowledge base plus the test-only annotators (loading does not run their code)."""
    folder = tmp_path_factory.mktemp("capabilities")
    return load_knowledge_base(
        folder / "user.ttl", extra_annotators=[BowlDetector, MilkDetector, CheapColor, RegionCropper]
    )


def names(specs: list) -> list[str]:
    return [s.name for s in specs]


def test_providers_of_semantic_color_for_red(kb: KnowledgeBase) -> None:
    assert names(kb.providers("SemanticColor", value="red")) == ["SemanticColorAnnotator"]
    assert names(kb.providers("SemanticColor", value="Red")) == ["SemanticColorAnnotator"]
    assert kb.providers("SemanticColor", value="teal") == []


def test_providers_rank_by_reliability_then_cost(test_kb: KnowledgeBase) -> None:
    # same reliability 0.8: the cheaper one first
    assert names(test_kb.providers("SemanticColor", value="red")) == ["CheapColor", "SemanticColorAnnotator"]
    assert names(test_kb.providers("SemanticColor", value="teal")) == ["CheapColor"]
    assert names(test_kb.providers("SemanticColor", value="white")) == ["SemanticColorAnnotator"]


def test_a_colour_no_expert_reports_is_asked_as_its_basic_colours(kb: KnowledgeBase, test_kb: KnowledgeBase) -> None:
    assert kb.basic_colors("Teal") == ("Blue", "Green") and kb.basic_colors("Blue") == ()
    assert kb.reported_as("SemanticColor", "Teal") == ("Blue", "Green")  # the shipped namer says no teal
    assert kb.reported_as("SemanticColor", "Red") == ("Red",)
    assert kb.reported_as("SemanticColor", "Silver") == ("Silver",)  # no basic colours: refused by the planner
    assert test_kb.reported_as("SemanticColor", "Teal") == ("Teal",)  # CheapColor says teal


def test_detector_of_a_subclass_serves_a_query_for_the_superclass(test_kb: KnowledgeBase) -> None:
    assert "BowlDetector" in names(test_kb.providers("Classification", value="Bowl"))
    assert "BowlDetector" in names(test_kb.providers("ObjectHypothesis", object_class="Bowl"))
    assert "BowlDetector" in names(test_kb.providers("Classification", value="Container"))
    assert "BowlDetector" not in names(test_kb.providers("Classification", value="Milk"))
    assert "BowlDetector" not in names(test_kb.providers("ObjectHypothesis", object_class="Cup"))


def test_detector_of_a_superclass_serves_a_query_for_a_subclass(test_kb: KnowledgeBase) -> None:
    found = names(test_kb.providers("Classification", value="LactoseFreeMilk"))
    # the KnowledgeClassifier reports any PhysicalObject, so it serves every class too
    assert [name for name in found if name != "KnowledgeClassifier"] == ["MilkDetector"]
    assert "KnowledgeClassifier" in found


def test_annotators_without_class_domain_serve_any_class(test_kb: KnowledgeBase) -> None:
    found = names(test_kb.providers("ObjectHypothesis", object_class="Cup"))
    assert found == ["ClutterSegmenter", "ClusterExtractor", "ImageRegionSegmenter"]  # by reliability


def test_not_transparent_precondition_excludes_glass(kb: KnowledgeBase) -> None:
    assert "NotForTransparentObjects" in kb.annotator("ClusterExtractor").preconditions
    assert "ClusterExtractor" in names(kb.providers("ObjectHypothesis", object_class="Cup"))
    assert "ClusterExtractor" not in names(kb.providers("ObjectHypothesis", object_class="Glass"))
    assert "ClusterExtractor" not in names(kb.providers("ObjectHypothesis", object_class="wine glasses"))


def test_depth_and_region_preconditions(test_kb: KnowledgeBase) -> None:
    assert "PointCloudGenerator" in names(test_kb.providers("PointCloud"))
    no_depth = Conditions(depth=False)
    assert "PointCloudGenerator" not in names(test_kb.providers("PointCloud", conditions=no_depth))
    assert "RegionCropper" in names(test_kb.providers("PointCloud"))
    assert "RegionCropper" not in names(test_kb.providers("PointCloud", conditions=Conditions(region=False)))


def test_providers_include_subtypes_and_views(kb: KnowledgeBase) -> None:
    assert set(names(kb.providers("ColorImage"))) == {
        "KitchenSceneReader", "ColorDepthPairReader", "TumSequenceReader", "TumPairReader", "PcdReader",
        "TiffSequenceReader", "BagReader", "BagCloudReader", "StreamReader", "PerceivedFrameReader",
        "Open3dFolderReader",
    }  # fmt: skip
    assert "SemanticColorAnnotator" in names(kb.providers("Annotation"))


def test_value_of_the_wrong_kind_is_an_error(kb: KnowledgeBase) -> None:
    with pytest.raises(UnknownTermError, match="colour"):
        kb.providers("SemanticColor", value="Milk")
    with pytest.raises(UnknownTermError, match="CAS type"):
        kb.providers("SemanticColour")


def test_inputs_of_an_annotator(kb: KnowledgeBase) -> None:
    assert set(kb.inputs_of("ClusterExtractor")) == {"PointCloud", "Plane"}
    spec = kb.annotator("PointCloudGenerator")
    assert set(spec.inputs) == {"DepthImage", "CameraInfo"}
    assert spec.optional_inputs == ("ColorImage",)
    assert spec.outputs == ("PointCloud",)
    assert spec.implemented_by == "annotators.cloud.point_cloud.PointCloudGenerator"
    assert spec.cost_ms > 0 and 0 < spec.reliability <= 1


def test_a_user_colour_is_asked_as_its_basic_colours_and_basic_colours_must_link_colours(tmp_path: Path) -> None:
    extra = write_ttl(
        tmp_path / "colours.ttl",
        'rk:Mint a owl:Class ; rdfs:subClassOf rk:Color ; rdfs:label "mint"@en ; rk:basicColor rk:Green .\n'
        'rk:Ochre a owl:Class ; rdfs:subClassOf rk:Color ; rdfs:label "ochre"@en .\n',
    )
    user = KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])
    assert user.reported_as("SemanticColor", "Mint") == ("Green",)
    assert user.reported_as("SemanticColor", "Ochre") == ("Ochre",)  # no basic colour: asked as itself
    wrong = write_ttl(tmp_path / "wrong.ttl", "rk:Cup rk:basicColor rk:Blue .\nrk:Teal rk:basicColor rk:Teal .\n")
    with pytest.raises(OntologyError) as error:
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[wrong])
    assert "Cup rk:basicColor Blue" in str(error.value) and "Teal rk:basicColor Teal" in str(error.value)
