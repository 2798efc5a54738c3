"""Export for Protégé and owlready2, import from OWL files: round trips keep the meaning, foreign IRIs need a map."""

from __future__ import annotations

from pathlib import Path

import owlready2
import pytest
from rdflib import Graph
from rdflib.compare import isomorphic

from reasoning.errors import EditRejectedError
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.exchange import export_ontology
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base

RK = "http://robokudo.org/ontology#"

FOREIGN = """\
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix skos: <http://www.w3.org/2004/02/skos/core#> .
@prefix food: <http://example.org/food#> .
@prefix rk: <http://robokudo.org/ontology#> .

<http://example.org/food> a owl:Ontology .
food:SoyMilk a owl:Class ;
    rdfs:subClassOf food:Milch , [ a owl:Restriction ; owl:onProperty rk:typicalColor ; owl:someValuesFrom rk:Yellow ] ;
    rdfs:label "soy milk"@en ;
    skos:altLabel "soya drink"@en .
"""


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, KnowledgeBase]:
    """A user layer with two classes (one with its own default location) and the knowledge base that loads it."""
    user_file = tmp_path_factory.mktemp("exported") / "user.ttl"
    kb = load_knowledge_base(user_file)
    editor = OntologyEditor(kb, use_reasoner=False)
    editor.add_object("OatMilk", ["Milk"], colors=["white"], texts=["oat"], synonyms=["oat drink"])
    editor.add_object("PicnicCup", ["Cup"], colors=["red"], shape="cylinder", stored_in="cupboard", transparent=False)
    return user_file, kb


def load_in_owlready2(path: Path) -> owlready2.World:
    world = owlready2.World()
    world.get_ontology(path.as_uri()).load()
    return world


def storage_places(cls: owlready2.ThingClass, world: owlready2.World) -> set[str]:
    """The storedIn fillers on a class and its ancestors, as owlready2 reads them."""
    stored_in = world[RK + "storedIn"]
    return {
        r.value.name
        for ancestor in cls.ancestors()
        for r in ancestor.is_a
        if isinstance(r, owlready2.Restriction) and r.property is stored_in
    }


@pytest.mark.parametrize("fmt", ["xml", "owl"])
def test_owlready2_loads_the_merged_export_and_sees_the_new_class_under_milk(
    exported: tuple[Path, KnowledgeBase], tmp_path: Path, fmt: str
) -> None:
    _, kb = exported
    path = tmp_path / f"robokudo.{fmt}"
    path.write_bytes(export_ontology(kb, fmt, merged=True))
    world = load_in_owlready2(path)
    oat_milk, milk = world[RK + "OatMilk"], world[RK + "Milk"]
    assert milk in oat_milk.is_a
    assert storage_places(oat_milk, world) == {"Fridge"}  # its default location, inherited from milk
    assert storage_places(world[RK + "PicnicCup"], world) >= {"Cupboard"}
    assert [str(label) for label in oat_milk.label] == ["oat milk"]


@pytest.mark.parametrize("fmt", ["turtle", "xml", "owl"])
def test_importing_the_user_layer_export_into_an_empty_layer_gives_the_same_graph(
    exported: tuple[Path, KnowledgeBase], tmp_path: Path, fmt: str
) -> None:
    user_file, kb = exported
    path = tmp_path / f"user-layer.{ {'turtle': 'ttl'}.get(fmt, fmt) }"
    path.write_bytes(export_ontology(kb, fmt))
    if fmt != "turtle":
        assert milk_is_parent_in_owlready2(path)
    fresh = tmp_path / "fresh" / "user.ttl"
    result = OntologyEditor(KnowledgeBase.load(fresh), use_reasoner=False).import_file(path)
    assert result.name == "2 class(es) from " + path.name
    assert isomorphic(Graph().parse(fresh, format="turtle"), Graph().parse(user_file, format="turtle"))


def milk_is_parent_in_owlready2(path: Path) -> bool:
    world = load_in_owlready2(path)
    return world[RK + "Milk"] in world[RK + "OatMilk"].is_a


def test_importing_the_merged_export_brings_only_the_user_classes(
    exported: tuple[Path, KnowledgeBase], tmp_path: Path
) -> None:
    user_file, kb = exported
    path = tmp_path / "merged.owl"
    path.write_bytes(export_ontology(kb, "xml", merged=True))
    fresh = tmp_path / "fresh" / "user.ttl"
    OntologyEditor(load_knowledge_base(fresh), use_reasoner=False).import_file(path)
    assert isomorphic(Graph().parse(fresh, format="turtle"), Graph().parse(user_file, format="turtle"))


def test_a_class_outside_the_namespace_is_refused_and_nothing_is_written(tmp_path: Path, user_file: Path) -> None:
    foreign = tmp_path / "food.ttl"
    foreign.write_text(FOREIGN, encoding="utf-8")
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    with pytest.raises(EditRejectedError) as caught:
        editor.import_file(foreign)
    message = str(caught.value)
    assert (
        "2 IRI(s) outside the rk: namespace (<http://example.org/food#Milch>, <http://example.org/food#SoyMilk>)"
        in (message)
    )
    assert "--map NAMESPACE" in message and "--map IRI=NAME" in message
    assert not user_file.exists()
    assert editor.log() == []


def test_a_mapped_namespace_and_name_are_imported_into_rk(tmp_path: Path, user_file: Path) -> None:
    foreign = tmp_path / "food.ttl"
    foreign.write_text(FOREIGN, encoding="utf-8")
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    with pytest.raises(EditRejectedError, match=r"SoyMilk: superclass Milch is not declared \(a typo\?\)"):
        editor.import_file(foreign, namespaces=["http://example.org/food#"])  # food:Milch is no class of ours
    editor.import_file(
        foreign, namespaces=["http://example.org/food#"], names={"http://example.org/food#Milch": "Milk"}
    )
    profile = editor.kb.object_profile("soya drinks")
    assert (profile.name, profile.colors, profile.stored_in) == ("SoyMilk", ("Yellow",), "Fridge")
    assert editor.kb.is_subclass("SoyMilk", "Milk")


def test_an_imported_word_that_names_something_else_is_refused(tmp_path: Path, user_file: Path) -> None:
    clashing = tmp_path / "clash.ttl"
    clashing.write_text(
        "@prefix rk: <http://robokudo.org/ontology#> .\n@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\nrk:Soy a owl:Class ; rdfs:subClassOf rk:Milk ;"
        ' rdfs:label "cereal"@en .\n',
        encoding="utf-8",
    )
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    with pytest.raises(EditRejectedError, match="'cereal' already names the object class CerealBox"):
        editor.import_file(clashing)
    assert not user_file.exists()
