"""Capability questions: providers by annotation type, value domain under subsumption, preconditions."""

from __future__ import annotations

from pathlib import Path

import pytest

from reasoning.errors import OntologyError, UnknownTermError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import Conditions
from tests.reasoning.helpers import write_ttl

# Test-only annotators layered over the shipped ones (never imported: loading does not import code).
TEST_ANNOTATORS = """
rk:BowlDetector a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.test_only.BowlDetector" ;
    rk:requiresInput rk:ColorImage ;
    rk:providesOutput rk:ObjectHypothesis , rk:Classification ;
    rk:canReportClass rk:WhiteCeramicBowl ;
    rk:expectedCostMs 40.0 ;
    rk:reliability 0.95 .

rk:MilkDetector a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.test_only.MilkDetector" ;
    rk:requiresInput rk:ColorImage ;
    rk:providesOutput rk:ObjectHypothesis , rk:Classification ;
    rk:canReportClass rk:Milk ;
    rk:expectedCostMs 40.0 ;
    rk:reliability 0.7 .

rk:CheapColor a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.test_only.CheapColor" ;
    rk:requiresInput rk:ObjectHypothesis ;
    rk:providesOutput rk:SemanticColor ;
    rk:canReportColor rk:Red , rk:Teal ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 0.8 .

rk:RegionCropper a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.test_only.RegionCropper" ;
    rk:requiresInput rk:PointCloud , rk:CameraInfo ;
    rk:providesOutput rk:PointCloud ;
    rk:precondition rk:NeedsRegion ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 1.0 .
"""


@pytest.fixture(scope="module")
def test_kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    folder = tmp_path_factory.mktemp("capabilities")
    extra = write_ttl(folder / "test_annotators.ttl", TEST_ANNOTATORS)
    return KnowledgeBase.load(folder / "user.ttl", extra_files=[extra])


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
    assert found == ["ClusterExtractor", "ImageRegionSegmenter"]  # by reliability


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
        "TiffSequenceReader",
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


@pytest.mark.parametrize(
    "target",
    ["os.system", "subprocess.Popen", "annotatorsx.evil.Class", "annotators.NoModule", "annotators", "builtins.eval"],
)
def test_implementation_outside_the_annotators_package_is_rejected_at_load(tmp_path: Path, target: str) -> None:
    extra = write_ttl(
        tmp_path / "evil.ttl",
        f"""rk:Evil a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "{target}" ;
    rk:providesOutput rk:Text ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 1.0 .
""",
    )
    with pytest.raises(OntologyError, match="annotators"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])


def test_annotator_with_an_unknown_port_type_is_rejected(tmp_path: Path) -> None:
    extra = write_ttl(
        tmp_path / "bad.ttl",
        """rk:Odd a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.odd.Odd" ;
    rk:providesOutput rk:Milk ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 1.0 .
""",
    )
    with pytest.raises(OntologyError, match="Milk is not a CAS type"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])
