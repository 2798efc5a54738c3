"""The in-memory index of a loaded ontology: built once from the RDF graph, then only read.

:func:`build_index` validates the graph (every problem is collected and raised as one
:class:`~reasoning.errors.OntologyError`) and precomputes everything the knowledge base answers: the
transitive class closure, word keys, inherited object profiles, region boxes per region class and
ranked providers per CAS type.
"""

from __future__ import annotations

from collections import defaultdict, deque
from collections.abc import Container, Iterable, Mapping
from dataclasses import dataclass, field
from decimal import Decimal
from itertools import repeat
from pathlib import Path

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.collection import Collection
from rdflib.term import Node

from ontology import REGION_BOX_PROPERTIES
from reasoning.errors import OntologyError
from reasoning.knowledge.capabilities import field_of
from reasoning.knowledge.model import KIND_WORDS, KINDS, AnnotatorSpec, Kind, ObjectProfile, Resolved
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, RK, SKOS, is_rk, local_name
from reasoning.knowledge.words import camel_words, one_line, word_key
from robokudo.core.regions import RegionBox

ROOTS: Mapping[Kind, str] = {
    "class": "PhysicalObject",
    "region_class": "Region",
    "color": "Color",
    "shape": "GeometricShape",
    "size": "SizeCategory",
    "material": "Material",
}
"""The root class of each kind of class; value kinds exclude their root, the others include it."""

PROFILE_PROPERTIES: Mapping[str, tuple[str, Kind | None]] = {
    "typicalColor": ("colors", "color"),
    "typicalShape": ("shape", "shape"),
    "sizeClass": ("size_class", "size"),
    "madeOf": ("material", "material"),
    "storedIn": ("stored_in", "region_class"),
    "packagedIn": ("packaged_in", "class"),
    "transparent": ("transparent", None),
    "printedText": ("texts", None),
    "brand": ("brand", None),
    "hasHandle": ("handle", None),
    "openTop": ("open_top", None),
    "printedLabel": ("printed", None),
    "waisted": ("waisted", None),
    "minHeightToWidth": ("min_height_to_width", None),
    "maxHeightToWidth": ("max_height_to_width", None),
    "minElongation": ("min_elongation", None),
    "maxElongation": ("max_elongation", None),
}
"""Restriction property -> (profile field, kind of its filler class, None for literal values)."""

DOMAIN_PROPERTIES: Mapping[str, Kind] = {
    "canReportColor": "color",
    "canReportShape": "shape",
    "canReportSize": "size",
    "canReportMaterial": "material",
    "canReportClass": "class",
}
"""Annotator value-domain property -> kind of its values."""

PRECONDITION_KEYS: frozenset[str] = frozenset({"depth", "region", "opaque", "model"})
"""The condition keys the planner knows how to evaluate."""

_SINGLE_FIELDS = (
    "shape",
    "size_class",
    "material",
    "stored_in",
    "packaged_in",
    "transparent",
    "brand",
    "handle",
    "printed",
    "waisted",
    "open_top",
    "min_height_to_width",
    "max_height_to_width",
    "min_elongation",
    "max_elongation",
)
_BOOLEAN_FIELDS = ("transparent", "handle", "open_top", "printed", "waisted")
_NUMBER_FIELDS = ("min_height_to_width", "max_height_to_width", "min_elongation", "max_elongation")


def _ratio_range(
    name: str, values: Mapping[str, object], problems: list[str], ratio: str = "height_to_width"
) -> tuple[float, float] | None:
    """The class's range of a ratio (``height_to_width`` or ``elongation``) from its (inherited) minimum and
    maximum; a missing bound is open."""
    low, high = values.get(f"min_{ratio}"), values.get(f"max_{ratio}")
    if low is None and high is None:
        return None
    bounds = (float(low) if low is not None else 0.0, float(high) if high is not None else float("inf"))  # type: ignore[arg-type]
    if not 0.0 <= bounds[0] < bounds[1]:
        problems.append(f"{name}: {ratio.replace('_', '-')} range {bounds} is empty or negative")
        return None
    return bounds


@dataclass(frozen=True)
class Inferred:
    """Subsumptions a reasoner derived: per class its named direct parents and all its ancestors."""

    parents: Mapping[str, frozenset[str]]
    ancestors: Mapping[str, frozenset[str]]


