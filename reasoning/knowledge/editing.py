"""Validated editing of the user ontology: add or remove object classes, change synonyms, import, undo, check.

Edits go to the user file layered over the shipped ontology, so upgrades never lose them. Every edit is a
transaction (:meth:`OntologyEditor._commit`): it holds the user file's exclusive lock, reads the file as it is now
(hand edits included), works out the triples to add and remove, edits the file *as text* (its own block appended
between ``# >>> robokudo edit N`` and ``# <<< robokudo edit N`` markers, removed statements cut out; comments, order
and everything else kept: :mod:`reasoning.knowledge.turtle_text`), validates the result completely (names, parents,
regions and values must exist; no name or word clash; the ontology must load; the reasoner must find no unsatisfiable
class), and replaces the file atomically, only if nobody changed it meanwhile (else the edit is redone on the new
content). A rejected edit raises :class:`~reasoning.errors.EditRejectedError` and leaves the file byte-identical.
Each edit is recorded in the history beside the file (:mod:`reasoning.knowledge.history`), which :meth:`undo`
reverts. After a successful edit the knowledge base is reloaded, so the new class can be used at once.

The reasoner check: a full HermiT run costs seconds (a fresh JVM), so the editor keeps the classification of every
state it proved coherent (:mod:`reasoning.knowledge.reasoner_cache`); new classes added to such a state are checked
incrementally against it (:mod:`reasoning.knowledge.fresh_classes`), and HermiT runs only when there is no stored
classification (the first edit, or after hand edits) or the change is outside what the incremental check decides.
:meth:`check` always runs HermiT on everything. Validation sees the ontology as the knowledge base does: the Turtle
files plus the triples of its annotator classes. The same editor serves the CLI, Python callers and a server.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from rdflib import BNode, Graph, Literal, URIRef
from rdflib.term import Node

from reasoning.errors import EditRejectedError, OntologyError, TermError
from reasoning.knowledge.exchange import map_to_namespace, outside_namespace, read_ontology
from reasoning.knowledge.folded_triples import (
    FoldedTriple,
    NotFoldableError,
    digest,
    fold,
    mentions,
    subjects,
)
from reasoning.knowledge.fresh_classes import Fragment, annotation_properties, check_fresh_classes, is_logical
from reasoning.knowledge.hermit import classify, describe_unsatisfiable
from reasoning.knowledge.history import UNDO, EditHistory, HistoryEntry, history_path
from reasoning.knowledge.index import OntologyIndex, build_index
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import KIND_WORDS, Kind
from reasoning.knowledge.reasoner_cache import (
    Classification,
    ReasonerCache,
    cache_path,
    sources_digest,
    state_key,
)
from reasoning.knowledge.sources import Stamp, file_stamp, parse_turtle
from reasoning.knowledge.turtle_text import TextEditError, edit_turtle
from reasoning.knowledge.user_layer import ChangedMeanwhileError, LockTimeoutError, Snapshot, UserLayerFile
from reasoning.knowledge.vocabulary import NAME_PATTERN, OWL, RDF, RDFS, SKOS, XSD, is_rk, local_name, rk
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

NEW_USER_FILE = """\
# RoboKudo user ontology: classes added by the user, layered over the shipped ontology.
# Edit it by hand, in Protégé or with `robokudo ontology`: the command appends its own blocks between
# "# >>> robokudo edit N" and "# <<< robokudo edit N" and removes only what an edit removes, keeping comments,
# order and everything else. History: `robokudo ontology log`; undo: `robokudo ontology undo`.
@prefix rk: <http://robokudo.org/ontology#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdf: <http://www.w3.org/1999/02/22-rdf-syntax-ns#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix skos: <http://www.w3.org/2004/02/skos/core#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .

<http://robokudo.org/ontology/user> a owl:Ontology ;
    rdfs:label "RoboKudo user ontology"@en .
