"""Validated editing of the user ontology: add or remove object classes, check the whole ontology.

Edits go to the user file layered over the shipped ontology, so upgrades never lose them. Every edit is
validated completely before anything is written (names, parents, regions and values must exist; no name or
word clash; the result must load and HermiT must find no unsatisfiable class), and the write is atomic
(temporary file + rename). A rejected edit raises :class:`~reasoning.errors.EditRejectedError` and leaves
the file byte-identical. After a successful edit the knowledge base is reloaded, so the new class can be
used at once. The editor rewrites the user file with rdflib, so comments in it are not kept. Validation sees the
ontology as the knowledge base does: the Turtle files plus the triples of its annotator classes.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.term import Node

from reasoning.errors import EditRejectedError, OntologyError, TermError
from reasoning.knowledge.atomic_write import write_atomically
from reasoning.knowledge.hermit import classify, describe_unsatisfiable
from reasoning.knowledge.index import OntologyIndex, build_index
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import KIND_WORDS, Kind
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, RK, SKOS, XSD, is_rk, local_name, rk
from reasoning.knowledge.words import (
    MAX_LABEL_LENGTH,
    MAX_NAME_LENGTH,
    camel_case,
    camel_words,
    control_characters,
    word_key,
)
from robokudo.core.types import ANNOTATION_TYPES, VIEW_TYPES

USER_ONTOLOGY_IRI = URIRef("http://robokudo.org/ontology/user")
"""The ontology IRI of the user file."""

_CLASS_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")
_HEADER = (
    b"# RoboKudo user ontology: object classes and regions added by the user, layered over the shipped\n"
    b"# ontology. Written by `robokudo ontology` (comments in this file are not kept).\n\n"
)


@dataclass(frozen=True)
class EditResult:
    """A successful edit: what was done, where it was written and how it was checked."""

    action: str
    name: str
    user_file: Path
    checked_by: str
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class CheckReport:
    """The result of checking the whole ontology; ``ok`` when there are no problems."""

    problems: tuple[str, ...]
    warnings: tuple[str, ...]
    reasoner: str

    @property
    def ok(self) -> bool:
        """True when nothing is wrong."""
        return not self.problems


class OntologyEditor:
    """Adds and removes user object classes in the user file of a knowledge base, validated and atomic."""

    def __init__(
        self,
        kb: KnowledgeBase | None = None,
        *,
        user_file: Path | None = None,
        use_reasoner: bool = True,
    ) -> None:
        if kb is not None and user_file is not None and Path(user_file) != kb.user_file:
            raise ValueError(f"user_file {user_file} differs from the knowledge base's {kb.user_file}")
        self.kb = kb if kb is not None else KnowledgeBase.load(user_file)  # without annotators unless ``kb`` has them
        self.use_reasoner = use_reasoner

    @property
    def user_file(self) -> Path:
        """The file edits are written to."""
        return self.kb.user_file

    # ------------------------------------------------------------------ add

    def add_object(
        self,
        name: str,
        is_a: Sequence[str],
        *,
        colors: Sequence[str] = (),
        shape: str | None = None,
        size: str | None = None,
        material: str | None = None,
        transparent: bool | None = None,
        stored_in: str | None = None,
        texts: Sequence[str] = (),
        brand: str | None = None,
        label: str | None = None,
        synonyms: Sequence[str] = (),
    ) -> EditResult:
        """Add object class ``name`` under the classes ``is_a`` with its typical properties.

        Parents, colours, shape, size, material and the storage region (a region class) may be given as
        names or words ("milk", "fridge"). Raises EditRejectedError (nothing written) when anything is wrong.
        """
        self.kb.reload_if_changed()
        index = self.kb.index
        problems: list[str] = []
        self._check_new_name(name, index, problems)
        if not is_a:
            problems.append("give at least one parent class (--is-a)")
        parents = [self._term(p, ("class",), "parent class", problems) for p in is_a]
        color_names = [self._term(c, ("color",), "colour", problems) for c in colors]
        shape_name = self._term(shape, ("shape",), "shape", problems) if shape else None
        size_name = self._term(size, ("size",), "size class", problems) if size else None
        material_name = self._term(material, ("material",), "material", problems) if material else None
        region_name = self._term(stored_in, ("region_class",), "region class", problems) if stored_in else None
        clean_texts = [t.strip().lower() for t in texts]
        if any(not t for t in clean_texts):
            problems.append("printed text must not be empty")
        if brand is not None and not brand.strip():
            problems.append("brand must not be empty")
        the_label = (label or camel_words(name)).strip()
        words = [the_label, *synonyms]
        problems += _text_problems("label", [the_label]) + _text_problems("synonym", synonyms)
        problems += _text_problems("printed text", texts) + _text_problems("brand", [brand] if brand else [])
        if _CLASS_NAME.fullmatch(name) and word_key(name) not in {word_key(w) for w in words}:
            words.append(name)  # the name is a word too ("Beverage" would clash with the synonym "beverage")
        for word in words:
            if not word_key(word):
                problems.append(f"label or synonym {word!r} has no letters or digits")
                continue
            for found in self.kb.resolve_all(word):
                what = KIND_WORDS[found.kind]
                problems.append(f"the word {word!r} already names the {what} {found.name}; choose another label")
        if problems:
            raise EditRejectedError(problems)

        graphs = self.kb.source_graphs()
        user_graph = _copy(graphs.get(self.user_file))
        subject = rk(name)
        user_graph.add((subject, RDF.type, OWL.Class))
        for parent in parents:
            user_graph.add((subject, RDFS.subClassOf, rk(str(parent))))
        for prop, value in (
            *(("typicalColor", c) for c in color_names),
            ("typicalShape", shape_name),
            ("sizeClass", size_name),
            ("madeOf", material_name),
            ("storedIn", region_name),
        ):
            if value:
                _restrict(user_graph, subject, prop, OWL.someValuesFrom, rk(value))
        if transparent is not None:
            _restrict(user_graph, subject, "transparent", OWL.hasValue, Literal(transparent, datatype=XSD.boolean))
        for text in clean_texts:
            _restrict(user_graph, subject, "printedText", OWL.hasValue, Literal(text))
        if brand is not None:
            _restrict(user_graph, subject, "brand", OWL.hasValue, Literal(brand.strip()))
        user_graph.add((subject, RDFS.label, Literal(the_label, lang="en")))
        for synonym in synonyms:
            user_graph.add((subject, SKOS.altLabel, Literal(synonym.strip(), lang="en")))

        checked_by, warnings = self._validate(graphs, user_graph, name)
        self._write(user_graph)
        return EditResult("add-object", name, self.user_file, checked_by, warnings)

    def _check_new_name(self, name: str, index: OntologyIndex, problems: list[str]) -> None:
        if len(name) > MAX_NAME_LENGTH:
            problems.append(f"the class name is {len(name)} characters long; at most {MAX_NAME_LENGTH} are allowed")
            return
        if _CLASS_NAME.fullmatch(name) is None:
            suggestion = camel_case(name)
            hint = f", e.g. {suggestion!r}" if suggestion and _CLASS_NAME.fullmatch(suggestion) else ""
            problems.append(f"{name!r} is not a valid class name: use CamelCase letters and digits{hint}")
            return
        existing = name if name in index.names else index.name_keys.get(word_key(name))
        if existing is not None:
            where = index.defined_in.get(existing)
            problems.append(
                f"{name} clashes with the existing term {existing}" + (f" (defined in {where.name})" if where else "")
            )

    def _term(self, word: str, kinds: tuple[Kind, ...], what: str, problems: list[str]) -> str:
        try:
            return self.kb.resolve(word, kinds).name if self.kb.index.kinds.get(word) not in kinds else word
        except TermError as error:
            hint = ""
            if "region_class" in kinds:
                regions = [r.name for r in self.kb.resolve_all(word) if r.kind == "region"]
                if regions:
                    hint = f" ({regions[0]} is a region of class {self.kb.region(regions[0]).region_class})"
            problems.append(f"{what}: {error}{hint}")
            return ""

    # ------------------------------------------------------------------ remove

    def remove_object(self, name: str) -> EditResult:
        """Remove an object class the user added (shipped classes cannot be removed)."""
        self.kb.reload_if_changed()
        graphs = self.kb.source_graphs()
        current = graphs.get(self.user_file)
        subject = rk(name)
        if current is None or (subject, RDF.type, OWL.Class) not in current:
            where = self.kb.defined_in(name)
            if where is not None:
                raise EditRejectedError(
                    [
                        f"{name} is defined in {where}, not in the user file {self.user_file}; only classes added by "
                        f"the user can be removed"
                    ]
                )
            raise EditRejectedError([f"{name} is not a class of the user file {self.user_file}"])
        merged, _ = self.kb.combine(graphs)
        users = set()
        for referrer, prop in merged.subject_predicates(subject):
            owner = _owner(merged, referrer)
            if owner != name:
                users.add(f"{owner} ({merged.namespace_manager.normalizeUri(prop)})")
        if users:
            raise EditRejectedError([f"{name} is still used by: {', '.join(sorted(users))}; change those first"])
        user_graph = _copy(current)
        for node in _closure(current, subject):
            user_graph.remove((node, None, None))
        checked_by, warnings = self._validate(graphs, user_graph, None)
        self._write(user_graph)
        return EditResult("remove-object", name, self.user_file, checked_by, warnings)

    # ------------------------------------------------------------------ check

    def check(self, code: bool = True) -> CheckReport:
        """Check everything: the files load, HermiT finds no problem, and (``code``) the CAS types are the runtime's."""
        problems: list[str] = []
        warnings: list[str] = []
        try:
            self.kb.reload()
        except OntologyError as error:
            return CheckReport(error.problems, (), "not run: the ontology does not load")
        index = self.kb.index
        reasoner = "not run"
        if self.use_reasoner:
            result = classify(self.kb.combine(self.kb.source_graphs())[0])
            reasoner = result.message
            if not result.available:
                warnings.append(result.message)
                problems += _asserted_conflicts(index, index.classes)
            elif not result.ok:
                problems += describe_unsatisfiable(index, result)
        else:
            problems += _asserted_conflicts(index, index.classes)
        for key, found in sorted(index.words.items()):
            for kind in {r.kind for r in found}:
                same = [r.name for r in found if r.kind == kind]
                if len(same) > 1:
                    word = index.word_labels[key]
                    warnings.append(f"the word {word!r} names several {kind} terms: {', '.join(same)}")
        if code:
            problems += check_cas_types(self.kb)
        return CheckReport(tuple(problems), tuple(warnings), reasoner)

    # ------------------------------------------------------------------ validation and writing

    def _validate(self, graphs: dict[Path, Graph], user_graph: Graph, name: str | None) -> tuple[str, tuple[str, ...]]:
        """Load and reason over the ontology as it would be after the edit; EditRejectedError when it fails."""
        candidate = {**{p: g for p, g in graphs.items() if p != self.user_file}, self.user_file: user_graph}
        try:
            merged, defined = self.kb.combine(candidate)
            index = build_index(merged, defined)
        except OntologyError as error:
            raise EditRejectedError(error.problems) from None
        if name is None:
            return "loads cleanly (a removal adds no axioms, so it cannot make the ontology inconsistent)", ()
        if not self.use_reasoner:
            conflicts = _asserted_conflicts(index, [name])
            if conflicts:
                raise EditRejectedError(conflicts)
            return "asserted checks (reasoner not asked for)", ()
        result = classify(merged)
        if not result.available:
            conflicts = _asserted_conflicts(index, [name])
            if conflicts:
                raise EditRejectedError(conflicts)
            return "asserted checks", (result.message,)
        if not result.ok:
            raise EditRejectedError(describe_unsatisfiable(index, result))
        return result.message, ()

    def _write(self, user_graph: Graph) -> None:
        user_graph.bind("rk", RK)
        user_graph.bind("owl", OWL)
        user_graph.bind("skos", SKOS)
        data = _HEADER + user_graph.serialize(format="turtle").encode("utf-8")
        write_atomically(self.user_file, data)
        self.kb.reload()


