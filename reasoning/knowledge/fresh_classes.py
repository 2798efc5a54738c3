"""Whether new classes added to a coherent, HermiT-classified ontology can have instances, without running HermiT.

Adding a class nothing mentioned before, described only by axioms with it on the left (``X ⊑ C``), keeps the ontology
consistent and every other class satisfiable and where it was (give the new class no instances), so only the new
class needs checking, against the stored classification of the rest (:mod:`reasoning.knowledge.reasoner_cache`).
:func:`check_fresh_classes` decides that exactly for the fragment the ontology is written in, EL with disjointness,
domains and ranges and data values:

* the new classes: named parents and restrictions ``P some C`` (C a named class) and ``P value literal``;
* the ontology: the same in class descriptions, ``owl:equivalentClass`` to a named class, a restriction or an
  intersection of those (defined classes such as ``RefrigeratedItem``), disjointness (``owl:disjointWith``,
  ``owl:AllDisjointClasses``), ``rdfs:domain`` / ``rdfs:range`` (a named class, or ``xsd:string`` / ``xsd:boolean``
  / ``xsd:decimal`` / ``rdfs:Literal`` for data properties), and individuals with their types and property values.

A new class's subsumers are closed under its parents' classified ancestors and told restrictions, domains, defined
classes whose definition it meets (an existential conjunct is met by a successor whose own closure, range included,
holds the filler); it is unsatisfiable when they hold two disjoint classes or ``owl:Nothing``, a successor is
unsatisfiable, or a value does not fit its property's data range. Anything outside the fragment (unions,
complements, universal or cardinality restrictions, property characteristics or hierarchies, nested class
expressions, ...) makes the result :attr:`FreshCheck.supported` False with the reason, and the caller runs HermiT.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.collection import Collection
from rdflib.term import Node

from reasoning.knowledge.folded_triples import FoldedTriple, Tree
from reasoning.knowledge.reasoner_cache import Classification
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, SKOS, XSD, is_rk, local_name

ANNOTATION_PROPERTIES: frozenset[URIRef] = frozenset(
    {
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
)
"""Properties whose triples state nothing a reasoner uses (the ontology may declare more)."""

_MAX_DEPTH = 4
_DATA_RANGES = {XSD.string, XSD.boolean, XSD.decimal, RDFS.Literal}
_DECIMAL_TYPES = {XSD.decimal, XSD.integer, XSD.nonNegativeInteger, XSD.positiveInteger, XSD.int, XSD.long}
_DECIMAL_TEXT = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)")
_OWL_TYPES = {
    OWL.Class,
    OWL.NamedIndividual,
    OWL.Ontology,
    OWL.ObjectProperty,
    OWL.DatatypeProperty,
    OWL.AnnotationProperty,
    OWL.AllDisjointClasses,
    OWL.Thing,
}


class Unsupported(Exception):  # noqa: N818 (an outcome, not a failure)
    """Something outside the fragment the check decides."""


@dataclass(frozen=True)
class Some:
    """``P some C``."""

    prop: URIRef
    filler: URIRef


@dataclass(frozen=True)
class Value:
    """``P value v`` with a literal v."""

    prop: URIRef
    value: Literal


Atom = URIRef | Some | Value


@dataclass(frozen=True)
class FreshCheck:
    """The outcome: ``supported`` False (with ``reason``) when HermiT must decide; else ``problems`` (why classes
    can have no instances; empty when all can) and, when there are none, the new classes' inferred place."""

    supported: bool
    reason: str = ""
    problems: tuple[str, ...] = ()
    parents: Mapping[str, frozenset[str]] = field(default_factory=dict)
    ancestors: Mapping[str, frozenset[str]] = field(default_factory=dict)


def annotation_properties(*graphs: Graph) -> frozenset[URIRef]:
    """The standard annotation properties plus those the ``graphs`` declare."""
    declared = {p for g in graphs for p in g.subjects(RDF.type, OWL.AnnotationProperty) if isinstance(p, URIRef)}
    return ANNOTATION_PROPERTIES | declared


