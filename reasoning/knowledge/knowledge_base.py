"""The knowledge base: the ontology loaded once, answering typed questions from in-memory indexes.

Loading parses the Turtle files with rdflib, adds the triples of the annotator classes it is given (an annotator
is declared by its Python class, never in Turtle: :mod:`reasoning.knowledge.capabilities`) and, with
``reason=True``, classifies the whole with HermiT; every question afterwards is a dictionary or set lookup on
the :class:`~reasoning.knowledge.index.OntologyIndex`: no question parses a file or runs the reasoner.
:meth:`KnowledgeBase.reload` swaps in a fresh index (re-parsing only the files that changed), so a long-running
process sees ontology edits.
"""

from __future__ import annotations

import difflib
import logging
from collections.abc import Collection, Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rdflib import Graph

from reasoning.errors import AmbiguousTermError, InconsistentOntologyError, OntologyError, UnknownTermError
from reasoning.knowledge.capabilities import annotator_files, capability_graph, turtle_annotators
from reasoning.knowledge.hermit import ReasonerResult, classify, describe_unsatisfiable
from reasoning.knowledge.index import OntologyIndex, build_index
from reasoning.knowledge.model import (
    KIND_WORDS,
    KINDS,
    AnnotatorSpec,
    Conditions,
    Kind,
    ObjectProfile,
    Resolved,
)
from reasoning.knowledge.sources import Sources, Stamp, defined_names, file_stamp, merge_graphs, parse_turtle
from reasoning.knowledge.words import close_keys, singular_keys, word_key
from robokudo.core.regions import RegionBox

if TYPE_CHECKING:
    from robokudo.core.annotator import Annotator

log = logging.getLogger(__name__)

UNKNOWN_CLASS_ADVICE = "'find all objects' shows every object seen, and a new class can be added to the user ontology"
"""Said with an unknown object class that resembles no known one (a person asked for something not modelled)."""

_ALL_CONDITIONS = Conditions()
_CLASS_KINDS: tuple[Kind, ...] = ("class", "region_class", "color", "shape", "size", "material")


