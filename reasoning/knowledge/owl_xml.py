"""OWL/XML (the OWL 2 XML serialization Protégé and owlready2 read) of an RDF graph of an OWL ontology.

Covers what RoboKudo ontologies hold and the usual OWL 2 class expressions: declarations; subclass, equivalent and
disjoint classes (``owl:AllDisjointClasses`` too); restrictions (some, all, value, cardinalities), intersections,
unions, complements and enumerations; property domains, ranges and sub-properties; class and property assertions
of individuals; annotations (on entities and on the ontology) and imports. Anything else raises ValueError naming it.
"""

from __future__ import annotations

from collections.abc import Iterable
from xml.sax.saxutils import escape, quoteattr

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.collection import Collection
from rdflib.term import Node

from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, RK, SKOS, XSD

_PREFIXES = {"rk": str(RK), "owl": str(OWL), "rdf": str(RDF), "rdfs": str(RDFS), "xsd": str(XSD), "skos": str(SKOS)}
_STANDARD_ANNOTATIONS = {
    RDFS.label,
    RDFS.comment,
    RDFS.seeAlso,
    RDFS.isDefinedBy,
    OWL.versionInfo,
    OWL.deprecated,
    SKOS.altLabel,
    SKOS.prefLabel,
    SKOS.hiddenLabel,
    SKOS.definition,
    SKOS.note,
    SKOS.example,
}
_DECLARED = {
    OWL.Class: "Class",
    OWL.ObjectProperty: "ObjectProperty",
    OWL.DatatypeProperty: "DataProperty",
    OWL.AnnotationProperty: "AnnotationProperty",
    OWL.NamedIndividual: "NamedIndividual",
}
_CARDINALITIES = {
    OWL.minCardinality: "MinCardinality",
    OWL.maxCardinality: "MaxCardinality",
    OWL.cardinality: "ExactCardinality",
    OWL.minQualifiedCardinality: "MinCardinality",
    OWL.maxQualifiedCardinality: "MaxCardinality",
    OWL.qualifiedCardinality: "ExactCardinality",
}


def to_owl_xml(graph: Graph) -> str:
    """The OWL/XML document of ``graph`` (one ontology: the subject typed ``owl:Ontology``, if any)."""
    return _Writer(graph).document()


def _iri(node: Node) -> str:
    return f"IRI={quoteattr(str(node))}"