def is_logical(triple: FoldedTriple, annotations: frozenset[URIRef]) -> bool:
    """True unless the triple only annotates (a label, a synonym, a comment, ...)."""
    return triple[1] not in annotations


def check_fresh_classes(
    base: Fragment, classification: Classification, added: Iterable[FoldedTriple], annotations: frozenset[URIRef]
) -> FreshCheck:
    """Decide the satisfiability of the classes ``added`` declares, on top of the ontology ``base`` holds (coherent,
    classified as ``classification``)."""
    if base.unsupported is not None:
        return FreshCheck(False, base.unsupported)
    try:
        return _Checker(base, classification, annotations).check(frozenset(added))
    except Unsupported as reason:
        return FreshCheck(False, str(reason))


class Fragment:
    """The told axioms of an ontology in the fragment the check decides (:attr:`unsupported` says why not, if not).

    Read from each source graph separately (:meth:`of`) and combined (:meth:`plus`), so the part that does not
    change between edits is read once."""

    def __init__(self) -> None:
        self.told: dict[URIRef, set[Atom]] = defaultdict(set)
        self.definitions: list[tuple[URIRef, frozenset[Atom]]] = []
        self.disjoint: dict[URIRef, set[URIRef]] = defaultdict(set)
        self.domains: dict[URIRef, set[URIRef]] = defaultdict(set)
        self.ranges: dict[URIRef, set[URIRef]] = defaultdict(set)
        self.object_properties: set[URIRef] = set()
        self.data_properties: set[URIRef] = set()
        self.nodes: set[URIRef] = set()
        self.unsupported: str | None = None

    @classmethod
    def of(cls, graphs: Iterable[Graph], annotations: frozenset[URIRef]) -> Fragment:
        """The fragment of the ontology made of ``graphs``."""
        fragment = cls()
        for graph in graphs:
            fragment.object_properties |= {p for p in graph.subjects(RDF.type, OWL.ObjectProperty) if is_iri(p)}
            fragment.data_properties |= {p for p in graph.subjects(RDF.type, OWL.DatatypeProperty) if is_iri(p)}
            fragment.nodes |= {n for n in graph.all_nodes() if isinstance(n, URIRef)} | set(graph.predicates())
            if fragment.unsupported is None:
                try:
                    fragment._read(graph, annotations)
                except Unsupported as reason:
                    fragment.unsupported = str(reason)
        return fragment

    def plus(self, other: Fragment) -> Fragment:
        """The fragment of both ontologies together."""
        both = Fragment()
        for mine, theirs, into in (
            (self.told, other.told, both.told),
            (self.disjoint, other.disjoint, both.disjoint),
            (self.domains, other.domains, both.domains),
            (self.ranges, other.ranges, both.ranges),
        ):
            for key in {*mine, *theirs}:
                into[key] = {*mine.get(key, ()), *theirs.get(key, ())}  # type: ignore[index]
        both.definitions = [*self.definitions, *other.definitions]
        both.object_properties = self.object_properties | other.object_properties
        both.data_properties = self.data_properties | other.data_properties
        both.nodes = self.nodes | other.nodes
        both.unsupported = self.unsupported or other.unsupported
        return both

    def _read(self, graph: Graph, annotations: frozenset[URIRef]) -> None:
        consumed: set[BNode] = set()
        for subject, predicate, obj in graph:
            if predicate in annotations or isinstance(subject, BNode):
                continue
            if predicate == RDFS.subClassOf:
                self.told[subject].add(self._atom(graph, obj, consumed))  # type: ignore[index]
            elif predicate == OWL.equivalentClass:
                conjuncts = self._conjuncts(graph, obj, consumed)
                self.definitions.append((subject, conjuncts))  # type: ignore[arg-type]
                if isinstance(obj, URIRef):
                    self.definitions.append((obj, frozenset({subject})))  # type: ignore[arg-type]
                self.told[subject] |= conjuncts  # type: ignore[index]
            elif predicate == OWL.disjointWith:
                self._disjoint([subject, obj])
            elif predicate == RDFS.domain:
                self.domains[subject].add(self._named(obj))  # type: ignore[index]
            elif predicate == RDFS.range:
                self.ranges[subject].add(self._named(obj))  # type: ignore[index]
            elif predicate == RDF.type:
                if not isinstance(obj, URIRef):
                    raise Unsupported(f"{_show(subject)} is an instance of a class expression")
                if str(obj).startswith(str(OWL)) and obj not in _OWL_TYPES:
                    raise Unsupported(f"{_show(subject)} is declared a {_show(obj)}")
            elif predicate == RDFS.subPropertyOf or (str(predicate).startswith(str(OWL)) and predicate != OWL.imports):
                raise Unsupported(f"the ontology uses {_show(predicate)}")
        for group in graph.subjects(RDF.type, OWL.AllDisjointClasses):
            consumed.add(group)  # type: ignore[arg-type]
            for head in graph.objects(group, OWL.members):
                consumed.update(c for c in (head, *_list_cells(graph, head)) if isinstance(c, BNode))
                self._disjoint(list(Collection(graph, head)))
        for node in set(graph.subjects()):
            if isinstance(node, BNode) and node not in consumed:
                raise Unsupported("the ontology holds an anonymous axiom or class expression the check does not read")

    def _disjoint(self, members: list[Node]) -> None:
        named = [self._named(m) for m in members]
        for i, a in enumerate(named):
            for b in named[i + 1 :]:
                if a != b:
                    self.disjoint[a].add(b)
                    self.disjoint[b].add(a)

    @staticmethod
    def _named(node: Node) -> URIRef:
        if not isinstance(node, URIRef):
            raise Unsupported("a disjointness, domain or range names a class expression")
        return node

    def _atom(self, graph: Graph, node: Node, consumed: set[BNode]) -> Atom:
        if isinstance(node, URIRef):
            return node
        if not isinstance(node, BNode):
            raise Unsupported(f"a superclass {node!r} is neither a class nor a restriction")
        consumed.add(node)
        pairs = set(graph.predicate_objects(node))
        return _restriction(dict(pairs), len(pairs))

    def _conjuncts(self, graph: Graph, node: Node, consumed: set[BNode]) -> frozenset[Atom]:
        if isinstance(node, URIRef):
            return frozenset({node})
        if not isinstance(node, BNode):
            raise Unsupported("an equivalent class is a literal")
        consumed.add(node)
        head = graph.value(node, OWL.intersectionOf)
        if head is None:
            return frozenset({self._atom(graph, node, consumed)})
        if set(graph.predicates(node)) - {RDF.type, OWL.intersectionOf}:
            raise Unsupported("a class definition the check does not read")
        cells = [head, *(c for c in _list_cells(graph, head))]
        consumed.update(c for c in cells if isinstance(c, BNode))
        return frozenset(self._atom(graph, member, consumed) for member in Collection(graph, head))


