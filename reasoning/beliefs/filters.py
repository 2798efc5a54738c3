"""From a parsed query and the knowledge base to a :class:`~reasoning.beliefs.store.BeliefFilter`.

The object description is the query's body or its ``obj`` block (the natural front end nests it there). Words
are resolved with the knowledge base (any :class:`Vocabulary`, e.g. the KnowledgeBase); a word it does not
know is used as it is, so memory can still be searched by name, unless the filter is ``strict``: then the
knowledge base's LookupError (e.g. ``unknown object class 'unicorn'``) is raised, as planning the query would.
An ``id`` (``inspect object 3``, ``inspect {obj: {id: 3}}``) selects that stored belief. A ``select`` (``the top
box``) is kept in the filter for the answer to apply.
A list of words under an attribute key (``color: [red, blue]``, from ``red or blue cup`` or a robot's designator)
selects objects with any of those values: an object has one dominant colour, shape and size, so "all of them"
would match nothing, and RoboKudo's designator lists mean alternatives too. A colour no expert reports is asked
as the basic colours a person names it by (``teal``: blue or green; ``KnowledgeBase.reported_as``).

The class test of the filter is :func:`kb_query_class_test`: an object answers a query for a class it is, or for the
container it is typically packaged in (``rk:packagedIn``: a mustard for "find all bottles").

Which key filters which attribute comes from the ontology (the annotation type answering the key, its value
kind) and the annotation type's ``attribute`` (:mod:`robokudo.core.types`); without a knowledge base a key
filters the attribute of the same name.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import replace
from typing import Protocol

from queries import ANYWHERE, Block, ListValue, Number, Query, String, Symbol, Value
from queries.model import text_switch
from queries.selection import SELECT_KEY, selection_request
from reasoning.beliefs.store import BeliefFilter
from reasoning.knowledge.model import Resolved
from robokudo.core.regions import RegionBox
from robokudo.core.types import ATTRIBUTE_TYPES, Annotation, Classification, Location

CLASS_KEYS = ("type", "class", "object")
REGION_KEYS = ("location", "region")
REGION_RELATIONS = ("in", "on", "at", "inside", "within")
ID_KEY = "id"
"""The key naming one stored belief by its id."""
FILTERED_TYPES: tuple[type[Annotation], ...] = tuple(t for t in ATTRIBUTE_TYPES if t not in (Classification, Location))
"""The annotation types whose attribute a query key filters on (class and region have their own keys above)."""


class Vocabulary(Protocol):
    """What the filter asks the knowledge base; each method raises LookupError for a word it does not know."""

    def resolve(self, word: str, kinds: Collection[str] | None = None) -> Resolved: ...

    def is_subclass(self, name: str, ancestor: str) -> bool: ...

    def answers_to(self, name: str, asked: str) -> bool: ...

    def annotation_type_for_key(self, key: str) -> str: ...

    def value_kind(self, annotation_type: str) -> str | None: ...

    def reported_as(self, annotation_type: str, value: str) -> tuple[str, ...]: ...

    def region(self, name: str) -> RegionBox: ...

    def regions_of_class(self, region_class: str) -> Sequence[RegionBox]: ...


def belief_filter(
    query: Query, kb: Vocabulary | None = None, *, include_gone: bool = False, strict: bool = False
) -> BeliefFilter:
    """The filter selecting the known objects that answer ``query`` (class subsumption and regions via ``kb``).

    With ``strict`` (and a ``kb``), a class, value or region word the knowledge base does not know raises its
    LookupError instead of being searched by name.
    """
    blocks = [b for b in (_body(query), _block(_get(_body(query), "obj"))) if b is not None]
    object_class = _first_word(blocks, CLASS_KEYS)
    region_word = _region_word(blocks)
    if region_word is not None and region_word.strip().lower() == ANYWHERE:  # ``location: anywhere``: no region
        region_word = None
    attributes = _attributes(blocks, kb, strict)
    class_test = kb_query_class_test(kb)
    if object_class is not None:
        object_class = _resolve(kb, object_class, "class", strict)
    region, boxes = (None, ()) if region_word is None else _resolve_region(kb, region_word, strict)
    limit = _number(blocks, "max_results")
    min_confidence = _number(blocks, "confidence")  # ``confidence: 0.75``: the least belief confidence answered
    object_id = _number(blocks, ID_KEY)
    return BeliefFilter(
        object_class=object_class,
        class_test=class_test,
        region=region,
        region_boxes=boxes,
        attributes=attributes,
        include_gone=include_gone,
        min_confidence=0.0 if min_confidence is None else min_confidence,
        limit=None if limit is None else int(limit),
        ids=None if object_id is None else (int(object_id),),
        selection=selection_request(query.body.get(SELECT_KEY)),
    )


def _body(query: Query) -> Block:
    return query.body


def _get(block: Block | None, key: str) -> Value | None:
    return block.get(key) if block is not None else None


def _block(value: Value | None) -> Block | None:
    return value if isinstance(value, Block) else None


def _word(value: Value | None) -> str | None:
    """The text of a symbol or string value (None for numbers, lists, blocks, ``?``)."""
    if isinstance(value, Symbol):
        return value.name or None
    if isinstance(value, String):
        return value.text or None
    return None


def _first_word(blocks: list[Block], keys: tuple[str, ...]) -> str | None:
    for block in blocks:
        for key in keys:
            word = _word(_get(block, key))
            if word is not None:
                return word
    return None


def _number(blocks: list[Block], key: str) -> float | None:
    for block in blocks:
        value = _get(block, key)
        if isinstance(value, Number):
            return float(value.value)
    return None


def _attributes(blocks: list[Block], kb: Vocabulary | None, strict: bool) -> dict[str, str | tuple[str, ...]]:
    """Attribute name -> the value asked for (a tuple: any of several), resolved to the knowledge base's name when
    it has a value kind."""
    words: dict[type[Annotation], tuple[str, ...]] = {}
    for block in blocks:
        for field in block.fields:
            annotation_type = _answering_type(kb, field.key)
            if (
                annotation_type is not None
                and annotation_type.attribute == "text"
                and text_switch(field.value) is not None
            ):
                continue  # ``text: false`` / ``text: true`` says whether to read text, not a text to look for
            asked = _words(field.value)
            if annotation_type is not None and asked:
                words.setdefault(annotation_type, asked)
    found: dict[str, str | tuple[str, ...]] = {}
    for annotation_type in FILTERED_TYPES:
        asked = words.get(annotation_type)
        if asked is not None:
            kind = None if kb is None else kb.value_kind(annotation_type.type_name())
            names = tuple(
                dict.fromkeys(
                    reported
                    for word in asked
                    for reported in (
                        (word,) if kind is None else _reported(kb, annotation_type, _resolve(kb, word, kind, strict))
                    )
                )
            )
            found[annotation_type.attribute] = names[0] if len(names) == 1 else names
    return found


def _words(value: Value | None) -> tuple[str, ...]:
    """The words of a symbol or string value, or of a list of them; () for anything else."""
    if isinstance(value, ListValue):
        words = [_word(item) for item in value.items]
        return tuple(w for w in words if w is not None) if None not in words else ()
    word = _word(value)
    return () if word is None else (word,)


def _answering_type(kb: Vocabulary | None, key: str) -> type[Annotation] | None:
    """The filtered annotation type answering ``key``: per the ontology, else the type whose attribute it names."""
    if kb is None:
        return next((t for t in FILTERED_TYPES if t.attribute == key), None)
    try:
        name = kb.annotation_type_for_key(key)
    except LookupError:
        return None
    return next((t for t in FILTERED_TYPES if t.type_name() == name), None)


def _region_word(blocks: list[Block]) -> str | None:
    for block in blocks:
        for key in REGION_KEYS:
            value = _get(block, key)
            word = _word(value)
            if word is not None:
                return word
            nested = _block(value)
            if nested is not None:
                for relation in REGION_RELATIONS:
                    word = _word(_get(nested, relation))
                    if word is not None:
                        return word
    return None


def _reported(kb: Vocabulary | None, annotation_type: type[Annotation], name: str) -> tuple[str, ...]:
    """The values experts report for an asked value: a colour no expert says is matched by the basic colours a
    person names it by (teal: blue or green), any other value by itself."""
    if kb is None:
        return (name,)
    try:
        return kb.reported_as(annotation_type.type_name(), name)
    except LookupError:
        return (name,)


def _resolve(kb: Vocabulary | None, word: str, kind: str, strict: bool = False) -> str:
    """The knowledge base's name for ``word`` as a term of ``kind``, else ``word`` (LookupError when ``strict``)."""
    if kb is None:
        return word
    if strict:
        return kb.resolve(word, (kind,)).name
    try:
        return kb.resolve(word, (kind,)).name
    except LookupError:
        return word


