"""Ontologies in and out of the formats other OWL tools use: Turtle, RDF/XML and OWL/XML.

:func:`export_ontology` writes the user layer or everything a knowledge base loads; :func:`serialize` writes a graph
as Turtle, RDF/XML (Protégé, owlready2) or OWL/XML (:mod:`reasoning.knowledge.owl_xml`); :func:`for_export` makes
the merged ontology one self-contained ontology (the files' headers and ``owl:imports`` between them replaced by one
header). :func:`read_ontology` reads any of these formats (OWL/XML through owlready2) and :func:`map_to_namespace`
renames IRIs of other namespaces into ``rk:`` as the user maps them; :func:`outside_namespace` names the IRIs that
stay outside.
"""

from __future__ import annotations

import io
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.namespace import DC, DCTERMS

from reasoning.errors import EditRejectedError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.owl_xml import to_owl_xml
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, RK, SKOS, XSD, is_rk

FORMATS: tuple[str, ...] = ("turtle", "xml", "owl")
"""Export formats: Turtle, RDF/XML, OWL/XML."""

MERGED_IRI = URIRef("http://robokudo.org/ontology/merged")
"""The ontology IRI of a merged export."""

STANDARD_NAMESPACES: tuple[str, ...] = (str(RDF), str(RDFS), str(OWL), str(XSD), str(SKOS), str(DC), str(DCTERMS))
"""Vocabularies an imported description may use without mapping."""


def for_export(merged: Graph) -> Graph:
    """The merged ontology with one ontology header and no ``owl:imports`` (each file's header dropped)."""
    headers = set(merged.subjects(RDF.type, OWL.Ontology))
    graph = Graph()
    for prefix, namespace in merged.namespaces():
        graph.bind(prefix, namespace, override=True, replace=True)
    for triple in merged:
        if triple[0] not in headers:
            graph.add(triple)
    graph.add((MERGED_IRI, RDF.type, OWL.Ontology))
    graph.add((MERGED_IRI, RDFS.label, Literal("RoboKudo ontology (shipped and user classes)", lang="en")))
    return graph


def export_ontology(kb: KnowledgeBase, fmt: str, merged: bool = False) -> bytes:
    """The user layer of ``kb`` (Turtle: the file's own text, comments included) or, ``merged``, everything it
    loads (shipped files, annotator classes, user layer) as one ontology, in format ``fmt``."""
    graphs = kb.source_graphs()
    if merged:
        return serialize(for_export(kb.combine(graphs)[0]), fmt)
    if fmt == "turtle" and kb.user_file.exists():
        return kb.user_file.read_bytes()
    user = graphs.get(kb.user_file)
    return serialize(user if user is not None else Graph(), fmt)


def serialize(graph: Graph, fmt: str) -> bytes:
    """``graph`` in format ``fmt`` (one of :data:`FORMATS`)."""
    if fmt == "turtle":
        return graph.serialize(format="turtle", encoding="utf-8")
    if fmt == "xml":
        return graph.serialize(format="xml", encoding="utf-8")
    if fmt == "owl":
        return to_owl_xml(graph).encode("utf-8")
    raise ValueError(f"unknown format {fmt!r}; use one of {', '.join(FORMATS)}")


def read_ontology(path: Path) -> Graph:
    """An ontology file in Turtle, N-Triples, RDF/XML or OWL/XML (by content); EditRejectedError when unreadable."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise EditRejectedError([f"cannot read {path}: {error.strerror or error}"]) from None
    head = data[:4096].lstrip()
    graph = Graph()
    try:
        if head.startswith(b"<") and b"http://www.w3.org/2002/07/owl#" in head and b"<Ontology" in head:
            return _owl_xml(data)
        if head.startswith(b"<"):
            graph.parse(data=data, format="xml", publicID=Path(path).resolve().as_uri())
        elif Path(path).suffix == ".nt":
            graph.parse(data=data, format="nt")
        else:
            graph.parse(data=data, format="turtle", publicID=Path(path).resolve().as_uri())
    except Exception as error:  # rdflib raises several unrelated types for syntax errors
        raise EditRejectedError([f"{path}: not a readable ontology (Turtle, RDF/XML or OWL/XML): {error}"]) from None
    return plain_strings(graph)


def plain_strings(graph: Graph) -> Graph:
    """``graph`` with ``xsd:string`` literals written as plain ones (the same value in RDF 1.1; rdflib tells them
    apart, and OWL/XML readers type every plain literal)."""
    typed = [(s, p, o) for s, p, o in graph if isinstance(o, Literal) and o.datatype == XSD.string]
    for subject, predicate, obj in typed:
        graph.remove((subject, predicate, obj))
        graph.add((subject, predicate, Literal(str(obj))))
    return graph


def _owl_xml(data: bytes) -> Graph:
    """OWL/XML read by owlready2 and handed over as N-Triples."""
    import owlready2

    world = owlready2.World()
    try:
        world.get_ontology("http://robokudo.org/ontology/imported").load(fileobj=io.BytesIO(data))
        buffer = io.BytesIO()
        world.save(buffer, format="ntriples")
    finally:
        world.close()
    graph = Graph()
    graph.parse(data=buffer.getvalue(), format="nt")
    return plain_strings(graph)


def map_to_namespace(graph: Graph, namespaces: Sequence[str] = (), names: Mapping[str, str] | None = None) -> Graph:
    """``graph`` with IRIs renamed into ``rk:``: ``names`` maps single IRIs to rk names, ``namespaces`` maps every
    IRI starting with one of them to rk + the rest. Standard vocabularies stay as they are."""
    renamed = Graph()
    names = names or {}

    def rename(node: object) -> object:
        if not isinstance(node, URIRef) or is_rk(node):
            return node
        text = str(node)
        if text in names:
            return RK[names[text]]
        for namespace in namespaces:
            if text.startswith(namespace) and len(text) > len(namespace):
                return RK[text[len(namespace) :]]
        return node

    for subject, predicate, obj in graph:
        renamed.add((rename(subject), rename(predicate), rename(obj)))  # type: ignore[arg-type]
    return renamed


def outside_namespace(nodes: Iterable[object]) -> list[str]:
    """The IRIs among ``nodes`` that are neither ``rk:`` nor a standard vocabulary, sorted."""
    return sorted(
        {str(n) for n in nodes if isinstance(n, URIRef) and not is_rk(n) and not str(n).startswith(STANDARD_NAMESPACES)}
    )


def is_blank(node: object) -> bool:
    """True for a blank node."""
    return isinstance(node, BNode)