"""
"""What a user file starts as."""

_OLD_HEADER = (
    "# RoboKudo user ontology: object classes and regions added by the user, layered over the shipped\n"
    "# ontology. Written by `robokudo ontology` (comments in this file are not kept).\n"
)
_NEW_HEADER = "".join(NEW_USER_FILE.splitlines(keepends=True)[:4])
_CLASS_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")
_ATTEMPTS = 5
_NO_AXIOMS = "loads cleanly (no axioms added, so the edit cannot make the ontology inconsistent)"


@dataclass(frozen=True)
class EditResult:
    """A successful edit: what was done, where it was written, how it was checked and its history number."""

    action: str
    name: str
    user_file: Path
    checked_by: str
    warnings: tuple[str, ...] = ()
    number: int = 0
    undone: tuple[HistoryEntry, ...] = ()


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


@dataclass(frozen=True)
class _Validated:
    """A validated edit: how it was checked, warnings, the ontology after it and, when proven coherent, the new
    state's classification."""

    checked_by: str
    warnings: tuple[str, ...]
    graphs: Mapping[Path, Graph]
    index: OntologyIndex
    classification: Classification | None = None


@dataclass(frozen=True)
class _Change:
    """What an edit does to the user file, worked out from its current content."""

    added: frozenset[FoldedTriple]
    removed: frozenset[FoldedTriple] = frozenset()
    name: str = ""
    undone: tuple[HistoryEntry, ...] = field(default=())