def _text_problems(what: str, values: Sequence[str]) -> list[str]:
    """Why labels, synonyms or texts cannot be written: too long, or with control characters (one line each)."""
    problems = []
    for value in values:
        shown = value if len(value) <= 40 else value[:40] + "..."
        if len(value) > MAX_LABEL_LENGTH:
            problems.append(f"{what} {shown!r} is {len(value)} characters long; at most {MAX_LABEL_LENGTH} are allowed")
        breaking = control_characters(value)
        if breaking:
            listed = ", ".join(breaking)
            problems.append(f"{what} {shown!r} contains control characters ({listed}); write it on one line")
    return problems


def check_cas_types(kb: KnowledgeBase) -> list[str]:
    """How the ontology's CAS types differ from the runtime's (robokudo.core.types); empty when they agree."""
    problems = []
    for root, runtime in (("View", VIEW_TYPES), ("Annotation", ANNOTATION_TYPES)):
        in_code = {t.__name__ for t in runtime}
        in_ontology = set(kb.subclasses(root))
        for name in sorted(in_code - in_ontology):
            problems.append(f"runtime {root.lower()} type {name} is not a subclass of rk:{root} in the ontology")
        for name in sorted(in_ontology - in_code):
            problems.append(f"ontology {root.lower()} type {name} has no runtime class in robokudo.core.types")
    return problems