@dataclass(frozen=True)
class OntologyIndex:
    """Everything the knowledge base answers from; built by :func:`build_index`, never modified.

    ``up`` / ``down`` map every class to itself plus all its super- / subclasses (the transitive closure);
    ``words`` maps a word key (:func:`~reasoning.knowledge.words.word_key`) to the terms it names, preferred first;
    ``providers`` maps a CAS type to the annotators writing it or a subtype, ranked; ``names`` holds every
    ``rk:`` local name in use and ``name_keys`` their word keys (for clash checks).

    For planning many queries fast: ``ranked`` holds every annotator in rank order; ``type_bits`` gives each CAS type
    a bit and ``port_masks`` each annotator its (inputs, outputs, outputs with their supertypes) as bit masks;
    ``needing`` maps a condition key to the annotators with a precondition on it and ``class_domain`` lists the
    annotators with a class domain; ``look_alikes`` groups the object classes by (colours, shape, size class).
    """

    labels: Mapping[str, str]
    synonyms: Mapping[str, tuple[str, ...]]
    kinds: Mapping[str, Kind]
    words: Mapping[str, tuple[Resolved, ...]]
    word_labels: Mapping[str, str]
    classes: frozenset[str]
    parents: Mapping[str, tuple[str, ...]]
    children: Mapping[str, tuple[str, ...]]
    up: Mapping[str, frozenset[str]]
    down: Mapping[str, frozenset[str]]
    disjoint: Mapping[str, frozenset[str]]
    cas_types: frozenset[str]
    value_domains: Mapping[str, Kind]
    profiles: Mapping[str, ObjectProfile]
    hypothesis_types: Mapping[str, str]
    text_variants: frozenset[str]
    regions: Mapping[str, RegionBox]
    regions_by_class: Mapping[str, tuple[RegionBox, ...]]
    query_keys: Mapping[str, str]
    annotators: Mapping[str, AnnotatorSpec]
    providers: Mapping[str, tuple[AnnotatorSpec, ...]]
    precondition_keys: Mapping[str, str]
    annotator_conditions: Mapping[str, frozenset[str]]
    defined_in: Mapping[str, Path]
    names: frozenset[str]
    name_keys: Mapping[str, str]
    ranked: tuple[AnnotatorSpec, ...]
    type_bits: Mapping[str, int]
    port_masks: Mapping[str, tuple[int, int, int]]
    needing: Mapping[str, frozenset[str]]
    class_domain: tuple[AnnotatorSpec, ...]
    look_alikes: Mapping[tuple[frozenset[str], str | None, str | None], tuple[str, ...]]

    size_bounds: Mapping[str, float] = field(default_factory=dict)
    """Size class -> the bound on its objects' largest extent in metres (``rk:largestExtentBelow``)."""
    written_types: Mapping[str, frozenset[str]] = field(default_factory=dict)
    """Annotator -> what it makes present for others: its outputs and their supertypes minus its inputs and theirs
    (annotators with a port type outside the class closure are left out)."""
    makers: Mapping[str, tuple[AnnotatorSpec, ...]] = field(default_factory=dict)
    """CAS type -> its ranked providers that have inputs and do not read it (not sensor readers, not refiners)."""
    refiners: Mapping[str, tuple[AnnotatorSpec, ...]] = field(default_factory=dict)
    """CAS type -> its providers that read it too (refiners), cheapest first (by cost, then name)."""
    inspected_types: tuple[str, ...] = ()
    """The annotation types answering the query keys marked ``rk:refinedByInspection true``, sorted."""
    bit_types: tuple[str, ...] = ()
    """The CAS types by bit position: ``type_bits[bit_types[i]] == 1 << i``."""
    rule_ports: tuple[tuple[str, int, int, int], ...] = ()
    """The annotators with inputs (not sensor readers) in rank order, each with its inputs, its outputs and the
    types it provides (``port_masks``), the last two without its inputs (a provider does not provide what it
    reads)."""
    class_annotators: Mapping[str, frozenset[str]] = field(default_factory=dict)
    """Object class -> the annotators with a class domain naming it (``class_domain`` by class)."""
    class_domain_names: frozenset[str] = frozenset()
    """The names of the annotators with a class domain (``class_domain``)."""
    rank_notes: Mapping[str, str] = field(default_factory=dict)
    """Annotator -> its name with its rank: ``Name (reliability 0.9, 12 ms)`` (for the reasons of alternatives)."""
    basic_colors: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    """Colour -> the basic colours a person names it by (``rk:basicColor``: Teal -> Blue, Green), sorted."""

    def mask(self, types: Iterable[str]) -> int:
        """The bit mask of CAS types (names that are no CAS type are left out)."""
        bits = self.type_bits
        if isinstance(types, set | frozenset):  # distinct names: the sum of their bits is their union
            return sum(map(bits.get, types, repeat(0)))
        found = 0
        for name in types:
            found |= bits.get(name, 0)
        return found

    def of_kind(self, kind: Kind) -> list[str]:
        """All names of ``kind``, sorted."""
        return sorted(name for name, k in self.kinds.items() if k == kind)

    def disjoint_conflicts(self, name: str) -> list[tuple[str, str]]:
        """Pairs of declared-disjoint classes that are both superclasses (or self) of ``name``."""
        up = self.up.get(name, frozenset({name}))
        pairs = {tuple(sorted((a, b))) for a in up for b in self.disjoint.get(a, ()) if b in up}
        return sorted(pairs)  # type: ignore[arg-type]