class OntologyEditor:
    """Edits the user file of a knowledge base: validated, locked, atomic, recorded and undoable."""

    def __init__(
        self,
        kb: KnowledgeBase | None = None,
        *,
        user_file: Path | None = None,
        use_reasoner: bool = True,
        lock_timeout: float = 60.0,
    ) -> None:
        if kb is not None and user_file is not None and Path(user_file) != kb.user_file:
            raise ValueError(f"user_file {user_file} differs from the knowledge base's {kb.user_file}")
        self.kb = kb if kb is not None else KnowledgeBase.load(user_file)  # without annotators unless ``kb`` has them
        self.use_reasoner = use_reasoner
        self.layer = UserLayerFile(self.kb.user_file, lock_timeout)
        self.history = EditHistory(history_path(self.kb.user_file))
        self.reasoner_cache = ReasonerCache(cache_path(self.kb.user_file))
        self._sources_digest: tuple[tuple[Stamp | None, ...], str] | None = None
        self._fixed_fragment: tuple[str, Fragment] | None = None

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

        def change(_: Graph) -> _Change:
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
            problems += _text_problems("label", [the_label]) + _text_problems("synonym", synonyms)
            problems += _text_problems("printed text", texts) + _text_problems("brand", [brand] if brand else [])
            problems += self._word_clashes(name, [the_label, *synonyms])
            if problems:
                raise EditRejectedError(problems)
            graph = Graph()
            subject = rk(name)
            graph.add((subject, RDF.type, OWL.Class))
            for parent in parents:
                graph.add((subject, RDFS.subClassOf, rk(str(parent))))
            for prop, value in (
                *(("typicalColor", c) for c in color_names),
                ("typicalShape", shape_name),
                ("sizeClass", size_name),
                ("madeOf", material_name),
                ("storedIn", region_name),
            ):
                if value:
                    _restrict(graph, subject, prop, OWL.someValuesFrom, rk(value))
            if transparent is not None:
                _restrict(graph, subject, "transparent", OWL.hasValue, Literal(transparent, datatype=XSD.boolean))
            for text in clean_texts:
                _restrict(graph, subject, "printedText", OWL.hasValue, Literal(text))
            if brand is not None:
                _restrict(graph, subject, "brand", OWL.hasValue, Literal(brand.strip()))
            graph.add((subject, RDFS.label, Literal(the_label, lang="en")))
            for synonym in synonyms:
                graph.add((subject, SKOS.altLabel, Literal(synonym.strip(), lang="en")))
            return _Change(fold(graph), name=name)

        return self._commit("add-object", change)

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

    def _word_clashes(self, name: str, words: Sequence[str], new: bool = True) -> list[str]:
        """Why new labels and synonyms of class ``name`` cannot be used (they name other terms); the name of a
        ``new`` class is checked as a word too."""
        problems = []
        words = list(words)
        if new and _CLASS_NAME.fullmatch(name) and word_key(name) not in {word_key(w) for w in words}:
            words.append(name)  # the name is a word too ("Beverage" would clash with the synonym "beverage")
        for word in words:
            if not word_key(word):
                problems.append(f"label or synonym {word!r} has no letters or digits")
                continue
            for found in self.kb.resolve_all(word):
                if found.name == name:
                    continue
                what = KIND_WORDS[found.kind]
                problems.append(f"the word {word!r} already names the {what} {found.name}; choose another label")
        return problems

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
        """Remove a class the user file declares (shipped classes cannot be removed)."""

        def change(current: Graph) -> _Change:
            subject = rk(name)
            if (subject, RDF.type, OWL.Class) not in current:
                where = self.kb.defined_in(name)
                if where is not None and where != self.user_file:
                    raise EditRejectedError(
                        [
                            f"{name} is defined in {where}, not in the user file {self.user_file}; only classes "
                            f"added by the user can be removed"
                        ]
                    )
                raise EditRejectedError([f"{name} is not a class of the user file {self.user_file}"])
            merged, _ = self.kb.combine(self.kb.source_graphs())
            users = _users(merged, [subject])
            if users:
                raise EditRejectedError([f"{name} is still used by: {', '.join(users)}; change those first"])
            return _Change(added=frozenset(), removed=_about(_fold(current, self.user_file), subject), name=name)

        return self._commit("remove-object", change)

    # ------------------------------------------------------------------ synonyms

    def change_synonyms(self, name: str, add: Sequence[str] = (), remove: Sequence[str] = ()) -> EditResult:
        """Add synonyms to a term (any class, region or value the ontology knows) and remove synonyms the user
        file gave it (a synonym from a shipped file cannot be removed)."""

        def change(current: Graph) -> _Change:
            try:
                term = self.kb.resolve(name).name
            except TermError as error:
                raise EditRejectedError([str(error)]) from None
            if not add and not remove:
                raise EditRejectedError(["give a synonym to add (--add) or to remove (--remove)"])
            subject = rk(term)
            problems = _text_problems("synonym", add)
            for word in add:
                if not word_key(word):
                    problems.append(f"synonym {word!r} has no letters or digits")
                    continue
                for found in self.kb.resolve_all(word):
                    if found.name == term:
                        problems.append(f"{term} is already called {word!r}")
                    else:
                        what = KIND_WORDS[found.kind]
                        problems.append(f"the word {word!r} already names the {what} {found.name}; choose another")
            removed: set[FoldedTriple] = set()
            for word in remove:
                key = word_key(word)
                own = [o for o in current.objects(subject, SKOS.altLabel) if word_key(str(o)) == key]
                if own:
                    removed |= {(subject, SKOS.altLabel, o) for o in own}
                elif word_key(word) in {word_key(s) for s in self.kb.synonyms(term)}:
                    problems.append(
                        f"the synonym {word!r} of {term} comes from {self.kb.defined_in(term) or 'a shipped file'}, "
                        f"not from the user file; only synonyms the user added can be removed"
                    )
                else:
                    problems.append(f"{term} has no synonym {word!r}")
            if problems:
                raise EditRejectedError(problems)
            added = frozenset((subject, SKOS.altLabel, Literal(w.strip(), lang="en")) for w in add)
            return _Change(added, frozenset(removed), name=term)

        return self._commit("synonym", change)

    # ------------------------------------------------------------------ import

    def import_file(
        self, path: Path, namespaces: Sequence[str] = (), names: Mapping[str, str] | None = None
    ) -> EditResult:
        """Bring the classes an ontology file (Turtle, RDF/XML or OWL/XML) describes into the user file: their
        parents, restrictions (colours, shapes, default locations, ...), labels and synonyms.

        IRIs outside the ``rk:`` namespace are refused unless mapped: ``namespaces`` maps every IRI starting with
        one of them to ``rk:`` + the rest, ``names`` maps single IRIs to rk names. What the ontology already says
        is skipped; the rest is validated like any edit."""
        source = read_ontology(Path(path))
        mapped = map_to_namespace(source, namespaces, names or {})

        def change(_: Graph) -> _Change:
            known_classes = self.kb.index.classes
            classes = sorted(
                {s for s in mapped.subjects(RDF.type, OWL.Class) if isinstance(s, URIRef)}
                | {s for s in mapped.subjects() if is_rk(s) and local_name(s) in known_classes}
            )
            try:
                described = fold(mapped)
            except NotFoldableError as error:
                raise EditRejectedError([f"{path}: {error}; the import reads blank-node trees only"]) from None
            wanted = frozenset(t for t in described if t[0] in classes)
            outside = outside_namespace(mentions(wanted))
            if outside:
                shown = ", ".join(f"<{iri}>" for iri in outside[:5]) + (" ..." if len(outside) > 5 else "")
                raise EditRejectedError(
                    [
                        f"{path}: {len(outside)} IRI(s) outside the rk: namespace ({shown}); map them with "
                        f"--map NAMESPACE (every IRI starting with it becomes rk:<the rest>) or --map IRI=NAME"
                    ]
                )
            if not classes:
                raise EditRejectedError([f"{path}: declares no class (owl:Class)"])
            merged, _ = self.kb.combine(self.kb.source_graphs())
            known = frozenset(t for t in _fold(_described(merged, classes), "the ontology") if t[0] in classes)
            added = wanted - known
            problems: list[str] = []
            index = self.kb.index
            for cls in classes:
                name = local_name(cls)
                if name not in index.classes:
                    if len(name) > MAX_NAME_LENGTH or NAME_PATTERN.fullmatch(name) is None:
                        problems.append(f"{name!r} is not a valid class name (letters, digits, underscores)")
                    elif name in index.names or word_key(name) in index.name_keys:
                        problems.append(f"{name} clashes with the existing term {index.name_keys[word_key(name)]}")
                words = [str(o) for s, p, o in added if s == cls and p in (RDFS.label, SKOS.altLabel)]
                problems += _text_problems(f"label or synonym of {name}", words)
                problems += self._word_clashes(name, words, new=name not in index.classes)
            if problems:
                raise EditRejectedError(sorted(set(problems)))
            if not added:
                raise EditRejectedError([f"{path}: the ontology already holds everything it says about its classes"])
            return _Change(added, name=f"{len(classes)} class(es) from {Path(path).name}")

        return self._commit("import", change)

    # ------------------------------------------------------------------ history

    def log(self) -> list[HistoryEntry]:
        """The history of the user file, oldest first."""
        return self.history.entries()

    def undo(self, count: int = 1) -> EditResult:
        """Revert the last ``count`` edits (undos excluded, each edit at most once), validated like any edit.

        Hand edits made since are kept; what an undone edit added and was removed by hand meanwhile stays removed.
        """
        if count < 1:
            raise EditRejectedError(["undo needs a number of edits of at least 1"])

        def change(current: Graph) -> _Change:
            entries = self.history.undoable(count)
            if len(entries) < count:
                have = f"only {len(entries)} edit(s) can" if entries else "no edit can"
                raise EditRejectedError([f"{have} be undone (see `robokudo ontology log`)"])
            now = _fold(current, self.user_file)
            state = now
            for entry in entries:
                state = (state - entry.added_triples) | entry.removed_triples
            return _Change(state - now, now - state, ", ".join(str(e.number) for e in entries), tuple(entries))

        return self._commit(UNDO, change)

    # ------------------------------------------------------------------ check

    def check(self, code: bool = True) -> CheckReport:
        """Check everything: the files load, HermiT finds no problem, and (``code``) the CAS types are the runtime's.

        A coherent result is stored, so later edits are checked incrementally against it."""
        problems: list[str] = []
        warnings: list[str] = []
        try:
            self.kb.reload()
        except OntologyError as error:
            return CheckReport(error.problems, (), "not run: the ontology does not load")
        index = self.kb.index
        reasoner = "not run"
        if self.use_reasoner:
            data = self.layer.read().data
            result = classify(self.kb.combine(self.kb.source_graphs())[0])
            reasoner = result.message
            if not result.available:
                warnings.append(result.message)
                problems += _asserted_conflicts(index, index.classes)
            elif not result.ok:
                problems += describe_unsatisfiable(index, result)
            elif result.inferred is not None and self.layer.read().data == data:
                inferred = result.inferred
                self.reasoner_cache.put(Classification(self._key(data), inferred.parents, inferred.ancestors, "HermiT"))
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

    # ------------------------------------------------------------------ the transaction

    def _commit(self, action: str, make_change: Callable[[Graph], _Change]) -> EditResult:
        """Lock, read, change, validate, replace, record; redone when the file changed meanwhile."""
        for _ in range(_ATTEMPTS):
            try:
                with self.layer.locked():
                    snapshot = self.layer.read()
                    current = self._adopt(snapshot)
                    before = self.kb.source_graphs()
                    change = make_change(current)
                    number = self.history.next_number()
                    text = _upgrade_header(snapshot.text) if snapshot.exists else NEW_USER_FILE
                    heading = f"{action} {change.name}".strip()
                    try:
                        edited = edit_turtle(
                            text, self.user_file.as_uri(), change.removed, change.added, heading, number
                        )
                    except TextEditError as error:
                        raise EditRejectedError([f"{self.user_file}: {error}; edit the file by hand"]) from None
                    data = edited.encode("utf-8")
                    edited_graph = parse_turtle(self.user_file, data)
                    validated = self._validate(before, edited_graph, change, snapshot.data, data)
                    self.layer.replace(snapshot, data)
                    undoes = [e.number for e in change.undone]
                    self.history.append(
                        number, action, change.name, change.added, change.removed, validated.checked_by, undoes
                    )
                    if validated.classification is not None:
                        self.reasoner_cache.put(validated.classification)
                    written = self.layer.read()
                    adopted = False
                    if written.stamp is not None and written.data == data:
                        self.kb.adopt_parsed(self.user_file, written.stamp, edited_graph)
                        adopted = self.kb.adopt_index(validated.graphs, validated.index)
            except ChangedMeanwhileError:
                continue
            except LockTimeoutError as error:
                raise EditRejectedError([str(error)]) from None
            if not adopted:
                self.kb.reload()
            return EditResult(
                action, change.name, self.user_file, validated.checked_by, validated.warnings, number, change.undone
            )
        raise EditRejectedError([f"{self.user_file} kept changing while the edit was validated; try again"])

    def _adopt(self, snapshot: Snapshot) -> Graph:
        """Bring the knowledge base to the user file as read (parsed once); the user graph (empty if none)."""
        graph = Graph()
        if snapshot.exists and snapshot.stamp is not None:
            try:
                graph = parse_turtle(self.user_file, snapshot.data)
            except OntologyError as error:
                raise EditRejectedError([*error.problems, "fix the user file first"]) from None
            self.kb.adopt_parsed(self.user_file, snapshot.stamp, graph)
        try:
            self.kb.reload_if_changed()
        except OntologyError as error:
            raise EditRejectedError(
                [*error.problems, f"the ontology does not load as it is; fix {self.user_file} first"]
            ) from None
        return graph

    def _key(self, user_file_bytes: bytes) -> str:
        """The reasoner cache key of the sources as they are with this user file content."""
        files = self.kb.sources.files
        stamps = tuple(file_stamp(path) for path in files)
        if self._sources_digest is None or self._sources_digest[0] != stamps:
            annotators = digest(fold(self.kb.annotator_graph))
            self._sources_digest = (stamps, sources_digest(files, annotators))
        return state_key(self._sources_digest[1], user_file_bytes)

    def _validate(
        self, before: Mapping[Path, Graph], edited: Graph, change: _Change, old_data: bytes, new_data: bytes
    ) -> _Validated:
        """Load and reason over the ontology as it would be after the edit; EditRejectedError when it fails."""
        candidate = {**{p: g for p, g in before.items() if p != self.user_file}, self.user_file: edited}
        try:
            merged, defined = self.kb.combine(candidate)
        except OntologyError as error:
            raise EditRejectedError(error.problems) from None
        gone = [
            s
            for s, p, o in change.removed
            if p == RDF.type and o == OWL.Class and (s, RDF.type, OWL.Class) not in merged
        ]
        problems = [
            f"{local_name(s)} is still used by: {', '.join(users)}" for s in gone if (users := _users(merged, [s]))
        ]
        if problems:
            raise EditRejectedError(problems)
        try:
            index = build_index(merged, defined)
        except OntologyError as error:
            raise EditRejectedError(error.problems) from None
        annotations = annotation_properties(merged)
        logical_added = [t for t in change.added if is_logical(t, annotations)]
        logical_removed = [t for t in change.removed if is_logical(t, annotations)]
        new_classes = sorted(local_name(s) for s in subjects(change.added) if (s, RDF.type, OWL.Class) in edited)
        cached = self.reasoner_cache.get(self._key(old_data)) if self.use_reasoner else None
        if not logical_added:
            classification = None
            if cached is not None and all(_is_description_of(t, gone) for t in logical_removed):
                names = [local_name(s) for s in gone]
                classification = cached.without(self._key(new_data), names, "removal from a coherent state")
            return _Validated(_NO_AXIOMS, (), candidate, index, classification)
        if not self.use_reasoner:
            conflicts = _asserted_conflicts(index, new_classes)
            if conflicts:
                raise EditRejectedError(conflicts)
            return _Validated("asserted checks (reasoner not asked for)", (), candidate, index)
        if cached is not None and not logical_removed:
            fresh = check_fresh_classes(self._fragment(before, annotations), cached, change.added, annotations)
            if fresh.supported:
                if fresh.problems:
                    raise EditRejectedError(list(fresh.problems))
                how = f"incremental check of {', '.join(new_classes)} against the stored HermiT classification"
                classification = cached.extended(self._key(new_data), fresh.parents, fresh.ancestors, how)
                return _Validated(f"{how}: consistent", (), candidate, index, classification)
        result = classify(merged)
        if not result.available:
            conflicts = _asserted_conflicts(index, new_classes)
            if conflicts:
                raise EditRejectedError(conflicts)
            return _Validated("asserted checks", (result.message,), candidate, index)
        if not result.ok:
            raise EditRejectedError(describe_unsatisfiable(index, result))
        assert result.inferred is not None
        inferred = result.inferred
        classification = Classification(self._key(new_data), inferred.parents, inferred.ancestors, "HermiT")
        return _Validated(result.message, (), candidate, index, classification)

    def _fragment(self, before: Mapping[Path, Graph], annotations: frozenset[URIRef]) -> Fragment:
        """The fragment of the ontology before the edit; the read-only sources' part is read once."""
        key = self._key(b"")
        if self._fixed_fragment is None or self._fixed_fragment[0] != key:
            fixed = [g for p, g in before.items() if p != self.user_file] + [self.kb.annotator_graph]
            self._fixed_fragment = (key, Fragment.of(fixed, annotation_properties(*fixed)))
        user = [g for p, g in before.items() if p == self.user_file]
        return self._fixed_fragment[1].plus(Fragment.of(user, annotations))


