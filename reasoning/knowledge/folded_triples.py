"""RDF graphs as sets of folded triples: each blank-node tree folded into the triple that points at it.

Blank nodes get new identities every time a file is parsed, so two parses of one file share no blank node and their
triples cannot be compared, subtracted or stored. Folding replaces a blank node that exactly one triple points at (a
restriction, an RDF list cell, an anonymous class expression) by its content, a :class:`Tree` of (predicate, folded
object) pairs. A blank node no triple points at (``[] a owl:AllDisjointClasses ; ...``) becomes the one folded triple
``(None, None, tree)``. A blank node two triples point at, or a cycle of blank nodes, cannot be folded
(:class:`NotFoldableError`). Folded triples are hashable, so sets of them are compared, subtracted and written to the
edit history as N-Triples (:func:`to_ntriples`, :func:`from_ntriples`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from typing import Union

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.term import Node


class Tree(frozenset):  # type: ignore[type-arg]
    """The content of a folded blank node: a frozenset of (predicate, folded object) pairs."""


Folded = Union[URIRef, Literal, Tree]  # noqa: UP007 (a runtime alias of a recursive type)
FoldedTriple = tuple[URIRef | None, URIRef | None, Folded]
"""(subject, predicate, object) with blank nodes folded; ``(None, None, tree)`` for an unreferenced blank node."""


class NotFoldableError(ValueError):
    """A graph holds a blank node referenced by several triples, or a cycle of blank nodes."""


def fold(graph: Graph) -> frozenset[FoldedTriple]:
    """The folded triples of ``graph``; NotFoldableError when a blank node is shared or in a cycle."""
    referrers: dict[BNode, int] = {}
    for _, _, obj in graph:
        if isinstance(obj, BNode):
            referrers[obj] = referrers.get(obj, 0) + 1
    shared = [node for node, count in referrers.items() if count > 1]
    if shared:
        raise NotFoldableError(f"{len(shared)} blank node(s) are the object of several triples")
    folded: set[FoldedTriple] = set()
    done: dict[BNode, Tree] = {}
    for subject, predicate, obj in graph:
        if isinstance(subject, BNode):
            if subject not in referrers:
                folded.add((None, None, _tree(graph, subject, done, set())))
            continue
        folded.add((subject, predicate, _folded(graph, obj, done, set())))  # type: ignore[arg-type]
    return frozenset(folded)


def _folded(graph: Graph, node: Node, done: dict[BNode, Tree], path: set[BNode]) -> Folded:
    if isinstance(node, BNode):
        return _tree(graph, node, done, path)
    return node  # type: ignore[return-value]


def _tree(graph: Graph, node: BNode, done: dict[BNode, Tree], path: set[BNode]) -> Tree:
    found = done.get(node)
    if found is not None:
        return found
    if node in path:
        raise NotFoldableError("the graph holds a cycle of blank nodes")
    path.add(node)
    tree = Tree((p, _folded(graph, o, done, path)) for p, o in graph.predicate_objects(node))
    path.discard(node)
    done[node] = tree
    return tree


def unfold(triples: Iterable[FoldedTriple], graph: Graph | None = None) -> Graph:
    """The triples of ``triples`` with a new blank node for each tree, added to ``graph`` (default: a new one)."""
    target = graph if graph is not None else Graph()
    for subject, predicate, obj in triples:
        if subject is None or predicate is None:
            _unfold_tree(target, obj)  # type: ignore[arg-type]
        else:
            target.add((subject, predicate, _unfold(target, obj)))
    return target


def _unfold(graph: Graph, value: Folded) -> Node:
    return _unfold_tree(graph, value) if isinstance(value, Tree) else value


def _unfold_tree(graph: Graph, tree: Tree) -> BNode:
    node = BNode()
    for predicate, value in tree:
        graph.add((node, predicate, _unfold(graph, value)))
    return node


def to_ntriples(triples: Iterable[FoldedTriple]) -> list[str]:
    """N-Triples lines of the folded triples (blank nodes labelled), sorted; :func:`from_ntriples` reads them."""
    graph = unfold(triples, Graph(bind_namespaces="none"))
    lines = graph.serialize(format="nt", encoding="utf-8").decode("utf-8").splitlines()
    return sorted(line for line in lines if line.strip())


def from_ntriples(lines: Iterable[str]) -> frozenset[FoldedTriple]:
    """The folded triples written by :func:`to_ntriples`."""
    graph = Graph(bind_namespaces="none")
    graph.parse(data="\n".join(lines) + "\n", format="nt")
    return fold(graph)


def canonical_text(triples: Iterable[FoldedTriple]) -> str:
    """A text that is the same for equal sets of folded triples, in every process (for content digests)."""
    return "\n".join(sorted(_canonical(t) for t in triples))


def digest(triples: Iterable[FoldedTriple]) -> str:
    """SHA-256 of :func:`canonical_text`."""
    return hashlib.sha256(canonical_text(triples).encode("utf-8")).hexdigest()


def _canonical(value: object) -> str:
    if isinstance(value, Tree):
        return "[" + " ; ".join(sorted(f"{_canonical(p)} {_canonical(o)}" for p, o in value)) + "]"
    if isinstance(value, tuple):
        return " ".join(_canonical(part) for part in value)
    if value is None:
        return "-"
    return value.n3()  # type: ignore[attr-defined]


def subjects(triples: Iterable[FoldedTriple]) -> set[URIRef]:
    """The named subjects of the folded triples."""
    return {s for s, _, _ in triples if s is not None}


def mentions(triples: Iterable[FoldedTriple]) -> set[URIRef]:
    """Every IRI the folded triples mention (in trees too), predicates included."""
    found: set[URIRef] = set()

    def visit(value: object) -> None:
        if isinstance(value, URIRef):
            found.add(value)
        elif isinstance(value, Tree):
            for predicate, obj in value:
                visit(predicate)
                visit(obj)

    for subject, predicate, obj in triples:
        visit(subject)
        visit(predicate)
        visit(obj)
    return found
