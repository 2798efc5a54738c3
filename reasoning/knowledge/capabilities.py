"""Annotator capabilities as ontology triples: the Python class is the source, its triples enter at load.

An annotator class declares its ports (``inputs`` / ``optional_inputs`` / ``outputs``, CAS types) and a
:class:`~robokudo.core.capability.Capability` (label, synonyms, description, value domains, preconditions, cost,
reliability). :func:`capability_graph` turns classes into the triples an ontology file would hold: the individual
``rk:<ClassName>`` of ``rk:Annotator`` with ``rk:requiresInput``, ``rk:optionalInput``, ``rk:providesOutput``,
``rk:canReport...``, ``rk:precondition``, ``rk:expectedCostMs``, ``rk:reliability`` and ``rk:implementedBy``
``"<module>.<qualname>"``. The :class:`~reasoning.knowledge.knowledge_base.KnowledgeBase` merges them with the
Turtle files before indexing and reasoning; the index then checks every name against the ontology and reports a
bad one with the class and the field that names it (:func:`field_of`). :func:`turtle_annotators` finds annotators
declared in a Turtle file instead, which the knowledge base rejects.

This module only reads the classes' attributes: it imports no annotator code (``reasoning`` sits below
``annotators``) and imports the Annotator type for type checking only, so loading the knowledge base does not
load the behaviour-tree runtime.
"""

from __future__ import annotations

import inspect
from collections.abc import Iterable, Mapping
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING

from rdflib import Graph, Literal
from rdflib.term import Node

from reasoning.errors import OntologyError
from reasoning.knowledge.vocabulary import NAME_PATTERN, OWL, RDF, RDFS, RK, SKOS, XSD, is_rk, local_name
from reasoning.knowledge.words import camel_words

if TYPE_CHECKING:
    from robokudo.core.annotator import Annotator

PORT_PROPERTIES: Mapping[str, str] = {
    "inputs": "requiresInput",
    "optional_inputs": "optionalInput",
    "outputs": "providesOutput",
}
"""Annotator port ClassVar -> the property its CAS types become."""

CAPABILITY_PROPERTIES: Mapping[str, str] = {
    "colors": "canReportColor",
    "shapes": "canReportShape",
    "sizes": "canReportSize",
    "materials": "canReportMaterial",
    "classes": "canReportClass",
    "preconditions": "precondition",
}
"""Capability field -> the property its names become."""

NUMBER_PROPERTIES: Mapping[str, str] = {"cost_ms": "expectedCostMs", "reliability": "reliability"}
"""Numeric Capability field -> its datatype property."""

ANNOTATOR_PROPERTIES: frozenset[str] = frozenset(
    {*PORT_PROPERTIES.values(), *CAPABILITY_PROPERTIES.values(), *NUMBER_PROPERTIES.values(), "implementedBy"}
)
"""Every property that states an annotator's capability (none of them may appear in a Turtle file)."""

_FIELDS: Mapping[str, str] = {
    **{prop: port for port, prop in PORT_PROPERTIES.items()},
    **{prop: f"capability.{field}" for field, prop in CAPABILITY_PROPERTIES.items()},
    **{prop: f"capability.{field}" for field, prop in NUMBER_PROPERTIES.items()},
}


def implementation_path(cls: type) -> str:
    """The dotted path of a class, ``<module>.<qualname>`` (its ``rk:implementedBy``)."""
    return f"{cls.__module__}.{cls.__qualname__}"


def field_of(prop: str) -> str:
    """The Python declaration a capability property comes from (``canReportColor`` -> ``capability.colors``)."""
    return _FIELDS.get(prop, f"rk:{prop}")


def description(cls: type[Annotator]) -> str:
    """The annotator's description: its Capability's, else the first paragraph of its own docstring."""
    if cls.capability.description:
        return cls.capability.description
    own = cls.__dict__.get("__doc__")
    if not isinstance(own, str) or not own.strip():
        return ""
    first = inspect.cleandoc(own).split("\n\n")[0]
    return " ".join(first.split()).replace("``", "")


