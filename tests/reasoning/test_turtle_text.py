"""Editing Turtle as text: what an edit does not touch stays byte for byte, and the result means what was asked."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rdflib import BNode, Graph, Literal
from rdflib.compare import isomorphic

from reasoning.knowledge.folded_triples import fold, from_ntriples, to_ntriples, unfold
from reasoning.knowledge.turtle_text import TextEditError, edit_turtle, parse, split_statements
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, SKOS, rk

BASE = "file:///tmp/user.ttl"

HAND_WRITTEN = """\
# my kitchen: written by hand
@prefix rk: <http://robokudo.org/ontology#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>
@prefix skos: <http://www.w3.org/2004/02/skos/core#> .

# the mug my aunt gave me
rk:AuntsMug a owl:Class ; rdfs:subClassOf rk:Mug ; rdfs:label "aunt's mug # not a comment"@en . # trailing
rk:Thermos a owl:Class ;
    rdfs:subClassOf rk:Bottle , [ a owl:Restriction ; owl:onProperty rk:storedIn ; owl:someValuesFrom rk:Shelf ] ;
    skos:altLabel "flask"@en , "vacuum bottle"@en ;
    rk:note 1.5 .
"""


def described(name: str, parent: str, color: str | None = None, synonyms: tuple[str, ...] = ()) -> frozenset:
    graph = Graph()
    subject = rk(name)
    graph.add((subject, RDF.type, OWL.Class))
    graph.add((subject, RDFS.subClassOf, rk(parent)))
    graph.add((subject, RDFS.label, Literal(name.lower(), lang="en")))
    for synonym in synonyms:
        graph.add((subject, SKOS.altLabel, Literal(synonym, lang="en")))
    if color:
        restriction = BNode()
        graph.add((subject, RDFS.subClassOf, restriction))
        graph.add((restriction, RDF.type, OWL.Restriction))
        graph.add((restriction, OWL.onProperty, rk("typicalColor")))
        graph.add((restriction, OWL.someValuesFrom, rk(color)))
    return fold(graph)


def test_statements_are_split_around_comments_strings_and_directives() -> None:
    bodies = [HAND_WRITTEN[s.start : s.end] for s in split_statements(HAND_WRITTEN)]
    assert [b.split()[0] for b in bodies] == ["@prefix", "@prefix", "PREFIX", "@prefix", "rk:AuntsMug", "rk:Thermos"]
    assert bodies[4].endswith('"aunt\'s mug # not a comment"@en .')
    assert bodies[5].endswith("rk:note 1.5 .")


def test_appending_keeps_the_text_and_removing_restores_it_byte_for_byte() -> None:
    oat_milk = described("OatMilk", "Milk", "White", ("oat drink",))
    added = edit_turtle(HAND_WRITTEN, BASE, frozenset(), oat_milk, "add-object OatMilk", 7)
    assert added.startswith(HAND_WRITTEN)
    block = added[len(HAND_WRITTEN) :]
    assert block.startswith("\n# >>> robokudo edit 7: add-object OatMilk\nrk:OatMilk a owl:Class ;")
    assert block.endswith("# <<< robokudo edit 7\n")
    assert "@prefix" not in block  # the file's prefixes are used
    assert edit_turtle(added, BASE, oat_milk, frozenset(), "remove-object OatMilk", 8) == HAND_WRITTEN


def test_removing_a_hand_written_class_cuts_only_its_statement() -> None:
    thermos = frozenset(t for t in fold(parse(HAND_WRITTEN, BASE)) if t[0] == rk("Thermos"))
    edited = edit_turtle(HAND_WRITTEN, BASE, thermos, frozenset(), "remove-object Thermos", 1)
    assert edited == HAND_WRITTEN[: HAND_WRITTEN.index("rk:Thermos")]


def test_removing_one_synonym_rewrites_only_that_statement() -> None:
    flask = frozenset({(rk("Thermos"), SKOS.altLabel, Literal("flask", lang="en"))})
    edited = edit_turtle(HAND_WRITTEN, BASE, flask, frozenset(), "synonym Thermos", 1)
    untouched = HAND_WRITTEN[: HAND_WRITTEN.index("rk:Thermos")]
    assert edited.startswith(untouched)
    assert "flask" not in edited and '"vacuum bottle"@en' in edited
    assert fold(parse(edited, BASE)) == fold(parse(HAND_WRITTEN, BASE)) - flask


def test_a_file_without_the_prefixes_gets_them_declared_in_the_block() -> None:
    text = "<http://robokudo.org/ontology#Bare> a <http://www.w3.org/2002/07/owl#Class> .\n"
    edited = edit_turtle(text, BASE, frozenset(), described("OatMilk", "Milk"), "add-object OatMilk", 1)
    assert "@prefix rk: <http://robokudo.org/ontology#> ." in edited
    assert fold(parse(edited, BASE)) == fold(parse(text, BASE)) | described("OatMilk", "Milk")


def test_triples_that_are_not_in_the_file_cannot_be_removed() -> None:
    with pytest.raises(TextEditError, match="not in the file"):
        edit_turtle(HAND_WRITTEN, BASE, described("OatMilk", "Milk"), frozenset(), "remove", 1)


def test_a_blank_node_shared_across_statements_is_refused_not_guessed() -> None:
    text = HAND_WRITTEN + "rk:Jar rdfs:subClassOf _:r .\nrk:Pot rdfs:subClassOf _:r .\n_:r a owl:Restriction .\n"
    with pytest.raises(TextEditError, match="blank node"):
        edit_turtle(text, BASE, frozenset(), described("OatMilk", "Milk"), "add", 1)


def test_folded_triples_survive_the_history_format() -> None:
    oat_milk = described("OatMilk", "Milk", "White", ("oat drink",))
    assert from_ntriples(to_ntriples(oat_milk)) == oat_milk
    assert isomorphic(unfold(oat_milk), unfold(from_ntriples(to_ntriples(oat_milk))))


names = st.lists(st.sampled_from(["Oat", "Rice", "Soy", "Almond", "Pea", "Hemp"]), min_size=1, max_size=6, unique=True)


@settings(max_examples=25, deadline=None)
@given(names, st.randoms(use_true_random=False))
def test_any_sequence_of_adds_then_removes_in_any_order_restores_the_file(order: list[str], rng: object) -> None:
    text = HAND_WRITTEN
    blocks = {}
    for number, name in enumerate(order, 1):
        blocks[name] = described(f"{name}Milk", "Milk", "White" if number % 2 else None, (f"{name.lower()} drink",))
        text = edit_turtle(text, BASE, frozenset(), blocks[name], f"add-object {name}Milk", number)
    removal = list(order)
    rng.shuffle(removal)  # type: ignore[attr-defined]
    for number, name in enumerate(removal, len(order) + 1):
        text = edit_turtle(text, BASE, blocks[name], frozenset(), f"remove-object {name}Milk", number)
    assert text == HAND_WRITTEN