def _resolve_region(kb: Vocabulary | None, word: str, strict: bool) -> tuple[str, tuple[RegionBox, ...]]:
    if kb is None:
        return word, ()
    if strict:
        kb.resolve(word, ("region", "region_class"))  # raises for a word naming no region
    candidates = [word, _resolve(kb, word, "region_class")]
    for name in candidates:
        try:
            box = kb.region(name)
        except LookupError:
            continue
        return str(box.name), (box,)
    for name in candidates:
        try:
            boxes = tuple(kb.regions_of_class(name))
        except LookupError:
            continue
        if boxes:
            return name, boxes
    return candidates[-1], ()


def kb_query_class_test(kb: Vocabulary | None) -> Callable[[str, str], bool] | None:
    """``kb.answers_to`` as the class test of a query: an object of class ``a`` answers a query for class ``b`` when
    it is one or is typically packaged in one (a mustard for "bottle"); names the KB does not know are equal or
    unrelated. Fusion and association keep :func:`kb_class_test` (what an object is, not what it is seen as)."""
    return None if kb is None else _known_or_equal(kb.answers_to)


def kb_class_test(kb: Vocabulary | None) -> Callable[[str, str], bool] | None:
    """``kb.is_subclass`` as a class test that treats names the KB does not know as equal-or-unrelated."""
    return None if kb is None else _known_or_equal(kb.is_subclass)


def _known_or_equal(relation: Callable[[str, str], bool]) -> Callable[[str, str], bool]:
    """``relation`` where the KB knows both names; otherwise a name stands only for itself."""

    def class_test(a: str, b: str) -> bool:
        try:
            return relation(a, b)
        except LookupError:
            return a == b

    return class_test


def searched_only(found: BeliefFilter, searched_region: str | None) -> BeliefFilter:
    """``found`` for the answer of a plan that searched ``searched_region``: when the plan searched the whole view
    (None: a table read as the support plane of an input without a camera pose), the answer is not narrowed to a
    region either (its beliefs have no place in the semantic map to be found in)."""
    if searched_region is not None or found.region is None:
        return found
    return replace(found, region=None, region_boxes=())