def capability_graph(classes: Iterable[type[Annotator]]) -> Graph:
    """The triples declaring each annotator class; OntologyError naming the class for a malformed declaration.

    A class given twice counts once; two classes with the same name are an error (the name is the annotator's
    ontology name). Whether the named CAS types, value classes and preconditions exist is checked by the index,
    against the whole ontology.
    """
    graph = Graph()
    problems: list[str] = []
    seen: dict[str, type] = {}
    for cls in dict.fromkeys(classes):
        if not isinstance(cls, type) or not hasattr(cls, "capability"):
            problems.append(f"{cls!r} is not an annotator class (an Annotator subclass)")
            continue
        other = seen.setdefault(cls.__name__, cls)
        if other is not cls:
            problems.append(
                f"two annotator classes are called {cls.__name__}: {implementation_path(other)} and "
                f"{implementation_path(cls)} (the class name is the annotator's name; rename one)"
            )
            continue
        problems += _declare(graph, cls)
    if problems:
        raise OntologyError(problems)
    return graph


def _declare(graph: Graph, cls: type[Annotator]) -> list[str]:
    """Add the triples of one class to ``graph``; the problems of its declaration."""
    name, path = cls.__name__, implementation_path(cls)
    where = f"annotator class {name} ({path})"
    problems: list[str] = []
    subject = RK[name]
    graph.add((subject, RDF.type, OWL.NamedIndividual))
    graph.add((subject, RDF.type, RK.Annotator))
    graph.add((subject, RK.implementedBy, Literal(path)))
    capability = cls.capability
    graph.add((subject, RDFS.label, Literal(capability.label or camel_words(name), lang="en")))
    for synonym in capability.synonyms:
        graph.add((subject, SKOS.altLabel, Literal(synonym, lang="en")))
    text = description(cls)
    if text:
        graph.add((subject, RDFS.comment, Literal(text, lang="en")))
    for port, prop in PORT_PROPERTIES.items():
        types = getattr(cls, port)
        if not isinstance(types, tuple):
            problems.append(f"{where}: {port} must be a tuple of CAS types, not {types!r}")
            continue
        for cas_type in types:
            if not isinstance(cas_type, type):
                problems.append(f"{where}: {port} holds {cas_type!r}, which is not a CAS type")
                continue
            graph.add((subject, RK[prop], RK[cas_type.__name__]))
    for field, prop in CAPABILITY_PROPERTIES.items():
        for value in getattr(capability, field):
            if NAME_PATTERN.fullmatch(value) is None:
                problems.append(f"{where}: capability.{field} holds {value!r}, which is not an ontology name")
                continue
            graph.add((subject, RK[prop], RK[value]))
    for field, prop in NUMBER_PROPERTIES.items():
        graph.add((subject, RK[prop], Literal(Decimal(str(float(getattr(capability, field)))), datatype=XSD.decimal)))
    return problems


def annotator_files(classes: Iterable[type[Annotator]]) -> dict[str, Path]:
    """Each annotator name -> the source file of its class (classes without one are left out)."""
    found: dict[str, Path] = {}
    for cls in classes:
        try:
            source = inspect.getsourcefile(cls)
        except (TypeError, OSError):
            source = None
        if source is not None:
            found.setdefault(cls.__name__, Path(source))
    return found


def turtle_annotators(graphs: Mapping[Path, Graph]) -> list[str]:
    """A problem for every annotator a Turtle file declares (annotators are declared by their Python class)."""
    annotator_classes: set[Node] = {RK.Annotator}
    for graph in graphs.values():
        annotator_classes |= set(graph.transitive_subjects(RDFS.subClassOf, RK.Annotator))
    problems = []
    for path, graph in graphs.items():
        subjects = {s for c in annotator_classes for s in graph.subjects(RDF.type, c)}
        subjects |= {s for prop in ANNOTATOR_PROPERTIES for s in graph.subjects(RK[prop], None)}
        for subject in sorted(subjects, key=str):
            shown = f"rk:{local_name(subject)}" if is_rk(subject) else str(subject)
            problems.append(
                f"{path}: declares the annotator {shown}; annotators are declared by their Python class (an "
                f"Annotator subclass with inputs, outputs and a Capability) and enter the knowledge base at load, "
                f"so remove it from the Turtle file"
            )
    return problems