def build_index(
    graph: Graph,
    defined_in: Mapping[str, Path] | None = None,
    inferred: Inferred | None = None,
) -> OntologyIndex:
    """Validate ``graph`` and index it; raises OntologyError listing every problem."""
    return _Builder(graph, defined_in or {}, inferred).build()


class _Builder:
    """Collects the index in several passes over the graph; problems accumulate in ``problems``."""

    def __init__(self, graph: Graph, defined_in: Mapping[str, Path], inferred: Inferred | None) -> None:
        self.graph = graph
        self.defined_in = defined_in
        self.inferred = inferred
        self.problems: list[str] = []

    # ------------------------------------------------------------------ driver

    def build(self) -> OntologyIndex:
        self._labels()
        self._hierarchy()
        self._kinds()
        self._disjointness()
        self._types_of_individuals()
        profiles = self._profiles()
        hypothesis_types = self._hypothesis_types()
        regions = self._regions()
        query_keys = self._query_keys()
        value_domains = self._value_domains()
        preconditions = self._preconditions()
        annotators = self._annotators(preconditions)
        words, word_labels = self._words(regions)
        size_bounds = self._size_bounds()
        inspected_types = self._inspected_types()
        basic_colors = self._basic_colors()
        if self.problems:
            raise OntologyError(sorted(set(self.problems)))
        annotator_conditions = {
            spec.name: frozenset(preconditions[p] for p in spec.preconditions) for spec in annotators.values()
        }
        cas_types = frozenset(self.down.get("CasType", frozenset()))
        providers = self._providers(annotators)
        ranked = tuple(sorted(annotators.values(), key=lambda s: (-s.reliability, s.cost_ms, s.name)))
        bit_types = tuple(sorted(cas_types))
        type_bits = {name: 1 << i for i, name in enumerate(bit_types)}
        port_masks = self._port_masks(annotators, providers, type_bits)
        needing: dict[str, set[str]] = defaultdict(set)
        for name, keys in annotator_conditions.items():
            for key in keys:
                needing[key].add(name)
        return OntologyIndex(
            labels=self.labels,
            synonyms={name: tuple(values) for name, values in self.alt_labels.items()},
            kinds=self.kind_of,
            words=words,
            word_labels=word_labels,
            classes=frozenset(self.class_names),
            parents=self.parents,
            children=self.children,
            up=self.up,
            down=self.down,
            disjoint=self.disjoint,
            cas_types=cas_types,
            value_domains=value_domains,
            profiles=profiles,
            hypothesis_types=hypothesis_types,
            text_variants=self._text_variants(profiles),
            regions=regions,
            regions_by_class=self._regions_by_class(regions),
            query_keys=query_keys,
            annotators=annotators,
            providers=providers,
            precondition_keys=preconditions,
            annotator_conditions=annotator_conditions,
            defined_in=dict(self.defined_in),
            names=frozenset(self.all_names),
            name_keys=self._name_keys(),
            ranked=ranked,
            type_bits=type_bits,
            port_masks=port_masks,
            needing={key: frozenset(names) for key, names in needing.items()},
            class_domain=tuple(spec for spec in ranked if spec.classes),
            look_alikes=self._look_alikes(profiles),
            size_bounds=size_bounds,
            inspected_types=inspected_types,
            written_types=self._written_types(annotators),
            makers={t: tuple(s for s in specs if s.inputs and t not in s.inputs) for t, specs in providers.items()},
            refiners={
                t: tuple(sorted((s for s in specs if t in s.inputs), key=lambda s: (s.cost_ms, s.name)))
                for t, specs in providers.items()
            },
            bit_types=bit_types,
            rule_ports=tuple(
                (s.name, inputs, outputs & ~inputs, written & ~inputs)
                for s in ranked
                if s.inputs
                for inputs, outputs, written in [port_masks[s.name]]
            ),
            class_annotators=self._class_annotators(ranked),
            class_domain_names=frozenset(spec.name for spec in ranked if spec.classes),
            rank_notes={s.name: f"{s.name} (reliability {s.reliability:g}, {s.cost_ms:g} ms)" for s in ranked},
            basic_colors=basic_colors,
        )

    @staticmethod
    def _class_annotators(ranked: Iterable[AnnotatorSpec]) -> dict[str, frozenset[str]]:
        """Object class -> the annotators whose class domain names it."""
        found: dict[str, set[str]] = defaultdict(set)
        for spec in ranked:
            for class_name in spec.classes:
                found[class_name].add(spec.name)
        return {name: frozenset(specs) for name, specs in found.items()}

    def _written_types(self, annotators: Mapping[str, AnnotatorSpec]) -> dict[str, frozenset[str]]:
        """Per annotator whose port types are all classes: its outputs and their supertypes, minus its inputs and
        theirs."""
        up = self.up
        found: dict[str, frozenset[str]] = {}
        for name, spec in annotators.items():
            if all(t in up for t in (*spec.inputs, *spec.outputs)):
                made = frozenset().union(*(up[t] for t in spec.outputs))
                found[name] = made - frozenset().union(*(up[t] for t in spec.inputs))
        return found

    @staticmethod
    def _port_masks(
        annotators: Mapping[str, AnnotatorSpec],
        providers: Mapping[str, tuple[AnnotatorSpec, ...]],
        type_bits: Mapping[str, int],
    ) -> dict[str, tuple[int, int, int]]:
        """Per annotator: its inputs, its outputs, and the types it provides (outputs and supertypes) as bit masks."""
        written = dict.fromkeys(annotators, 0)
        for type_name, specs in providers.items():
            for spec in specs:
                written[spec.name] |= type_bits[type_name]

        def mask(types: Iterable[str]) -> int:
            return sum({type_bits.get(t, 0) for t in types})

        return {name: (mask(spec.inputs), mask(spec.outputs), written[name]) for name, spec in annotators.items()}

    def _look_alikes(
        self, profiles: Mapping[str, ObjectProfile]
    ) -> dict[tuple[frozenset[str], str | None, str | None], tuple[str, ...]]:
        """Object classes grouped by how they look (colours, shape, size class), each group sorted."""
        groups: dict[tuple[frozenset[str], str | None, str | None], list[str]] = defaultdict(list)
        for name in sorted(n for n in profiles if self.kind_of.get(n) == "class"):
            profile = profiles[name]
            groups[(frozenset(profile.colors), profile.shape, profile.size_class)].append(name)
        return {look: tuple(names) for look, names in groups.items()}

    # ------------------------------------------------------------------ labels and names

    def _labels(self) -> None:
        self.labels: dict[str, str] = {}
        self.alt_labels: dict[str, list[str]] = defaultdict(list)
        for subject, label in self.graph.subject_objects(RDFS.label):
            if is_rk(subject) and isinstance(label, Literal) and label.language in (None, "en"):
                name = local_name(subject)
                if name not in self.labels or label.language == "en":
                    self.labels[name] = one_line(str(label))
        for subject, label in self.graph.subject_objects(SKOS.altLabel):
            if is_rk(subject) and isinstance(label, Literal) and label.language in (None, "en"):
                self.alt_labels[local_name(subject)].append(one_line(str(label)))
        for values in self.alt_labels.values():
            values.sort()
        self.all_names = {local_name(node) for triple in self.graph for node in triple if is_rk(node)}

    def label_of(self, name: str) -> str:
        return self.labels.get(name) or camel_words(name)

    def _name_keys(self) -> dict[str, str]:
        keys: dict[str, str] = {}
        for name in sorted(self.all_names):
            keys.setdefault(word_key(name), name)
        return keys

    # ------------------------------------------------------------------ classes

    def _hierarchy(self) -> None:
        graph = self.graph
        declared = {local_name(s) for s in graph.subjects(RDF.type, OWL.Class) if is_rk(s)}
        parents: dict[str, set[str]] = defaultdict(set)
        for child, parent in graph.subject_objects(RDFS.subClassOf):
            if not is_rk(child) or not isinstance(parent, URIRef):
                continue
            child_name = local_name(child)
            if child_name not in declared:
                self.problems.append(f"{child_name}: has a superclass but is not declared an owl:Class")
            if is_rk(parent):
                parent_name = local_name(parent)
                if parent_name not in declared:
                    self.problems.append(f"{child_name}: superclass {parent_name} is not declared (a typo?)")
                    continue
                if parent_name != child_name:
                    parents[child_name].add(parent_name)
        if self.inferred is not None:
            for name, inferred_parents in self.inferred.parents.items():
                if name in declared:
                    parents[name] |= {p for p in inferred_parents if p in declared and p != name}
        self.class_names = declared
        self.parents = {name: tuple(sorted(parents.get(name, ()))) for name in sorted(declared)}
        children: dict[str, list[str]] = defaultdict(list)
        for name, direct in self.parents.items():
            for parent in direct:
                children[parent].append(name)
        self.children = {name: tuple(sorted(children.get(name, ()))) for name in sorted(declared)}
        up: dict[str, frozenset[str]] = {}
        for name in self.parents:
            seen = {name}
            queue = deque(self.parents[name])
            while queue:
                current = queue.popleft()
                if current in seen:
                    continue
                seen.add(current)
                done = up.get(current)
                if done is not None:
                    seen |= done
                else:
                    queue.extend(self.parents.get(current, ()))
            if self.inferred is not None:
                seen |= {a for a in self.inferred.ancestors.get(name, ()) if a in declared}
            up[name] = frozenset(seen)
        down: dict[str, set[str]] = {name: set() for name in up}
        for name, ancestors in up.items():
            for ancestor in ancestors:
                down[ancestor].add(name)
        self.up = up
        self.down = {name: frozenset(values) for name, values in down.items()}

    def _kinds(self) -> None:
        self.kind_of: dict[str, Kind] = {}
        for kind, root in ROOTS.items():
            if root not in self.down:
                self.problems.append(f"the ontology does not declare the class {root}")
                continue
            members = self.down[root] if kind in ("class", "region_class") else self.down[root] - {root}
            for name in members:
                previous = self.kind_of.get(name)
                if previous is not None and previous != kind:
                    self.problems.append(f"{name}: is both a {previous} and a {kind} class")
                self.kind_of[name] = kind

    def _disjointness(self) -> None:
        pairs: dict[str, set[str]] = defaultdict(set)

        def add(a: Node, b: Node) -> None:
            if is_rk(a) and is_rk(b) and a != b:
                pairs[local_name(a)].add(local_name(b))
                pairs[local_name(b)].add(local_name(a))

        for a, b in self.graph.subject_objects(OWL.disjointWith):
            add(a, b)
        for group in self.graph.subjects(RDF.type, OWL.AllDisjointClasses):
            for head in self.graph.objects(group, OWL.members):
                members = list(Collection(self.graph, head))
                for i, a in enumerate(members):
                    for b in members[i + 1 :]:
                        add(a, b)
        for name in list(pairs):
            if name not in self.class_names:
                self.problems.append(f"disjointness names {name}, which is not a declared class")
        self.disjoint = {name: frozenset(values) for name, values in pairs.items()}

    # ------------------------------------------------------------------ object profiles

    def _inspected_types(self) -> tuple[str, ...]:
        """The annotation types of the query keys an inspection refines (``rk:refinedByInspection true``)."""
        found = set()
        for subject, value in self.graph.subject_objects(RK["refinedByInspection"]):
            name = local_name(subject) if is_rk(subject) else str(subject)
            answers = [local_name(v) for v in self.graph.objects(subject, RK.answeredBy)]
            if not (isinstance(value, Literal) and isinstance(value.toPython(), bool)) or len(answers) != 1:
                self.problems.append(f"{name}: rk:refinedByInspection is a boolean said of query keys")
            elif value.toPython():
                found.add(answers[0])
        return tuple(sorted(found))

    def _size_bounds(self) -> dict[str, float]:
        """Each size class's ``rk:largestExtentBelow`` (a positive number of metres)."""
        bounds: dict[str, float] = {}
        for subject, value in self.graph.subject_objects(RK["largestExtentBelow"]):
            name = local_name(subject) if is_rk(subject) else str(subject)
            number = value.toPython() if isinstance(value, Literal) else None
            if self.kind_of.get(name) != "size":
                self.problems.append(f"{name}: rk:largestExtentBelow is said only of size classes")
            elif isinstance(number, bool) or not isinstance(number, int | float | Decimal) or not number > 0:
                self.problems.append(
                    f"{name}: rk:largestExtentBelow must be a positive number of metres, not {value!s}"
                )
            else:
                bounds[name] = float(number)
        return bounds

    def _own_properties(self, name: str) -> dict[str, list[object]]:
        """The profile values a class declares itself (restrictions on its superclass list)."""
        own: dict[str, list[object]] = defaultdict(list)
        for restriction in self.graph.objects(RK[name], RDFS.subClassOf):
            if not isinstance(restriction, BNode):
                continue
            prop = self.graph.value(restriction, OWL.onProperty)
            if not is_rk(prop) or local_name(prop) not in PROFILE_PROPERTIES:
                continue
            prop_name = local_name(prop)
            field_name, kind = PROFILE_PROPERTIES[prop_name]
            filler = self.graph.value(restriction, OWL.someValuesFrom)
            value = self.graph.value(restriction, OWL.hasValue)
            if kind is not None:
                if not is_rk(filler) or self.kind_of.get(local_name(filler)) != kind:
                    shown = local_name(filler) if filler is not None else "nothing"
                    self.problems.append(f"{name}: rk:{prop_name} must be 'some' of a {kind} class, not {shown}")
                    continue
                own[field_name].append(local_name(filler))
            else:
                if not isinstance(value, Literal):
                    self.problems.append(f"{name}: rk:{prop_name} needs 'value' with a literal")
                    continue
                python_value = value.toPython()
                if field_name in _BOOLEAN_FIELDS:
                    if not isinstance(python_value, bool):
                        self.problems.append(f"{name}: rk:{prop_name} must be true or false, not {value!s}")
                        continue
                    own[field_name].append(python_value)
                elif field_name in _NUMBER_FIELDS:
                    if isinstance(python_value, bool) or not isinstance(python_value, (int, float, Decimal)):
                        self.problems.append(f"{name}: rk:{prop_name} must be a number, not {value!s}")
                        continue
                    own[field_name].append(float(python_value))
                else:
                    own[field_name].append(str(value))
        for field_name in _SINGLE_FIELDS:
            if len(set(own.get(field_name, ()))) > 1:
                values = sorted(map(str, own[field_name]))
                self.problems.append(f"{name}: declares several values for {field_name}: {values}")
        return own

    def _profiles(self) -> dict[str, ObjectProfile]:
        object_classes = sorted(self.down.get("PhysicalObject", ()))
        own = {name: self._own_properties(name) for name in object_classes}
        profiles: dict[str, ObjectProfile] = {}
        for name in object_classes:
            levels = self._levels(name)
            values: dict[str, object] = {}
            origins: list[tuple[str, str]] = []
            for field_name in ("colors", *_SINGLE_FIELDS):
                for level in levels:
                    found = sorted(c for c in level if field_name in own.get(c, {}))
                    if found:
                        merged = sorted({v for c in found for v in own[c][field_name]}, key=str)
                        values[field_name] = tuple(merged) if field_name == "colors" else merged[0]
                        origins.append((field_name, found[0]))
                        break
            texts: list[str] = []
            text_origin = ""
            for level in levels:
                for c in sorted(level):
                    for text in own.get(c, {}).get("texts", ()):
                        text_origin = text_origin or c
                        if text not in texts:
                            texts.append(str(text))
            if text_origin:
                origins.append(("texts", text_origin))
            profiles[name] = ObjectProfile(
                name=name,
                label=self.label_of(name),
                synonyms=tuple(self.alt_labels.get(name, ())),
                colors=values.get("colors", ()),  # type: ignore[arg-type]
                shape=values.get("shape"),  # type: ignore[arg-type]
                size_class=values.get("size_class"),  # type: ignore[arg-type]
                material=values.get("material"),  # type: ignore[arg-type]
                transparent=values.get("transparent"),  # type: ignore[arg-type]
                stored_in=values.get("stored_in"),  # type: ignore[arg-type]
                packaged_in=values.get("packaged_in"),  # type: ignore[arg-type]
                texts=tuple(texts),
                brand=values.get("brand"),  # type: ignore[arg-type]
                origins=tuple(origins),
                handle=values.get("handle"),  # type: ignore[arg-type]
                printed=values.get("printed"),  # type: ignore[arg-type]
                waisted=values.get("waisted"),  # type: ignore[arg-type]
                open_top=values.get("open_top"),  # type: ignore[arg-type]
                height_to_width=_ratio_range(name, values, self.problems),
                elongation=_ratio_range(name, values, self.problems, "elongation"),
            )
        return profiles

    def _hypothesis_types(self) -> dict[str, str]:
        """Per object class the hypothesis type its instances are found as (``rk:perceivedAs``, inherited from the
        nearest class declaring it, else ObjectHypothesis)."""
        hypotheses = self.down.get("ObjectHypothesis", frozenset())
        own: dict[str, str] = {}
        for subject, value in self.graph.subject_objects(RK.perceivedAs):
            name, type_name = local_name(subject), local_name(value)
            if type_name not in hypotheses:
                self.problems.append(f"{name}: rk:perceivedAs must name ObjectHypothesis or a subtype, not {type_name}")
                continue
            own[name] = type_name
        found: dict[str, str] = {}
        for name in self.down.get("PhysicalObject", ()):
            declared = [own[c] for level in self._levels(name) for c in sorted(level) if c in own]
            found[name] = declared[0] if declared else "ObjectHypothesis"
        return found

    def _basic_colors(self) -> dict[str, tuple[str, ...]]:
        """Per colour the basic colours a person names it by (``rk:basicColor``); both must be colours."""
        colors = self.down.get("Color", frozenset())
        found: dict[str, set[str]] = defaultdict(set)
        for subject, value in self.graph.subject_objects(RK.basicColor):
            name, basic = local_name(subject), local_name(value)
            if name not in colors or basic not in colors or name == basic:
                self.problems.append(f"{name} rk:basicColor {basic}: it links a colour to another colour")
                continue
            found[name].add(basic)
        return {name: tuple(sorted(basics)) for name, basics in found.items()}

    def _levels(self, name: str) -> list[set[str]]:
        """``name``, then its parents, then their parents, ... (each class at its shortest distance)."""
        levels = [{name}]
        seen = {name}
        while True:
            following = {p for c in levels[-1] for p in self.parents.get(c, ())} - seen
            if not following:
                return levels
            seen |= following
            levels.append(following)

    def _text_variants(self, profiles: Mapping[str, ObjectProfile]) -> frozenset[str]:
        """Classes with a sibling that looks the same but carries other printed text or another brand."""
        found: set[str] = set()
        for children in self.children.values():
            groups: dict[tuple[object, ...], list[ObjectProfile]] = defaultdict(list)
            for child in children:
                profile = profiles.get(child)
                if profile is not None:
                    look = (profile.colors, profile.shape, profile.size_class, profile.material, profile.transparent)
                    groups[look].append(profile)
            for members in groups.values():
                if len({(frozenset(p.texts), p.brand) for p in members}) > 1:
                    found.update(p.name for p in members)
        return frozenset(found)

    # ------------------------------------------------------------------ individuals

    def _types_of_individuals(self) -> None:
        types: dict[str, set[str]] = defaultdict(set)
        for subject, rdf_type in self.graph.subject_objects(RDF.type):
            if is_rk(subject) and is_rk(rdf_type):
                types[local_name(subject)].add(local_name(rdf_type))
        self.individual_types = types

    def _individuals_of(self, class_name: str) -> list[str]:
        members = self.down.get(class_name, frozenset({class_name}))
        return sorted(name for name, types in self.individual_types.items() if types & members)

    def _literal(self, subject: str, prop: str) -> Literal | None:
        values = [v for v in self.graph.objects(RK[subject], RK[prop]) if isinstance(v, Literal)]
        if len(values) > 1:
            self.problems.append(f"{subject}: has {len(values)} values for rk:{prop}, expected one")
        return values[0] if values else None

    def _number(self, subject: str, prop: str, required: bool = True) -> float | None:
        value = self._literal(subject, prop)
        if value is None:
            if required:
                self.problems.append(f"{subject}: rk:{prop} is missing")
            return None
        try:
            return float(value.toPython())
        except (TypeError, ValueError):
            self.problems.append(f"{subject}: rk:{prop} is not a number: {value!s}")
            return None

    def _regions(self) -> dict[str, RegionBox]:
        regions: dict[str, RegionBox] = {}
        region_classes = self.down.get("Region", frozenset())
        for name in self._individuals_of("Region"):
            classes = self.individual_types[name] & region_classes
            specific = sorted(c for c in classes if not any(c != o and c in self.up[o] for o in classes))
            if len(specific) != 1:
                self.problems.append(f"region {name}: needs exactly one most specific region class, has {specific}")
                continue
            numbers = [self._number(name, prop) for prop in REGION_BOX_PROPERTIES]
            frame = self._literal(name, "frame")
            if frame is None:
                self.problems.append(f"region {name}: rk:frame is missing")
            if frame is None or any(n is None for n in numbers):
                continue
            values = [float(n) for n in numbers if n is not None]
            if any(v <= 0 for v in values[7:]):
                self.problems.append(f"region {name}: box sizes must be positive, got {values[7:]}")
            norm = sum(v * v for v in values[3:7]) ** 0.5
            if abs(norm - 1.0) > 1e-3:
                self.problems.append(f"region {name}: orientation is not a unit quaternion (norm {norm:.4f})")
                continue
            in_map = self.graph.value(RK[name], RK.partOfMap)
            regions[name] = RegionBox(
                name=name,
                region_class=specific[0],
                frame=str(frame),
                position=(values[0], values[1], values[2]),
                orientation=(values[3] / norm, values[4] / norm, values[5] / norm, values[6] / norm),
                size=(values[7], values[8], values[9]),
                label=self.label_of(name),
                semantic_map=local_name(in_map) if is_rk(in_map) else "",
            )
        return regions

    def _regions_by_class(self, regions: Mapping[str, RegionBox]) -> dict[str, tuple[RegionBox, ...]]:
        by_class: dict[str, tuple[RegionBox, ...]] = {}
        for region_class in self.down.get("Region", ()):
            members = self.down[region_class]
            by_class[region_class] = tuple(box for _, box in sorted(regions.items()) if box.region_class in members)
        return by_class

    def _query_keys(self) -> dict[str, str]:
        keys: dict[str, str] = {}
        cas_types = self.down.get("CasType", frozenset())
        for name in self._individuals_of("QueryKey"):
            answers = [local_name(v) for v in self.graph.objects(RK[name], RK.answeredBy)]
            if len(answers) != 1 or answers[0] not in cas_types:
                self.problems.append(f"query key {name}: rk:answeredBy must name exactly one CAS type, got {answers}")
                continue
            words = [self.labels.get(name, ""), *self.alt_labels.get(name, ())]
            for word in filter(None, words):
                previous = keys.get(word_key(word))
                if previous is not None and previous != answers[0]:
                    self.problems.append(f"query key word {word!r} is answered by both {previous} and {answers[0]}")
                keys[word_key(word)] = answers[0]
        return keys

    def _value_domains(self) -> dict[str, Kind]:
        domains: dict[str, Kind] = {}
        root_kinds = {root: kind for kind, root in ROOTS.items()}
        for subject, root in self.graph.subject_objects(RK.valueDomain):
            name, root_name = local_name(subject), local_name(root)
            if root_name not in root_kinds or name not in self.down.get("CasType", ()):
                self.problems.append(f"{name}: rk:valueDomain must link a CAS type to a value root, not {root_name}")
                continue
            domains[name] = root_kinds[root_name]
        return domains

    def _preconditions(self) -> dict[str, str]:
        keys: dict[str, str] = {}
        for name in self._individuals_of("Precondition"):
            key = self._literal(name, "conditionKey")
            if key is None or str(key) not in PRECONDITION_KEYS:
                self.problems.append(
                    f"precondition {name}: rk:conditionKey must be one of {sorted(PRECONDITION_KEYS)}, got {key}"
                )
                continue
            keys[name] = str(key)
        return keys

    # ------------------------------------------------------------------ annotators

    def _annotators(self, preconditions: Mapping[str, str]) -> dict[str, AnnotatorSpec]:
        specs: dict[str, AnnotatorSpec] = {}
        cas_types = self.down.get("CasType", frozenset())
        names_of_kind: dict[Kind, frozenset[str]] = {
            kind: frozenset(n for n, k in self.kind_of.items() if k == kind) for kind in DOMAIN_PROPERTIES.values()
        }
        for name in self._individuals_of("Annotator"):
            subject = RK[name]
            implemented = [str(v) for v in self.graph.objects(subject, RK.implementedBy)]
            if len(implemented) != 1:
                self.problems.append(f"annotator {name}: needs exactly one rk:implementedBy, has {len(implemented)}")
                continue
            where = f"annotator class {name} ({implemented[0]})"
            inputs = self._annotator_names(name, where, "requiresInput", cas_types, "CAS type")
            optional = self._annotator_names(name, where, "optionalInput", cas_types, "CAS type")
            outputs = self._annotator_names(name, where, "providesOutput", cas_types, "CAS type")
            domains = {
                kind: frozenset(
                    self._annotator_names(
                        name,
                        where,
                        prop,
                        names_of_kind[kind],
                        f"{KIND_WORDS[kind]} of the ontology",
                    )
                )
                for prop, kind in DOMAIN_PROPERTIES.items()
            }
            conditions = self._annotator_names(name, where, "precondition", preconditions, "known rk:Precondition")
            cost = self._number(name, "expectedCostMs")
            reliability = self._number(name, "reliability")
            if cost is not None and cost < 0:
                self.problems.append(f"{where}: capability.cost_ms must not be negative")
            if reliability is not None and not 0.0 <= reliability <= 1.0:
                self.problems.append(f"{where}: capability.reliability must be within 0..1")
            if not outputs:
                self.problems.append(f"{where}: provides no output")
            specs[name] = AnnotatorSpec(
                name=name,
                implemented_by=implemented[0],
                inputs=tuple(inputs),
                optional_inputs=tuple(optional),
                outputs=tuple(outputs),
                colors=domains["color"],
                shapes=domains["shape"],
                sizes=domains["size"],
                materials=domains["material"],
                classes=domains["class"],
                preconditions=tuple(conditions),
                cost_ms=cost or 0.0,
                reliability=reliability if reliability is not None else 0.0,
                label=self.label_of(name),
            )
        return specs

    def _annotator_names(self, name: str, where: str, prop: str, members: Container[str], what: str) -> list[str]:
        """The sorted names an annotator gives for ``prop`` that are ``members``; the others are problems."""
        found = sorted(local_name(v) for v in self.graph.objects(RK[name], RK[prop]))
        for value in found:
            if value not in members:
                self.problems.append(f"{where}: {field_of(prop)} names {value}, which is not a {what}")
        return [v for v in found if v in members]

    def _providers(self, annotators: Mapping[str, AnnotatorSpec]) -> dict[str, tuple[AnnotatorSpec, ...]]:
        ranked = sorted(annotators.values(), key=lambda s: (-s.reliability, s.cost_ms, s.name))
        providers: dict[str, tuple[AnnotatorSpec, ...]] = {}
        for cas_type in self.down.get("CasType", ()):
            members = self.down[cas_type]
            providers[cas_type] = tuple(s for s in ranked if any(o in members for o in s.outputs))
        return providers

    # ------------------------------------------------------------------ words

    def _words(self, regions: Mapping[str, RegionBox]) -> tuple[dict[str, tuple[Resolved, ...]], dict[str, str]]:
        entries: dict[str, set[Resolved]] = defaultdict(set)
        shown: dict[str, str] = {}

        def add(word: str, resolved: Resolved) -> None:
            key = word_key(word)
            if key:
                entries[key].add(resolved)
                shown.setdefault(key, word)

        for name, kind in self.kind_of.items():
            if kind in ("class", "region_class") or name != ROOTS[kind]:
                resolved = Resolved(kind, name)
                add(self.label_of(name), resolved)
                for alt in self.alt_labels.get(name, ()):
                    add(alt, resolved)
                add(name, resolved)
        for name in regions:
            resolved = Resolved("region", name)
            add(self.label_of(name), resolved)
            for alt in self.alt_labels.get(name, ()):
                add(alt, resolved)
            add(name, resolved)
        order = {kind: i for i, kind in enumerate(KINDS)}
        words = {key: tuple(sorted(found, key=lambda r: (order[r.kind], r.name))) for key, found in entries.items()}
        return words, shown