class _Writer:
    def __init__(self, graph: Graph) -> None:
        self.graph = graph
        self.object_properties = set(graph.subjects(RDF.type, OWL.ObjectProperty))
        self.data_properties = set(graph.subjects(RDF.type, OWL.DatatypeProperty))
        self.annotation_properties = _STANDARD_ANNOTATIONS | set(graph.subjects(RDF.type, OWL.AnnotationProperty))

    def document(self) -> str:
        graph = self.graph
        ontologies = sorted(s for s in graph.subjects(RDF.type, OWL.Ontology) if isinstance(s, URIRef))
        ontology = ontologies[0] if ontologies else None
        head = [f"<Prefix name={quoteattr(p)} {_iri(iri)}/>" for p, iri in _PREFIXES.items()]
        axioms: list[str] = []
        for subject in sorted({s for s in graph.subjects() if isinstance(s, URIRef)}, key=str):
            if subject in ontologies:
                if subject == ontology:
                    head += self._ontology_header(subject)
                continue
            axioms += self._about(subject)
        for group in graph.subjects(RDF.type, OWL.AllDisjointClasses):
            members = [
                self._class(m) for head_node in graph.objects(group, OWL.members) for m in Collection(graph, head_node)
            ]
            axioms.append(f"<DisjointClasses>{''.join(members)}</DisjointClasses>")
        attributes = f" ontologyIRI={quoteattr(str(ontology))}" if ontology is not None else ""
        lines = [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<Ontology xmlns="http://www.w3.org/2002/07/owl#"{attributes}>',
            *(f"  {line}" for line in head),
            *(f"  {line}" for line in sorted(set(axioms), key=_axiom_order)),
            "</Ontology>",
            "",
        ]
        return "\n".join(lines)

    def _ontology_header(self, ontology: URIRef) -> list[str]:
        lines = []
        for predicate, obj in sorted(self.graph.predicate_objects(ontology)):
            if predicate == OWL.imports:
                lines.append(f"<Import>{escape(str(obj))}</Import>")
            elif predicate != RDF.type:
                lines.append(f"<Annotation><AnnotationProperty {_iri(predicate)}/>{self._value(obj)}</Annotation>")
        return sorted(lines, key=lambda line: not line.startswith("<Import>"))

    def _about(self, subject: URIRef) -> list[str]:
        graph = self.graph
        axioms: list[str] = []
        for predicate, obj in graph.predicate_objects(subject):
            if predicate == RDF.type:
                kind = _DECLARED.get(obj)  # type: ignore[arg-type]
                if kind is not None:
                    axioms.append(f"<Declaration><{kind} {_iri(subject)}/></Declaration>")
                elif obj in (OWL.Restriction, OWL.Thing) or str(obj).startswith(str(OWL)):
                    raise ValueError(f"{subject} is declared a {obj}, which OWL/XML export does not cover")
                else:
                    axioms.append(
                        f"<ClassAssertion>{self._class(obj)}<NamedIndividual {_iri(subject)}/></ClassAssertion>"
                    )
            elif predicate == RDFS.subClassOf:
                axioms.append(f"<SubClassOf>{self._class(subject)}{self._class(obj)}</SubClassOf>")
            elif predicate == OWL.equivalentClass:
                axioms.append(f"<EquivalentClasses>{self._class(subject)}{self._class(obj)}</EquivalentClasses>")
            elif predicate == OWL.disjointWith:
                axioms.append(f"<DisjointClasses>{self._class(subject)}{self._class(obj)}</DisjointClasses>")
            elif (
                predicate in (RDFS.domain, RDFS.range, RDFS.subPropertyOf) and subject not in self.annotation_properties
            ):
                axioms.append(self._property_axiom(subject, predicate, obj))
            elif predicate in self.annotation_properties or predicate not in (
                self.object_properties | self.data_properties
            ):
                if isinstance(obj, BNode):
                    raise ValueError(
                        f"{subject} {predicate} has a blank node value, which OWL/XML export does not cover"
                    )
                axioms.append(
                    f"<AnnotationAssertion><AnnotationProperty {_iri(predicate)}/><IRI>{escape(str(subject))}</IRI>"
                    f"{self._value(obj)}</AnnotationAssertion>"
                )
            elif predicate in self.object_properties:
                axioms.append(
                    f"<ObjectPropertyAssertion><ObjectProperty {_iri(predicate)}/><NamedIndividual {_iri(subject)}/>"
                    f"<NamedIndividual {_iri(obj)}/></ObjectPropertyAssertion>"
                )
            else:
                axioms.append(
                    f"<DataPropertyAssertion><DataProperty {_iri(predicate)}/><NamedIndividual {_iri(subject)}/>"
                    f"{self._literal(obj)}</DataPropertyAssertion>"
                )
        return axioms

    def _property_axiom(self, prop: URIRef, predicate: URIRef, obj: Node) -> str:
        is_data = prop in self.data_properties
        kind = "DataProperty" if is_data else "ObjectProperty"
        if predicate == RDFS.subPropertyOf:
            tag = "SubDataPropertyOf" if is_data else "SubObjectPropertyOf"
            return f"<{tag}><{kind} {_iri(prop)}/><{kind} {_iri(obj)}/></{tag}>"
        which = "Domain" if predicate == RDFS.domain else "Range"
        value = f"<Datatype {_iri(obj)}/>" if is_data and which == "Range" else self._class(obj)
        return f"<{kind}{which}><{kind} {_iri(prop)}/>{value}</{kind}{which}>"

    def _value(self, node: Node) -> str:
        if isinstance(node, Literal):
            return self._literal(node)
        return f"<IRI>{escape(str(node))}</IRI>"

    @staticmethod
    def _literal(node: Node) -> str:
        if not isinstance(node, Literal):
            raise ValueError(f"{node} is not a literal")
        if node.language:
            return f'<Literal xml:lang="{escape(node.language)}">{escape(str(node))}</Literal>'
        if node.datatype is None:
            return f"<Literal>{escape(str(node))}</Literal>"
        return f"<Literal datatypeIRI={quoteattr(str(node.datatype))}>{escape(str(node))}</Literal>"

    def _members(self, head: Node) -> Iterable[Node]:
        return list(Collection(self.graph, head))

    def _class(self, node: Node) -> str:
        if isinstance(node, URIRef):
            return f"<Class {_iri(node)}/>"
        if not isinstance(node, BNode):
            raise ValueError(f"{node!r} is not a class")
        graph = self.graph
        for predicate, tag in ((OWL.intersectionOf, "ObjectIntersectionOf"), (OWL.unionOf, "ObjectUnionOf")):
            head = graph.value(node, predicate)
            if head is not None:
                return f"<{tag}>{''.join(self._class(m) for m in self._members(head))}</{tag}>"
        complement = graph.value(node, OWL.complementOf)
        if complement is not None:
            return f"<ObjectComplementOf>{self._class(complement)}</ObjectComplementOf>"
        members = graph.value(node, OWL.oneOf)
        if members is not None:
            individuals = "".join(f"<NamedIndividual {_iri(m)}/>" for m in self._members(members))
            return f"<ObjectOneOf>{individuals}</ObjectOneOf>"
        prop = graph.value(node, OWL.onProperty)
        if prop is None:
            raise ValueError("a class expression OWL/XML export does not cover")
        return self._restriction(node, prop)

    def _restriction(self, node: BNode, prop: Node) -> str:
        graph = self.graph
        is_data = prop in self.data_properties
        kind, prefix = ("DataProperty", "Data") if is_data else ("ObjectProperty", "Object")
        on = f"<{kind} {_iri(prop)}/>"
        for predicate, name in ((OWL.someValuesFrom, "SomeValuesFrom"), (OWL.allValuesFrom, "AllValuesFrom")):
            filler = graph.value(node, predicate)
            if filler is not None:
                inner = f"<Datatype {_iri(filler)}/>" if is_data else self._class(filler)
                return f"<{prefix}{name}>{on}{inner}</{prefix}{name}>"
        value = graph.value(node, OWL.hasValue)
        if value is not None:
            inner = self._literal(value) if isinstance(value, Literal) else f"<NamedIndividual {_iri(value)}/>"
            tag = "DataHasValue" if isinstance(value, Literal) else "ObjectHasValue"
            return f"<{tag}>{on if isinstance(value, Literal) == is_data else self._on(prop, value)}{inner}</{tag}>"
        for predicate, name in _CARDINALITIES.items():
            count = graph.value(node, predicate)
            if count is not None:
                qualified = graph.value(node, OWL.onClass)
                inner = self._class(qualified) if qualified is not None else ""
                return f'<{prefix}{name} cardinality="{int(count)}">{on}{inner}</{prefix}{name}>'
        raise ValueError(f"a restriction on {prop} OWL/XML export does not cover")

    @staticmethod
    def _on(prop: Node, value: Node) -> str:
        kind = "DataProperty" if isinstance(value, Literal) else "ObjectProperty"
        return f"<{kind} {_iri(prop)}/>"


_ORDER = ("<Declaration", "<SubClassOf", "<EquivalentClasses", "<DisjointClasses")


def _axiom_order(axiom: str) -> tuple[int, str]:
    for rank, start in enumerate(_ORDER):
        if axiom.startswith(start):
            return rank, axiom
    return len(_ORDER), axiom
