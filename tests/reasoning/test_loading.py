"""Loading the shipped ontology: files, counts, CAS types, query keys, value classes."""

from __future__ import annotations

from pathlib import Path

import pytest
from rdflib import Graph

from ontology import EXAMPLE_USER_MAP_FILE, ontology_dir, shipped_files
from reasoning.errors import OntologyError
from reasoning.knowledge.editing import check_cas_types
from reasoning.knowledge.knowledge_base import KnowledgeBase
from tests.reasoning.helpers import write_ttl


def test_every_shipped_file_is_valid_turtle_on_its_own() -> None:
    for path in [*shipped_files(), ontology_dir() / EXAMPLE_USER_MAP_FILE]:
        assert len(Graph().parse(path, format="turtle")) > 10, path


def test_loads_with_at_least_sixty_object_classes(kb: KnowledgeBase) -> None:
    classes = kb.names_of_kind("class")
    assert len(classes) >= 60
    assert {"PhysicalObject", "FoodOrDrink", "Drink", "Milk", "WholeMilk", "LactoseFreeMilk", "SkimMilk"} <= set(
        classes
    )
    assert {"CerealBox", "Container", "Cup", "Mug", "Bowl", "Bottle", "Cutlery"} <= set(classes)


def test_every_object_class_has_a_label(kb: KnowledgeBase) -> None:
    assert all(name in kb.index.labels for name in kb.names_of_kind("class"))


def test_region_classes(kb: KnowledgeBase) -> None:
    assert {"Fridge", "Table", "CounterTop", "Shelf", "Drawer", "Cupboard"} <= set(kb.names_of_kind("region_class"))


def test_value_classes_have_lower_case_labels(kb: KnowledgeBase) -> None:
    colors = {kb.label(c) for c in kb.names_of_kind("color")}
    expected = {"red", "orange", "yellow", "green", "blue", "purple", "pink", "brown", "white", "grey", "black"}
    assert expected <= colors
    assert {kb.label(s) for s in kb.names_of_kind("shape")} == {"box", "cylinder", "sphere", "flat"}
    assert {kb.label(s) for s in kb.names_of_kind("size")} == {"small", "medium", "large"}
    for kind in ("color", "shape", "size"):
        assert all(kb.label(n) == kb.label(n).lower() for n in kb.names_of_kind(kind))


def test_cas_types_match_the_runtime(kb: KnowledgeBase) -> None:
    assert check_cas_types(kb) == []


@pytest.mark.parametrize(
    ("key", "annotation_type"),
    [
        ("color", "SemanticColor"),
        ("colour", "SemanticColor"),
        ("type", "Classification"),
        ("class", "Classification"),
        ("text", "Text"),
        ("pose", "Pose"),
        ("shape", "Shape"),
        ("size", "Size"),
        ("location", "Location"),
        ("Color", "SemanticColor"),
    ],
)
def test_query_keys(kb: KnowledgeBase, key: str, annotation_type: str) -> None:
    assert kb.annotation_type_for_key(key) == annotation_type


def test_unknown_query_key_suggests(kb: KnowledgeBase) -> None:
    with pytest.raises(KeyError, match="colr"):
        kb.annotation_type_for_key("colr")


def test_shipped_words_are_unambiguous_within_a_kind(kb: KnowledgeBase) -> None:
    for key, found in kb.index.words.items():
        kinds = [r.kind for r in found]
        assert len(kinds) == len(set(kinds)), (key, found)


def test_missing_user_file_is_an_empty_layer(tmp_path: Path) -> None:
    kb = KnowledgeBase.load(tmp_path / "nothing-here.ttl")
    assert kb.resolve("milk").name == "Milk"


def test_syntax_error_names_the_file(tmp_path: Path) -> None:
    broken = tmp_path / "broken.ttl"
    broken.write_text("rk:Milk a owl:Class", encoding="utf-8")
    with pytest.raises(OntologyError, match=r"broken\.ttl"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[broken])


def test_undeclared_superclass_is_reported(tmp_path: Path) -> None:
    extra = write_ttl(tmp_path / "typo.ttl", "rk:Oats a owl:Class ; rdfs:subClassOf rk:Cerael .\n")
    with pytest.raises(OntologyError, match="Cerael"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])


def test_restriction_with_a_wrong_kind_of_value_is_reported(tmp_path: Path) -> None:
    extra = write_ttl(
        tmp_path / "bad.ttl",
        "rk:Oats a owl:Class ; rdfs:subClassOf rk:Food , "
        "[ a owl:Restriction ; owl:onProperty rk:typicalColor ; owl:someValuesFrom rk:Fridge ] .\n",
    )
    with pytest.raises(OntologyError, match="typicalColor"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])
