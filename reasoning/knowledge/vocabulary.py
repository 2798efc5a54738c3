"""The ontology's namespace and the IRIs of the terms the knowledge base reads."""

from __future__ import annotations

import re

from rdflib import Namespace, URIRef
from rdflib.namespace import OWL, RDF, RDFS, SKOS, XSD

from ontology import NAMESPACE as ONTOLOGY_NAMESPACE

__all__ = [
    "NAME_PATTERN",
    "OWL",
    "RDF",
    "RDFS",
    "RK",
    "SKOS",
    "XSD",
    "is_rk",
    "local_name",
    "rk",
]

RK = Namespace(ONTOLOGY_NAMESPACE)
"""The ``rk:`` namespace of every term the project defines."""

NAME_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""What the local name of an ``rk:`` term looks like."""


def rk(name: str) -> URIRef:
    """The IRI of the ``rk:`` term ``name``."""
    return URIRef(ONTOLOGY_NAMESPACE + name)


def is_rk(node: object) -> bool:
    """True when ``node`` is an IRI in the ``rk:`` namespace."""
    return isinstance(node, URIRef) and str(node).startswith(ONTOLOGY_NAMESPACE)


def local_name(node: object) -> str:
    """The part of an ``rk:`` IRI after the ``#`` (other IRIs are returned whole)."""
    text = str(node)
    return text[len(ONTOLOGY_NAMESPACE) :] if text.startswith(ONTOLOGY_NAMESPACE) else text
