"""OWL reasoning with HermiT (through owlready2): consistency and the inferred class hierarchy.

HermiT is a Java program; it runs only when asked (loading with ``reason=True``, validating an edit,
``robokudo ontology check``), never while answering questions. owlready2 does not read Turtle, so the
merged graph is handed over as RDF/XML produced by rdflib.
"""

from __future__ import annotations

import io
import logging
import shutil
import time
from dataclasses import dataclass

from rdflib import Graph, URIRef
from rdflib.namespace import OWL, RDF

from reasoning.knowledge.index import Inferred, OntologyIndex
from reasoning.knowledge.vocabulary import is_rk, local_name

log = logging.getLogger(__name__)

MERGED_ONTOLOGY_IRI = "http://robokudo.org/ontology/merged"
"""The IRI the merged ontology gets inside the reasoner."""

JAVA_MISSING = (
    "Java was not found, so the HermiT reasoner cannot run (install a Java runtime, e.g. the Debian package "
    "default-jre-headless); falling back to the asserted class hierarchy and asserted disjointness checks"
)


@dataclass(frozen=True)
class ReasonerResult:
    """What a HermiT run found; ``available`` is False when Java is missing (then nothing was checked)."""

    available: bool
    consistent: bool
    unsatisfiable: tuple[str, ...]
    inferred: Inferred | None
    seconds: float
    message: str

    @property
    def ok(self) -> bool:
        """True when HermiT ran and found neither an inconsistency nor an unsatisfiable class."""
        return self.available and self.consistent and not self.unsatisfiable


def find_java() -> str | None:
    """The Java executable owlready2 will run, or None when there is none."""
    import owlready2

    return shutil.which(owlready2.JAVA_EXE)


def rdf_xml_for_reasoner(graph: Graph) -> bytes:
    """``graph`` as RDF/XML with its ontology headers and imports replaced by one header."""
    copy = Graph()
    for triple in graph:
        subject, predicate, obj = triple
        if predicate == OWL.imports or (predicate == RDF.type and obj == OWL.Ontology):
            continue
        if (subject, RDF.type, OWL.Ontology) in graph:
            continue
        copy.add(triple)
    copy.add((URIRef(MERGED_ONTOLOGY_IRI), RDF.type, OWL.Ontology))
    return copy.serialize(format="xml").encode("utf-8")


def classify(graph: Graph) -> ReasonerResult:
    """Run HermiT on ``graph``: consistency, unsatisfiable classes, inferred subsumptions of ``rk:`` classes."""
    start = time.perf_counter()
    if find_java() is None:
        log.warning(JAVA_MISSING)
        return ReasonerResult(False, True, (), None, 0.0, JAVA_MISSING)
    import owlready2

    data = rdf_xml_for_reasoner(graph)
    world = owlready2.World()
    try:
        world.get_ontology(MERGED_ONTOLOGY_IRI).load(fileobj=io.BytesIO(data))
        try:
            owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
        except owlready2.OwlReadyJavaError as error:
            message = f"HermiT failed to run ({error}); falling back to the asserted hierarchy and checks"
            log.warning(message)
            return ReasonerResult(False, True, (), None, time.perf_counter() - start, message)
        except owlready2.OwlReadyInconsistentOntologyError:
            seconds = time.perf_counter() - start
            message = f"HermiT: the ontology is inconsistent ({seconds:.1f} s)"
            return ReasonerResult(True, False, (), None, seconds, message)
        unsatisfiable = tuple(sorted(local_name(c.iri) for c in world.inconsistent_classes() if is_rk(URIRef(c.iri))))
        parents: dict[str, frozenset[str]] = {}
        ancestors: dict[str, frozenset[str]] = {}
        for cls in world.classes():
            if not is_rk(URIRef(cls.iri)):
                continue
            name = local_name(cls.iri)
            parents[name] = frozenset(
                local_name(p.iri) for p in cls.is_a if isinstance(p, owlready2.ThingClass) and is_rk(URIRef(p.iri))
            )
            ancestors[name] = frozenset(
                local_name(a.iri)
                for a in cls.ancestors(include_self=False)
                if isinstance(a, owlready2.ThingClass) and is_rk(URIRef(a.iri))
            )
    finally:
        world.close()
    seconds = time.perf_counter() - start
    if unsatisfiable:
        message = f"HermiT: unsatisfiable classes {', '.join(unsatisfiable)} ({seconds:.1f} s)"
    else:
        message = f"HermiT: consistent, {len(parents)} classes classified ({seconds:.1f} s)"
    return ReasonerResult(True, True, unsatisfiable, Inferred(parents, ancestors), seconds, message)


def describe_unsatisfiable(index: OntologyIndex, result: ReasonerResult) -> list[str]:
    """One message per problem HermiT found, naming the disjoint superclasses when that explains it."""
    if not result.consistent:
        return [result.message]
    messages = []
    for name in result.unsatisfiable:
        conflicts = index.disjoint_conflicts(name)
        if conflicts:
            pairs = "; ".join(f"{a} and {b}, which are disjoint" for a, b in conflicts)
            messages.append(f"{name} can have no instances according to HermiT: it is under {pairs}")
        else:
            messages.append(f"{name} can have no instances according to HermiT (its definition is contradictory)")
    return messages
