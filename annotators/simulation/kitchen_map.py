"""The built-in kitchen's region boxes, read from its semantic map (``ontology/kitchen_map.ttl``).

The Turtle map is the one place the boxes are written; the simulator reads them from there so the scene it
renders and the knowledge base's regions are the same data.
"""

from __future__ import annotations

from pathlib import Path

from rdflib import Graph, Literal, URIRef
from rdflib.namespace import RDF, RDFS

from ontology import DEFAULT_MAP_FILE, NAMESPACE, REGION_BOX_PROPERTIES, ontology_dir
from robokudo.core.regions import RegionBox

_PART_OF_MAP = URIRef(NAMESPACE + "partOfMap")
_FRAME = URIRef(NAMESPACE + "frame")


def _local(node: object) -> str:
    text = str(node)
    return text[len(NAMESPACE) :] if text.startswith(NAMESPACE) else ""


def _literal(graph: Graph, subject: URIRef, prop: URIRef) -> Literal:
    value = graph.value(subject, prop)
    if not isinstance(value, Literal):
        raise ValueError(f"{_local(subject)}: {_local(prop)} is missing")
    return value


def map_regions(path: Path | None = None) -> tuple[RegionBox, ...]:
    """The region boxes a semantic map declares (default: the built-in kitchen's), sorted by name.

    A region's class is its ``rk:`` type; the map must give each region exactly one.
    """
    graph = Graph().parse(path or ontology_dir() / DEFAULT_MAP_FILE, format="turtle")
    regions = []
    for subject in {s for s in graph.subjects(_PART_OF_MAP, None) if isinstance(s, URIRef)}:
        name = _local(subject)
        classes = [_local(t) for t in graph.objects(subject, RDF.type) if _local(t)]
        if len(classes) != 1:
            raise ValueError(f"region {name}: needs exactly one rk: class, has {sorted(classes)}")
        values = [float(_literal(graph, subject, URIRef(NAMESPACE + p)).toPython()) for p in REGION_BOX_PROPERTIES]
        label = graph.value(subject, RDFS.label)
        regions.append(
            RegionBox(
                name=name,
                region_class=classes[0],
                frame=str(_literal(graph, subject, _FRAME)),
                position=(values[0], values[1], values[2]),
                orientation=(values[3], values[4], values[5], values[6]),
                size=(values[7], values[8], values[9]),
                label=str(label) if label is not None else "",
                semantic_map=_local(graph.value(subject, _PART_OF_MAP)),
            )
        )
    return tuple(sorted(regions, key=lambda r: r.name))