def is_iri(node: object) -> bool:
    """True for an IRI."""
    return isinstance(node, URIRef)


def _list_cells(graph: Graph, head: Node) -> Iterable[Node]:
    cell = graph.value(head, RDF.rest)
    while cell is not None and cell != RDF.nil:
        yield cell
        cell = graph.value(cell, RDF.rest)


def _restriction(values: Mapping[Node, Node], count: int) -> Atom:
    prop = values.get(OWL.onProperty)
    if values.get(RDF.type) != OWL.Restriction or not isinstance(prop, URIRef):
        raise Unsupported("a class expression that is not a restriction")
    filler = values.get(OWL.someValuesFrom)
    value = values.get(OWL.hasValue)
    if count != 3:
        raise Unsupported(f"a restriction on {_show(prop)} the check does not read")
    if isinstance(filler, URIRef):
        return Some(prop, filler)
    if isinstance(value, Literal):
        return Value(prop, value)
    raise Unsupported(f"a restriction on {_show(prop)} that is neither 'some' a named class nor 'value' a literal")


def _show(node: object) -> str:
    return f"rk:{local_name(node)}" if is_rk(node) else str(node)


@dataclass
class _Closure:
    """A concept's subsumers: named classes, existential successors and data values."""

    named: set[URIRef] = field(default_factory=set)
    somes: set[Some] = field(default_factory=set)
    values: set[Value] = field(default_factory=set)


