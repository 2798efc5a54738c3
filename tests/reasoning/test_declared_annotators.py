"""An annotator is declared once, by its Python class: the knowledge base holds exactly what the class declares,
rejects a class whose declaration names something the ontology lacks, and rejects annotators declared in Turtle."""

from __future__ import annotations

from pathlib import Path

import pytest

from annotators.catalog import AnnotatorCatalog
from annotators.image.color import SemanticColorAnnotator
from reasoning.errors import EditRejectedError, OntologyError
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base
from robokudo.core.annotator import Annotator
from robokudo.core.capability import DEFAULT_COST_MS, DEFAULT_RELIABILITY, Capability
from robokudo.core.types import Annotation, ColorImage, ObjectHypothesis, SemanticColor, Shape
from tests.reasoning.helpers import write_ttl


def expert(name: str, **members: object) -> type[Annotator]:
    """A throw-away annotator class (loading never runs it)."""
    ports = {"inputs": (ObjectHypothesis,), "outputs": (SemanticColor,)}
    return type(name, (Annotator,), {"__module__": __name__, **ports, **members})


def names(types: tuple[type, ...]) -> set[str]:
    return {t.__name__ for t in types}


def test_the_knowledge_base_holds_every_catalog_annotator_as_its_class_declares_it(kb: KnowledgeBase) -> None:
    catalog = AnnotatorCatalog.discover()
    assert {spec.name for spec in kb.annotators()} == set(catalog)
    for name, cls in catalog.items():
        spec, capability = kb.annotator(name), cls.capability
        assert spec.implemented_by == f"{cls.__module__}.{cls.__qualname__}"
        assert set(spec.inputs) == names(cls.inputs), name
        assert set(spec.optional_inputs) == names(cls.optional_inputs), name
        assert set(spec.outputs) == names(cls.outputs), name
        assert spec.colors == set(capability.colors), name
        assert spec.shapes == set(capability.shapes), name
        assert spec.sizes == set(capability.sizes), name
        assert spec.materials == set(capability.materials), name
        assert spec.classes == set(capability.classes), name
        assert set(spec.preconditions) == set(capability.preconditions), name
        assert (spec.cost_ms, spec.reliability) == (capability.cost_ms, capability.reliability), name
        assert spec.label == kb.label(name) == capability.label, name
        assert kb.synonyms(name) == tuple(sorted(capability.synonyms)), name


def test_the_colour_expert_reports_exactly_its_declared_colours(kb: KnowledgeBase) -> None:
    spec = kb.annotator("SemanticColorAnnotator")
    assert spec.colors == set(SemanticColorAnnotator.capability.colors) and "Red" in spec.colors
    assert (spec.inputs, spec.outputs) == (("ColorImage", "ObjectHypothesis"), ("SemanticColor",))
    assert (spec.cost_ms, spec.reliability) == (3.0, 0.8)
    assert kb.synonyms("TextReader") == ("OCR",)
    where = kb.defined_in("ClusterExtractor")
    assert where is not None and where.name == "clusters.py"  # `ontology show` says "defined in clusters.py"


def test_annotator_without_a_declared_capability_gets_the_defaults(tmp_path: Path) -> None:
    plain = expert("PlainColourNamer", __doc__="Names colours plainly.\n\nMore detail here.")
    kb = KnowledgeBase.load(tmp_path / "user.ttl", annotators=[plain])
    spec = kb.annotator("PlainColourNamer")
    assert (spec.cost_ms, spec.reliability) == (DEFAULT_COST_MS, DEFAULT_RELIABILITY)
    assert spec.label == "plain colour namer" and spec.colors == frozenset() and spec.preconditions == ()
    assert [s.name for s in kb.providers("SemanticColor", value="teal")] == ["PlainColourNamer"]


def test_a_knowledge_base_without_annotator_classes_has_no_annotators(tmp_path: Path) -> None:
    kb = KnowledgeBase.load(tmp_path / "user.ttl")
    assert kb.annotators() == [] and kb.providers("SemanticColor") == []
    assert kb.is_subclass("WholeMilk", "Milk")


@pytest.mark.parametrize(
    ("members", "bad"),
    [
        ({"capability": Capability(preconditions=("NeedsSunshine",))}, "capability.preconditions names NeedsSunshine"),
        ({"capability": Capability(colors=("Red", "Ultraviolet"))}, "capability.colors names Ultraviolet"),
        ({"capability": Capability(colors=("Milk",))}, "capability.colors names Milk"),
        ({"capability": Capability(classes=("Unicorn",))}, "capability.classes names Unicorn"),
        ({"capability": Capability(shapes=("Red",))}, "capability.shapes names Red"),
        ({"outputs": (int,)}, "outputs names int, which is not a CAS type"),
        ({"outputs": (type("Sparkle", (Annotation,), {}),)}, "outputs names Sparkle, which is not a CAS type"),
        ({"inputs": ("ColorImage",)}, "inputs holds 'ColorImage', which is not a CAS type"),
        ({"outputs": ()}, "provides no output"),
    ],
)
def test_a_bad_declaration_is_rejected_at_load_naming_the_class(
    tmp_path: Path, members: dict[str, object], bad: str
) -> None:
    broken = expert("BrokenExpert", **members)
    with pytest.raises(OntologyError) as raised:
        KnowledgeBase.load(tmp_path / "user.ttl", annotators=[*AnnotatorCatalog.discover().values(), broken])
    message = str(raised.value)
    assert f"annotator class BrokenExpert ({__name__}.BrokenExpert)" in message and bad in message
    assert "SemanticColorAnnotator" not in message  # only the broken class is blamed