def _is_description_of(triple: FoldedTriple, classes: Sequence[URIRef]) -> bool:
    """True for ``X a owl:Class`` and ``X rdfs:subClassOf C`` with X one of ``classes``: axioms whose removal, when
    nothing else mentions X, leaves every other class where it was."""
    subject, predicate, obj = triple
    return subject in classes and (predicate == RDFS.subClassOf or (predicate == RDF.type and obj == OWL.Class))


def _upgrade_header(text: str) -> str:
    """A user file written before edits kept comments says they are not kept; say what is true now."""
    return _NEW_HEADER + text[len(_OLD_HEADER) :] if text.startswith(_OLD_HEADER) else text


def _fold(graph: Graph, where: object) -> frozenset[FoldedTriple]:
    try:
        return fold(graph)
    except NotFoldableError as error:
        raise EditRejectedError([f"{where}: {error}; edit it by hand"]) from None


def _about(triples: frozenset[FoldedTriple], subject: URIRef) -> frozenset[FoldedTriple]:
    return frozenset(t for t in triples if t[0] == subject)


def _described(graph: Graph, subjects_: Sequence[URIRef]) -> Graph:
    """The triples about ``subjects_`` with their blank-node trees."""
    found = Graph()
    queue: list[Node] = list(subjects_)
    seen: set[Node] = set()
    while queue:
        node = queue.pop()
        if node in seen:
            continue
        seen.add(node)
        for predicate, obj in graph.predicate_objects(node):
            found.add((node, predicate, obj))
            if isinstance(obj, BNode):
                queue.append(obj)
    return found


def _users(merged: Graph, names: Sequence[URIRef]) -> list[str]:
    """The terms (other than the named ones) whose descriptions mention any of ``names``, with the property."""
    users = set()
    for subject in names:
        for referrer, prop in merged.subject_predicates(subject):
            owner = _owner(merged, referrer)
            if owner not in {local_name(n) for n in names}:
                users.add(f"{owner} ({merged.namespace_manager.normalizeUri(prop)})")
    return sorted(users)


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


def _restrict(graph: Graph, subject: URIRef, prop: str, kind: URIRef, value: Node) -> None:
    restriction = BNode()
    graph.add((subject, RDFS.subClassOf, restriction))
    graph.add((restriction, RDF.type, OWL.Restriction))
    graph.add((restriction, OWL.onProperty, rk(prop)))
    graph.add((restriction, kind, value))


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