class _Checker:
    def __init__(self, base: Fragment, classification: Classification, annotations: frozenset[URIRef]) -> None:
        self.fragment = base
        self.classification = classification
        self.annotations = annotations
        self.fresh: dict[URIRef, set[Atom]] = {}
        self.closures: dict[URIRef, _Closure] = {}
        self.successors: dict[frozenset[Atom], tuple[_Closure, str | None]] = {}

    def check(self, added: frozenset[FoldedTriple]) -> FreshCheck:
        declared = {s for s, p, o in added if p == RDF.type and o == OWL.Class and s is not None}
        for name in declared:
            if name in self.fragment.nodes:
                raise Unsupported(f"{_show(name)} is not new: the ontology mentions it already")
            self.fresh[name] = set()
        for subject, predicate, obj in added:
            if predicate in self.annotations:
                continue
            if subject is None or subject not in self.fresh:
                raise Unsupported(f"new axioms about {_show(subject) if subject else 'an anonymous node'}")
            if predicate == RDF.type and obj == OWL.Class:
                continue
            if predicate != RDFS.subClassOf:
                raise Unsupported(f"{_show(subject)} gets a {_show(predicate)} axiom")
            if isinstance(obj, Tree):
                self.fresh[subject].add(_restriction(dict(obj), len(obj)))
            elif isinstance(obj, URIRef):
                self.fresh[subject].add(obj)
            else:
                raise Unsupported(f"{_show(subject)} has a literal superclass")
        problems: list[str] = []
        for name in self._in_order():
            closure, clash = self._saturate(set(self.fresh[name]), 0)
            self.closures[name] = closure
            if clash is not None:
                problems.append(f"{local_name(name)} can have no instances: {clash}")
        if problems:
            return FreshCheck(True, problems=tuple(problems))
        ancestors = {
            local_name(n): frozenset(local_name(a) for a in c.named if is_rk(a) and a != n)
            for n, c in self.closures.items()
        }
        parents = {n: self._most_specific(a, ancestors) for n, a in ancestors.items()}
        return FreshCheck(True, parents=parents, ancestors=ancestors)

    def _in_order(self) -> list[URIRef]:
        """The new classes, each after the new classes it names."""
        ordered: list[URIRef] = []
        visiting: set[URIRef] = set()

        def visit(name: URIRef) -> None:
            if name in ordered:
                return
            if name in visiting:
                raise Unsupported("the new classes form a cycle")
            visiting.add(name)
            for atom in self.fresh[name]:
                mentioned = atom if isinstance(atom, URIRef) else atom.filler if isinstance(atom, Some) else None
                if mentioned in self.fresh:
                    visit(mentioned)
            visiting.discard(name)
            ordered.append(name)

        for name in sorted(self.fresh):
            visit(name)
        return ordered

    def _most_specific(self, names: frozenset[str], ancestors: Mapping[str, frozenset[str]]) -> frozenset[str]:
        def above(name: str) -> frozenset[str]:
            return ancestors.get(name) or self.classification.ancestors.get(name, frozenset())

        return frozenset(n for n in names if not any(n in above(other) for other in names if other != n))

    # ------------------------------------------------------------------ closure

    def _class_atoms(self, name: URIRef) -> tuple[set[URIRef], set[Atom]]:
        """A class's named subsumers and the restrictions it and they carry."""
        if name == OWL.Thing:
            return {name}, set()
        if name == OWL.Nothing:
            return {name}, set()
        if name in self.closures:
            closure = self.closures[name]
            return {name, *closure.named}, {*closure.somes, *closure.values}
        if not is_rk(name) or local_name(name) not in self.classification.ancestors:
            raise Unsupported(f"{_show(name)} is not a classified class")
        named = {name, *(URIRef(str(name)[: -len(local_name(name))] + a) for a in self._ancestors(name))}
        atoms: set[Atom] = set()
        for cls in named:
            atoms |= {a for a in self.fragment.told.get(cls, ()) if not isinstance(a, URIRef)}
        return named, atoms

    def _ancestors(self, name: URIRef) -> frozenset[str]:
        return self.classification.ancestors.get(local_name(name), frozenset())

    def _saturate(self, atoms: set[Atom], depth: int) -> tuple[_Closure, str | None]:
        if depth > _MAX_DEPTH:
            raise Unsupported("restrictions nest too deeply")
        closure = _Closure()
        queue = list(atoms)
        while True:
            while queue:
                atom = queue.pop()
                if isinstance(atom, URIRef):
                    if atom in closure.named:
                        continue
                    named, restrictions = self._class_atoms(atom)
                    closure.named |= named
                    queue.extend(restrictions)
                elif isinstance(atom, Some):
                    if atom in closure.somes:
                        continue
                    if atom.prop not in self.fragment.object_properties:
                        raise Unsupported(f"'some' on {_show(atom.prop)}, which is not an object property")
                    closure.somes.add(atom)
                    queue.extend(self.fragment.domains.get(atom.prop, ()))
                else:
                    if atom in closure.values:
                        continue
                    if atom.prop not in self.fragment.data_properties:
                        raise Unsupported(f"'value' on {_show(atom.prop)}, which is not a data property")
                    closure.values.add(atom)
                    queue.extend(self.fragment.domains.get(atom.prop, ()))
            met = [
                d
                for d, conjuncts in self.fragment.definitions
                if d not in closure.named and self._meets(closure, conjuncts, depth)
            ]
            if not met:
                break
            queue.extend(met)
        return closure, self._clash(closure, depth)

    def _meets(self, closure: _Closure, conjuncts: frozenset[Atom], depth: int) -> bool:
        for conjunct in conjuncts:
            if isinstance(conjunct, URIRef):
                if conjunct not in closure.named:
                    return False
            elif isinstance(conjunct, Value):
                if conjunct not in closure.values:
                    return False
            elif not any(
                some.prop == conjunct.prop and conjunct.filler in self._successor(some, depth)[0].named
                for some in closure.somes
            ):
                return False
        return True

    def _successor(self, some: Some, depth: int) -> tuple[_Closure, str | None]:
        atoms: frozenset[Atom] = frozenset({some.filler, *self.fragment.ranges.get(some.prop, ())})
        found = self.successors.get(atoms)
        if found is None:
            for kind in self.fragment.ranges.get(some.prop, ()):
                if kind in _DATA_RANGES or str(kind).startswith(str(XSD)):
                    raise Unsupported(f"{_show(some.prop)} has a data range")
            found = self._saturate(set(atoms), depth + 1)
            self.successors[atoms] = found
        return found

    def _clash(self, closure: _Closure, depth: int) -> str | None:
        if OWL.Nothing in closure.named:
            return "it is under owl:Nothing"
        pairs = sorted(
            {
                tuple(sorted((local_name(a), local_name(b))))
                for a in closure.named
                for b in self.fragment.disjoint.get(a, ())
                if b in closure.named
            }
        )
        if pairs:
            return "it is under " + "; ".join(f"{a} and {b}, which are disjoint" for a, b in pairs)
        for value in sorted(closure.values, key=str):
            ranges = self.fragment.ranges.get(value.prop, set())
            for kind in ranges:
                if kind not in _DATA_RANGES:
                    raise Unsupported(f"{_show(value.prop)} has the data range {_show(kind)}")
                if not _fits(value.value, kind):
                    return (
                        f"its {_show(value.prop)} value {value.value.n3()} is not of the property's type {_show(kind)}"
                    )
        for some in sorted(closure.somes, key=str):
            _, clash = self._successor(some, depth)
            if clash is not None:
                return f"its {_show(some.prop)} must be a {_show(some.filler)}, and {clash.removeprefix('it is ')}"
        return None


def _fits(value: Literal, kind: URIRef) -> bool:
    """True when a literal lies in one of the supported data ranges."""
    if kind == RDFS.Literal:
        return True
    if kind == XSD.string:
        return value.language is None and value.datatype in (None, XSD.string)
    if kind == XSD.decimal:  # xsd:integer and its kin are decimals too
        return value.datatype in _DECIMAL_TYPES and _DECIMAL_TEXT.fullmatch(str(value)) is not None
    return value.datatype == XSD.boolean and str(value) in ("true", "false", "1", "0")