def test_a_capability_with_impossible_values_fails_when_the_class_is_written() -> None:
    with pytest.raises(ValueError, match="reliability"):
        Capability(reliability=1.5)
    with pytest.raises(ValueError, match="cost_ms"):
        Capability(cost_ms=-1.0)
    with pytest.raises(TypeError, match="colors"):
        Capability(colors="Red")  # type: ignore[arg-type]


def test_two_classes_with_the_same_name_are_rejected(tmp_path: Path) -> None:
    impostor = expert("SemanticColorAnnotator")
    with pytest.raises(OntologyError, match="two annotator classes are called SemanticColorAnnotator"):
        KnowledgeBase.load(tmp_path / "user.ttl", annotators=[SemanticColorAnnotator, impostor])
    kb = KnowledgeBase.load(tmp_path / "user.ttl", annotators=[SemanticColorAnnotator, SemanticColorAnnotator])
    assert [spec.name for spec in kb.annotators()] == ["SemanticColorAnnotator"]


@pytest.mark.parametrize(
    "turtle",
    [
        """rk:GhostFilter a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.cloud.filters.GhostFilter" ;
    rk:requiresInput rk:PointCloud ;
    rk:providesOutput rk:PointCloud .
""",
        'rk:Evil a owl:NamedIndividual , rk:Annotator ; rk:implementedBy "os.system" .\n',
        "rk:SemanticColorAnnotator rk:reliability 0.99 .\n",
        "rk:Detector a owl:Class ; rdfs:subClassOf rk:Annotator .\nrk:MyDetector a rk:Detector .\n",
    ],
)
def test_an_annotator_declared_in_turtle_is_rejected(tmp_path: Path, turtle: str) -> None:
    extra = write_ttl(tmp_path / "annotator.ttl", turtle)
    with pytest.raises(OntologyError, match="annotators are declared by their Python class") as raised:
        load_knowledge_base(tmp_path / "user.ttl", extra_files=[extra])
    assert str(extra) in str(raised.value)


def test_reload_keeps_the_annotator_classes(tmp_path: Path) -> None:
    extra = write_ttl(tmp_path / "extra.ttl", 'rk:Mug2 a owl:Class ; rdfs:subClassOf rk:Cup ; rdfs:label "mug two" .\n')
    colour = expert("TealSpotter", capability=Capability(colors=("Teal",), reliability=0.9))
    kb = KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra], annotators=[colour])
    extra.write_text(extra.read_text() + 'rk:Mug3 a owl:Class ; rdfs:subClassOf rk:Cup ; rdfs:label "mug three" .\n')
    kb.reload()
    assert kb.is_subclass("Mug3", "Cup")
    assert [s.name for s in kb.providers("SemanticColor", value="teal")] == ["TealSpotter"]
    assert kb.annotator_classes == (colour,)


def test_editing_validates_with_the_annotators_and_keeps_them(tmp_path: Path) -> None:
    user_file = tmp_path / "user.ttl"
    editor = OntologyEditor(load_knowledge_base(user_file), use_reasoner=False)
    editor.add_object("OatMilk", ["Milk"], colors=["white"])
    shape_expert = expert(
        "OatMilkDetector", outputs=(Shape,), capability=Capability(classes=("OatMilk",), reliability=0.9)
    )
    kb = load_knowledge_base(user_file, extra_annotators=[shape_expert])
    assert "OatMilkDetector" in [s.name for s in kb.providers("Shape", object_class="OatMilk")]
    with pytest.raises(EditRejectedError, match="still used by: OatMilkDetector"):
        OntologyEditor(kb, use_reasoner=False).remove_object("OatMilk")
    assert editor.kb.annotator("SemanticColorAnnotator").colors  # the edit reloaded with the annotators kept
    with pytest.raises(EditRejectedError, match="clashes with the existing term SemanticColorAnnotator"):
        editor.add_object("SemanticColorAnnotator", ["Cup"])


@pytest.mark.slow
def test_hermit_classifies_the_ontology_with_the_annotator_individuals(tmp_path: Path) -> None:
    kb = load_knowledge_base(tmp_path / "user.ttl", reason=True)
    result = kb.reasoner_result
    assert result is not None and result.ok, result
    assert kb.annotator("KnowledgeClassifier").classes == {"PhysicalObject"}
    assert kb.is_subclass("Milk", "RefrigeratedItem")


def test_an_annotator_input_unknown_to_the_ontology_is_named(tmp_path: Path) -> None:
    reader = expert("ColourOnly", inputs=(ColorImage, type("Infrared", (Annotation,), {})))
    with pytest.raises(OntologyError, match=r"annotator class ColourOnly .*: inputs names Infrared"):
        KnowledgeBase.load(tmp_path / "user.ttl", annotators=[reader])