class KnowledgeBase:
    """Object classes, regions, annotation types and annotator capabilities, indexed for fast questions."""

    def __init__(self, sources: Sources, reason: bool = False, annotators: Iterable[type[Annotator]] = ()) -> None:
        self._sources = sources
        self._reason = reason
        self._annotator_classes = tuple(dict.fromkeys(annotators))
        self._annotator_graph = capability_graph(self._annotator_classes)
        self._annotator_files = annotator_files(self._annotator_classes)
        self._parsed: dict[Path, tuple[Stamp | None, Graph]] = {}
        self._stamps: dict[Path, Stamp | None] = {}
        self._reasoner: ReasonerResult | None = None
        self._index: OntologyIndex
        self.reload()

    @classmethod
    def load(
        cls,
        user_file: Path | None = None,
        *,
        reason: bool = False,
        map_file: Path | None = None,
        extra_files: Sequence[Path] = (),
        files: Sequence[Path] | None = None,
        annotators: Iterable[type[Annotator]] = (),
    ) -> KnowledgeBase:
        """Load the shipped ontology, a semantic map (default: the built-in kitchen), ``extra_files``, the user
        file (default: :func:`~reasoning.knowledge.sources.default_user_file`; a missing file is empty) and the
        ``annotators`` (Annotator classes; their declarations become the ontology's annotator individuals).

        ``files`` replaces the shipped files and map. With ``reason=True`` HermiT classifies the ontology
        (inferred subsumptions join the hierarchy; unsatisfiable classes raise InconsistentOntologyError);
        without Java it logs why and keeps the asserted hierarchy. A class whose declaration names something
        the ontology lacks, or an annotator declared in a Turtle file, raises OntologyError. The application
        loads with every annotator of the catalog (``robokudo.application.knowledge.load_knowledge_base``).
        """
        return cls(Sources.default(user_file, map_file, extra_files, files), reason=reason, annotators=annotators)

    # ------------------------------------------------------------------ loading

    @property
    def sources(self) -> Sources:
        """The files this knowledge base reads."""
        return self._sources

    @property
    def user_file(self) -> Path:
        """The user ontology file layered over the shipped ones."""
        return self._sources.user_file

    @property
    def index(self) -> OntologyIndex:
        """The current in-memory index (read-only)."""
        return self._index

    @property
    def reasoner_result(self) -> ReasonerResult | None:
        """The last HermiT run of a ``reason=True`` knowledge base, else None."""
        return self._reasoner

    @property
    def annotator_classes(self) -> tuple[type[Annotator], ...]:
        """The annotator classes whose declarations this knowledge base holds (kept across reloads)."""
        return self._annotator_classes

    @property
    def annotator_graph(self) -> Graph:
        """The triples the annotator classes declare (read-only)."""
        return self._annotator_graph

    def combine(self, graphs: Mapping[Path, Graph]) -> tuple[Graph, dict[str, Path]]:
        """``graphs`` merged with the annotator classes' triples, and the file each term is defined in.

        An annotator is defined in its class's source file. OntologyError when one of ``graphs`` declares an
        annotator (annotators are declared by their Python class).
        """
        declared_in_turtle = turtle_annotators(graphs)
        if declared_in_turtle:
            raise OntologyError(declared_in_turtle)
        merged = merge_graphs([*graphs.values(), self._annotator_graph])
        return merged, {**self._annotator_files, **defined_names(graphs)}

    def source_graphs(self) -> dict[Path, Graph]:
        """The parsed graph of every existing source file, the user file last (cached while unchanged)."""
        return self._read()[0]

    def _read(self) -> tuple[dict[Path, Graph], dict[Path, Stamp | None]]:
        graphs: dict[Path, Graph] = {}
        stamps: dict[Path, Stamp | None] = {}
        for path in (*self._sources.files, self._sources.user_file):
            stamp = stamps[path] = file_stamp(path)
            if stamp is None:
                if path != self._sources.user_file:
                    parse_turtle(path)  # raises the "no such file" OntologyError
                continue
            cached = self._parsed.get(path)
            if cached is None or cached[0] != stamp:
                cached = (stamp, parse_turtle(path))
                self._parsed[path] = cached
            graphs[path] = cached[1]
        return graphs, stamps

    def adopt_parsed(self, path: Path, stamp: Stamp, graph: Graph) -> None:
        """Take ``graph`` as the parse of source ``path`` while the file has ``stamp`` (an editor that read or wrote
        it already); the next (re)load uses it instead of parsing the file again."""
        self._parsed[path] = (stamp, graph)

    def adopt_index(self, graphs: Mapping[Path, Graph], index: OntologyIndex) -> bool:
        """Take ``index`` (built by :func:`build_index` from :meth:`combine` of ``graphs``) as the current index when
        ``graphs`` are the parses of the sources as they are now and this knowledge base does not reason (an
        editor validated exactly this); True when taken, else nothing changes."""
        if self._reason:
            return False
        paths = (*self._sources.files, self._sources.user_file)
        stamps = {path: file_stamp(path) for path in paths}
        for path in paths:
            parsed = self._parsed.get(path)
            if stamps[path] is None:
                if path in graphs:
                    return False
            elif parsed is None or parsed[0] != stamps[path] or graphs.get(path) is not parsed[1]:
                return False
        self._index = index
        self._reasoner = None
        self._stamps = stamps
        return True

    def reload(self) -> None:
        """Re-read the sources (only changed files are parsed again) and swap in a new index.

        The annotator classes' triples are merged in again (the classes are fixed when the knowledge base is made).
        """
        graphs, stamps = self._read()
        merged, defined = self.combine(graphs)
        result: ReasonerResult | None = None
        inferred = None
        if self._reason:
            result = classify(merged)
            if result.available and not result.ok:
                asserted = build_index(merged, defined)
                raise InconsistentOntologyError(
                    describe_unsatisfiable(asserted, result), heading="the reasoner rejects the ontology"
                )
            inferred = result.inferred
        self._index = build_index(merged, defined, inferred)
        self._reasoner = result
        self._stamps = stamps

    def reload_if_changed(self) -> bool:
        """Reload when a source file changed since the last load (one ``stat`` per file); True if reloaded."""
        for path, stamp in self._stamps.items():
            if file_stamp(path) != stamp:
                self.reload()
                return True
        return False

    # ------------------------------------------------------------------ words

    def resolve(self, word: str, kinds: Collection[Kind] | None = None) -> Resolved:
        """The term a word names: by label, synonym or name, any case, with spaces, underscores or plurals.

        An exact name wins ("Fridge" is the region class, "fridge" the region of the map); otherwise, when a
        word names terms of several kinds, the first in :data:`~reasoning.knowledge.model.KINDS` wins (an object class
        before a region, ...); ``kinds`` restricts the search. Raises UnknownTermError with close
        matches, or AmbiguousTermError when it names several terms of the same kind.
        """
        exact = self._exact(word)
        if exact is not None and (kinds is None or exact.kind in kinds):
            return exact
        found = self._lookup(word, kinds)
        if not found:
            advice = UNKNOWN_CLASS_ADVICE if kinds is not None and set(kinds) == {"class"} else ""
            raise UnknownTermError(word, self._what(kinds), self._suggestions(word, kinds), advice)
        same = [r for r in found if r.kind == found[0].kind]
        if len(same) > 1:
            raise AmbiguousTermError(word, [r.name for r in same])
        return same[0]

    def resolve_all(self, word: str) -> tuple[Resolved, ...]:
        """Every term a word may name, in preference order (empty when none)."""
        found = self._lookup(word, None)
        exact = self._exact(word)
        return found if exact is None else (exact, *(r for r in found if r != exact))

    def _exact(self, word: str) -> Resolved | None:
        """The term whose exact name ``word`` is (an exact name beats any label)."""
        index = self._index
        if word in index.regions:
            return Resolved("region", word)
        kind = index.kinds.get(word)
        return None if kind is None else Resolved(kind, word)

    def _lookup(self, word: str, kinds: Collection[Kind] | None) -> tuple[Resolved, ...]:
        words = self._index.words
        key = word_key(word)
        # A label said only in the plural ("sweets", "oats") is still found from its singular, which a phrase's
        # plural rule may have made of it; after the key and its singulars, so it never shadows a label.
        for candidate in (key, *singular_keys(key), key + "s", key + "es"):
            found = words.get(candidate)
            if found and kinds is not None:
                found = tuple(r for r in found if r.kind in kinds)
            if found:
                return found
        return ()

    def _suggestions(self, word: str, kinds: Collection[Kind] | None) -> list[str]:
        index = self._index
        keys = [k for k, found in index.words.items() if kinds is None or any(r.kind in kinds for r in found)]
        return [index.word_labels[k] for k in close_keys(word_key(word), keys)]

    @staticmethod
    def _what(kinds: Collection[Kind] | None) -> str:
        if kinds is None or len(kinds) == 0 or set(kinds) == set(KINDS):
            return "term"
        return " or ".join(KIND_WORDS[k] for k in KINDS if k in kinds)

    def _name(self, term: str, kinds: Collection[Kind]) -> str:
        """``term`` if it is the exact name of a term of one of ``kinds``, else what it resolves to."""
        kind = self._index.kinds.get(term)
        if kind is not None and kind in kinds:
            return term
        return self.resolve(term, kinds).name

    def _class(self, term: str) -> str:
        """A class name (any class, CAS types included) for ``term``."""
        if term in self._index.up:
            return term
        return self.resolve(term, _CLASS_KINDS).name

    def kind(self, name: str) -> Kind | None:
        """The kind of an exact name (None for names of other things, such as CAS types)."""
        if name in self._index.regions:
            return "region"
        return self._index.kinds.get(name)

    def label(self, name: str) -> str:
        """The label of a term (its lower-case words when it has none); runtime colour names are these."""
        return self._index.labels.get(name) or name

    def synonyms(self, name: str) -> tuple[str, ...]:
        """The synonyms (skos:altLabel) of a term."""
        return self._index.synonyms.get(name, ())

    def basic_colors(self, name: str) -> tuple[str, ...]:
        """The basic colours a person names a colour by when only the basic terms may be used (``rk:basicColor``:
        Teal -> Blue, Green); () for a basic colour and for any other term."""
        return self._index.basic_colors.get(name, ())

    def reported_as(self, annotation_type: str, value: str) -> tuple[str, ...]:
        """The values an expert reports for an asked ``value`` of ``annotation_type``: the value itself, or, for a
        colour no annotator reports that has basic colours (:meth:`basic_colors`), those (teal -> blue, green)."""
        basics = self.basic_colors(value)
        if basics and not self.providers(annotation_type, value=value):
            return basics
        return (value,)

    def names_of_kind(self, kind: Kind) -> list[str]:
        """All terms of a kind, sorted (e.g. every colour)."""
        if kind == "region":
            return sorted(self._index.regions)
        return self._index.of_kind(kind)

    def defined_in(self, name: str) -> Path | None:
        """The file that defines a term, or None."""
        return self._index.defined_in.get(name)

    # ------------------------------------------------------------------ classes

    def is_subclass(self, name: str, ancestor: str) -> bool:
        """True when ``name`` is ``ancestor`` or one of its (transitive) subclasses."""
        return self._class(ancestor) in self._index.up[self._class(name)]

    def answers_to(self, name: str, asked: str) -> bool:
        """True when an object of class ``name`` answers a query for class ``asked``: it is one (``is_subclass``),
        or it is typically packaged in one (``rk:packagedIn``, inherited): what is seen of a mustard is its
        bottle, so a mustard answers "find all bottles"."""
        if self.is_subclass(name, asked):
            return True
        cls = self._class(name)
        package = self._index.profiles[cls].packaged_in if self.kind(cls) == "class" else None
        return package is not None and self.is_subclass(package, asked)

    def subclasses(self, name: str, direct: bool = False) -> list[str]:
        """The (direct or all) proper subclasses of a class, sorted."""
        cls = self._class(name)
        if direct:
            return list(self._index.children.get(cls, ()))
        return sorted(self._index.down[cls] - {cls})

    def superclasses(self, name: str, direct: bool = False) -> list[str]:
        """The (direct or all) proper superclasses of a class, sorted."""
        cls = self._class(name)
        if direct:
            return list(self._index.parents.get(cls, ()))
        return sorted(self._index.up[cls] - {cls})

    def are_disjoint(self, a: str, b: str) -> bool:
        """True when the ontology declares ``a`` (or a superclass) disjoint with ``b`` (or a superclass)."""
        index = self._index
        up_b = index.up[self._class(b)]
        return any(not index.disjoint.get(x, frozenset()).isdisjoint(up_b) for x in index.up[self._class(a)])

    def object_profile(self, name: str) -> ObjectProfile:
        """Typical colours, shape, size, material, transparency, storage place, texts and brand of a class."""
        return self._index.profiles[self._name(name, ("class",))]

    def hypothesis_type(self, name: str) -> str:
        """The CAS type instances of this object class are found as (ObjectHypothesis unless the class says)."""
        return self._index.hypothesis_types.get(self._name(name, ("class",)), "ObjectHypothesis")

    def default_location(self, name: str) -> str | None:
        """The region class objects of this class are typically kept in (inherited), or None."""
        return self.object_profile(name).stored_in

    def largest_extent(self, name: str) -> float | None:
        """The bound on the largest extent (metres) of objects of this class, from its size class's
        ``rk:largestExtentBelow`` (None when the class has no size class or its size class has no bound)."""
        size_class = self.object_profile(name).size_class
        if size_class is None:
            return None
        return self._index.size_bounds.get(size_class)

    def look_alikes(self, name: str) -> tuple[str, ...]:
        """The object classes that look like this one (same typical colours, shape and size class), itself
        included, sorted."""
        profile = self.object_profile(name)
        return self._index.look_alikes[(frozenset(profile.colors), profile.shape, profile.size_class)]

    def variants_differ_by_text(self, name: str) -> bool:
        """True when a sibling class looks the same and only printed text or brand tells them apart."""
        return self._name(name, ("class",)) in self._index.text_variants

    # ------------------------------------------------------------------ regions

    def regions(self) -> list[RegionBox]:
        """Every named region of the loaded semantic maps, sorted by name."""
        return [self._index.regions[name] for name in sorted(self._index.regions)]

    def region(self, name: str) -> RegionBox:
        """A named region (exact name, label or synonym)."""
        found = self._index.regions.get(name)
        return found if found is not None else self._index.regions[self.resolve(name, ("region",)).name]

    def regions_of_class(self, region_class: str) -> list[RegionBox]:
        """The named regions whose class is ``region_class`` or one of its subclasses."""
        return list(self._index.regions_by_class[self._name(region_class, ("region_class",))])

    # ------------------------------------------------------------------ perception vocabulary

    def cas_types(self) -> list[str]:
        """The names of all CAS types (views and annotation types) the ontology declares."""
        return sorted(self._index.cas_types)

    def annotation_type_for_key(self, key: str) -> str:
        """The CAS annotation type that answers a query key (``color`` -> ``SemanticColor``)."""
        found = self._index.query_keys.get(word_key(key))
        if found is None:
            keys = sorted(self._index.query_keys)
            raise UnknownTermError(key, "query key", close_keys(word_key(key), keys))
        return found

    def value_kind(self, annotation_type: str) -> Kind | None:
        """The kind of the values an annotation type carries (``SemanticColor`` -> ``color``), per its
        ``rk:valueDomain``; None for types without one (free text, poses, ...)."""
        return self._index.value_domains.get(annotation_type)

    def inspected_types(self) -> tuple[str, ...]:
        """The annotation types an inspect query of one object by id refines (their query keys are marked
        ``rk:refinedByInspection``), sorted."""
        return self._index.inspected_types

    def query_keys(self) -> dict[str, str]:
        """Every query key word (normalised) -> the annotation type that answers it."""
        return dict(self._index.query_keys)

    # ------------------------------------------------------------------ annotators

    def annotators(self) -> list[AnnotatorSpec]:
        """Every annotator the knowledge base was loaded with, sorted by name."""
        return [self._index.annotators[name] for name in sorted(self._index.annotators)]

    def annotator(self, name: str) -> AnnotatorSpec:
        """One annotator by its name (its class name)."""
        found = self._index.annotators.get(name)
        if found is None:
            close = difflib.get_close_matches(name, list(self._index.annotators), n=3, cutoff=0.6)
            raise UnknownTermError(name, "annotator", close)
        return found

    def inputs_of(self, name: str) -> tuple[str, ...]:
        """The required input CAS types of an annotator."""
        return self.annotator(name).inputs

    def providers(
        self,
        annotation_type: str,
        value: str | None = None,
        object_class: str | None = None,
        conditions: Conditions | None = None,
    ) -> list[AnnotatorSpec]:
        """Annotators that write ``annotation_type`` (or a subtype), best first (reliability, then cost).

        ``value`` (for types with a value domain: colour, shape, size, class) keeps the annotators whose
        declared domain holds the value, a subclass of it or a superclass of it (a detector that knows
        WhiteCeramicBowl serves a query for Bowl); an empty domain means any value. ``object_class`` keeps
        the annotators whose class domain (if any) is related to it the same way and drops those whose
        preconditions exclude it (not for transparent objects); an annotator with a class domain that writes only
        a subtype of ``annotation_type`` (a people detector's PersonHypothesis) is kept only for a query of one of
        its classes or a subclass (not for "all objects", whose segmenters must each provide the type itself).
        ``conditions`` says whether depth and a region are available (default: both) and whether a detector model
        is configured (default: not).
        """
        index = self._index
        if annotation_type not in index.cas_types:
            close = difflib.get_close_matches(annotation_type, list(index.cas_types), n=3, cutoff=0.6)
            raise UnknownTermError(annotation_type, "CAS type", close)
        candidates = index.providers.get(annotation_type, ())
        if value is not None:
            candidates = self.serving_value(annotation_type, value, candidates)
        object_up = object_down = None
        transparent = False
        if object_class is not None:
            object_name = self._name(object_class, ("class",))
            object_up, object_down = index.up[object_name], index.down[object_name]
            transparent = index.profiles[object_name].transparent is True
        conditions = conditions or _ALL_CONDITIONS
        transparent = transparent or conditions.transparent
        chosen: list[AnnotatorSpec] = []
        for spec in candidates:
            if (
                object_up is not None
                and object_down is not None
                and spec.classes
                and spec.classes.isdisjoint(object_up)
                and spec.classes.isdisjoint(object_down)
            ):
                continue
            if (
                spec.classes
                and annotation_type not in spec.outputs
                and (object_up is None or spec.classes.isdisjoint(object_up))
            ):
                continue  # a detector of particular classes writing their own subtype serves queries for them only
            needs = index.annotator_conditions[spec.name]
            if needs and (
                ("depth" in needs and not conditions.depth)
                or ("region" in needs and not conditions.region)
                or ("model" in needs and not conditions.model)
                or ("opaque" in needs and transparent)
            ):
                continue
            chosen.append(spec)
        return chosen

    def serving_value(
        self, annotation_type: str, value: str, candidates: Sequence[AnnotatorSpec]
    ) -> Sequence[AnnotatorSpec]:
        """Of ``candidates`` (providers of ``annotation_type``), those whose declared domain holds ``value``, a
        subclass of it or a superclass of it, or is empty (any value), in their order (:meth:`providers`)."""
        index = self._index
        value_kind = index.value_domains.get(annotation_type)
        if value_kind is None:
            return candidates
        value_name = self._name(value, (value_kind,))
        value_up, value_down = index.up[value_name], index.down[value_name]
        return [
            spec
            for spec in candidates
            if not (domain := spec.domain(value_kind))
            or not domain.isdisjoint(value_up)
            or not domain.isdisjoint(value_down)
        ]

    def provider_exclusions(
        self, object_class: str | None = None, conditions: Conditions | None = None
    ) -> tuple[frozenset[str], frozenset[str]]:
        """What :meth:`providers` leaves out whatever the type, for one object class and conditions, in one pass:
        the annotators it drops for every type (a class domain unrelated to ``object_class``, preconditions that do
        not hold), and those it keeps only for the types they write themselves, not for supertypes (a class domain
        that does not name ``object_class`` or a superclass of it). No value is asked."""
        index = self._index
        conditions = conditions or _ALL_CONDITIONS
        transparent = conditions.transparent
        object_up = object_down = None
        if object_class is not None:
            object_name = self._name(object_class, ("class",))
            object_up, object_down = index.up[object_name], index.down[object_name]
            transparent = transparent or index.profiles[object_name].transparent is True
        holds = {"depth": conditions.depth, "region": conditions.region, "model": conditions.model}
        holds["opaque"] = not transparent
        unmet = [key for key, held in holds.items() if not held]
        everywhere: set[str] = set().union(*(index.needing.get(key, ()) for key in unmet))
        # class-domain annotators naming no superclass (or the class itself) serve only their own types, and those
        # naming no subclass either serve none
        domains = index.class_annotators
        own_types = set(index.class_domain_names)
        if object_up is not None and object_down is not None:
            own_types.difference_update(*(domains.get(c, ()) for c in object_up))
            everywhere |= own_types.difference(*(domains.get(c, ()) for c in object_down))
        return frozenset(everywhere), frozenset(own_types - everywhere)