def _copy(graph: Graph | None) -> Graph:
    """A copy of the user graph, or a new one with the user ontology header."""
    copy = Graph()
    if graph is None:
        copy.add((USER_ONTOLOGY_IRI, RDF.type, OWL.Ontology))
        copy.add((USER_ONTOLOGY_IRI, RDFS.label, Literal("RoboKudo user ontology", lang="en")))
        return copy
    for prefix, namespace in graph.namespaces():
        copy.bind(prefix, namespace)
    copy += graph
    return copy


def _restrict(graph: Graph, subject: URIRef, prop: str, kind: URIRef, value: Node) -> None:
    restriction = BNode()
    graph.add((subject, RDFS.subClassOf, restriction))
    graph.add((restriction, RDF.type, OWL.Restriction))
    graph.add((restriction, OWL.onProperty, rk(prop)))
    graph.add((restriction, kind, value))


def _closure(graph: Graph, subject: Node) -> list[Node]:
    """``subject`` and every blank node reachable from it (its restrictions and lists)."""
    found = [subject]
    seen = {subject}
    for node in found:
        for value in graph.objects(node, None):
            if isinstance(value, BNode) and value not in seen:
                seen.add(value)
                found.append(value)
    return found


def _owner(graph: Graph, node: Node) -> str:
    """The named term a node belongs to (a blank node belongs to the class whose restriction it is)."""
    seen: set[Node] = set()
    while isinstance(node, BNode) and node not in seen:
        seen.add(node)
        referrers = list(graph.subjects(None, node))
        if not referrers:
            break
        node = referrers[0]
    return local_name(node) if is_rk(node) else "an anonymous axiom"


def _asserted_conflicts(index: OntologyIndex, names: Sequence[str] | frozenset[str]) -> list[str]:
    """Classes under two declared-disjoint classes (the check used when HermiT cannot run)."""
    problems = []
    for name in sorted(names):
        conflicts = index.disjoint_conflicts(name)
        if conflicts:
            pairs = "; ".join(f"{a} and {b}, which are disjoint" for a, b in conflicts)
            problems.append(f"{name} can have no instances: it is under {pairs}")
    return problems
