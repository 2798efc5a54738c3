"""The incremental check of new classes decides exactly what HermiT decides, and hands anything else to HermiT."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from rdflib import BNode, Graph, Literal
from rdflib.term import Node

from reasoning.knowledge import vocabulary
from reasoning.knowledge.folded_triples import fold
from reasoning.knowledge.fresh_classes import Fragment, annotation_properties, check_fresh_classes
from reasoning.knowledge.hermit import classify, find_java
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.reasoner_cache import Classification
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, rk
from robokudo.application.knowledge import load_knowledge_base

NEW_CLASSES = 80


def restrict(graph: Graph, subject: Node, prop: str, kind: Node, value: Node) -> None:
    node = BNode()
    graph.add((subject, RDFS.subClassOf, node))
    graph.add((node, RDF.type, OWL.Restriction))
    graph.add((node, OWL.onProperty, rk(prop)))
    graph.add((node, kind, value))


def random_classes(kb: KnowledgeBase, rng: random.Random) -> Graph:
    """New classes as users and imports write them: one or two parents (sometimes disjoint ones), colours, shapes,
    storage places (sometimes a colour, which is no region), transparency, printed texts and height-to-width
    ratios of every type."""
    objects = kb.names_of_kind("class")
    everything = sorted(kb.index.classes)
    colors, shapes = kb.names_of_kind("color"), kb.names_of_kind("shape")
    regions = kb.names_of_kind("region_class")
    graph = Graph()
    for i in range(NEW_CLASSES):
        subject = rk(f"Random{i}")
        graph.add((subject, RDF.type, OWL.Class))
        pool = objects if rng.random() < 0.8 else everything
        for parent in rng.sample(pool, rng.choice([1, 1, 2])):
            graph.add((subject, RDFS.subClassOf, rk(parent)))
        if rng.random() < 0.5:
            restrict(graph, subject, "typicalColor", OWL.someValuesFrom, rk(rng.choice([*colors, shapes[0]])))
        if rng.random() < 0.4:
            restrict(graph, subject, "storedIn", OWL.someValuesFrom, rk(rng.choice([*regions, colors[0]])))
        if rng.random() < 0.3:
            value = rng.choice([Literal(True), Literal(False), Literal("yes")])
            restrict(graph, subject, "transparent", OWL.hasValue, value)
        if rng.random() < 0.2:
            value = rng.choice(
                [Literal("oat"), Literal("oat", lang="en"), Literal("oat", datatype=vocabulary.XSD.string)]
            )
            restrict(graph, subject, "printedText", OWL.hasValue, value)
        if rng.random() < 0.2:
            value = rng.choice(
                [Literal("1.5", datatype=vocabulary.XSD.decimal), Literal(2), Literal("tall"), Literal(0.5)]
            )
            restrict(graph, subject, "maxHeightToWidth", OWL.hasValue, value)
    return graph


def own_triples(graph: Graph, name: str) -> frozenset:
    return frozenset(t for t in fold(graph) if t[0] == rk(name))


@pytest.mark.slow
@pytest.mark.skipif(find_java() is None, reason="HermiT needs Java")
def test_the_incremental_check_agrees_with_hermit_on_random_new_classes(tmp_path: Path) -> None:
    kb = load_knowledge_base(tmp_path / "user.ttl")
    base, _ = kb.combine(kb.source_graphs())
    classified = classify(base)
    assert classified.ok and classified.inferred is not None
    classification = Classification("base", classified.inferred.parents, classified.inferred.ancestors, "HermiT")
    new = random_classes(kb, random.Random(7))
    hermit = classify(base + new)  # new classes never affect each other: one run decides them all
    assert hermit.available and hermit.consistent
    annotations = annotation_properties(base)
    fragment = Fragment.of([base], annotations)
    unsatisfiable = 0
    for i in range(NEW_CLASSES):
        name = f"Random{i}"
        found = check_fresh_classes(fragment, classification, own_triples(new, name), annotations)
        assert found.supported, found.reason
        assert bool(found.problems) == (name in hermit.unsatisfiable), (name, found.problems)
        if found.problems:
            unsatisfiable += 1
            continue
        assert hermit.inferred is not None
        assert found.ancestors[name] == hermit.inferred.ancestors[name], name
    assert 10 <= unsatisfiable <= NEW_CLASSES - 10  # both outcomes were tried


@pytest.fixture(scope="module")
def asserted(tmp_path_factory: pytest.TempPathFactory) -> tuple[Graph, Classification]:
    """The shipped ontology with its asserted hierarchy standing in for a stored classification."""
    kb = KnowledgeBase.load(tmp_path_factory.mktemp("fresh") / "user.ttl")
    index = kb.index
    parents = {n: frozenset(p) for n, p in index.parents.items()}
    ancestors = {n: up - {n} for n, up in index.up.items()}
    return kb.combine(kb.source_graphs())[0], Classification("asserted", parents, ancestors, "asserted")


def test_a_clash_is_explained(asserted: tuple[Graph, Classification]) -> None:
    base, classification = asserted
    new = Graph()
    new.add((rk("MilkMug"), RDF.type, OWL.Class))
    new.add((rk("MilkMug"), RDFS.subClassOf, rk("Milk")))
    new.add((rk("MilkMug"), RDFS.subClassOf, rk("Mug")))
    annotations = annotation_properties(base)
    found = check_fresh_classes(Fragment.of([base], annotations), classification, fold(new), annotations)
    assert found.supported
    assert found.problems == (
        "MilkMug can have no instances: it is under FoodOrDrink and Tableware, which are disjoint",
    )


@pytest.mark.parametrize(
    ("extra", "reason"),
    [
        ("rk:Sieve owl:disjointWith rk:Pan .", "rk:Sieve gets a http://www.w3.org/2002/07/owl#disjointWith axiom"),
        (
            "rk:storedIn a owl:FunctionalProperty .",
            "rk:storedIn is declared a http://www.w3.org/2002/07/owl#Functional",
        ),
        (
            "rk:Sieve rdfs:subClassOf [ a owl:Restriction ; owl:onProperty rk:storedIn ; owl:allValuesFrom rk:Shelf ] "
            ".",
            "rk:storedIn",
        ),
        ("rk:Milk rdfs:subClassOf rk:Sieve .", "rk:Sieve is not new"),
    ],
)
def test_what_the_check_does_not_decide_goes_to_hermit(
    asserted: tuple[Graph, Classification], extra: str, reason: str
) -> None:
    base, classification = asserted
    prefixes = (
        "@prefix rk: <http://robokudo.org/ontology#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
    )
    text = prefixes + "rk:Sieve a owl:Class ; rdfs:subClassOf rk:Utensil .\n"
    extra_graph = Graph().parse(data=prefixes + extra, format="turtle")
    new = Graph().parse(data=text, format="turtle")
    in_base = extra.startswith(("rk:storedIn", "rk:Milk"))
    added = fold(new) if in_base else fold(new) | fold(extra_graph)
    annotations = annotation_properties(base)
    graphs = [base, extra_graph] if in_base else [base]
    found = check_fresh_classes(Fragment.of(graphs, annotations), classification, added, annotations)
    assert not found.supported
    assert reason in found.reason
