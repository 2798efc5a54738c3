"""From a parsed query and the knowledge base to a :class:`~reasoning.beliefs.store.BeliefFilter`.

The query is read duck-typed (``query.body`` a block with ``get(key)`` and ``fields``; the natural front end
nests the object description under ``obj``); the knowledge base is any object with ``resolve(word)``,
``is_subclass(a, b)``, ``region(name)``, ``regions_of_class(name)``, ``annotation_type_for_key(key)`` and
``value_kind(annotation_type)`` (each may be missing or raise for an unknown word, in which case the word is
used as it is). Neither package is imported here.

Which key filters which attribute comes from the ontology (the annotation type answering the key, its value
kind) and the annotation type's ``attribute`` (:mod:`robokudo.core.types`); without a knowledge base a key
filters the attribute of the same name.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from reasoning.beliefs.store import BeliefFilter
from robokudo.core.types import ATTRIBUTE_TYPES, Annotation, Classification, Location

CLASS_KEYS = ("type", "class", "object")
REGION_KEYS = ("location", "region")
REGION_RELATIONS = ("in", "on", "at", "inside", "within")
FILTERED_TYPES: tuple[type[Annotation], ...] = tuple(t for t in ATTRIBUTE_TYPES if t not in (Classification, Location))
"""The annotation types whose attribute a query key filters on (class and region have their own keys above)."""


def belief_filter(query: Any, kb: Any = None, *, include_gone: bool = False) -> BeliefFilter:
    """The filter selecting the known objects that answer ``query`` (class subsumption and regions via ``kb``)."""
    blocks = [b for b in (_body(query), _block(_get(_body(query), "obj"))) if b is not None]
    object_class = _first_word(blocks, CLASS_KEYS)
    region_word = _region_word(blocks)
    attributes = _attributes(blocks, kb)
    class_test = kb_class_test(kb)
    if object_class is not None:
        object_class = _resolve(kb, object_class, "class")
    region, boxes = (None, ()) if region_word is None else _resolve_region(kb, region_word)
    limit = _number(blocks, "max_results")
    return BeliefFilter(
        object_class=object_class,
        class_test=class_test,
        region=region,
        region_boxes=boxes,
        attributes=attributes,
        include_gone=include_gone,
        limit=None if limit is None else int(limit),
    )


def _body(query: Any) -> Any:
    return getattr(query, "body", None)


def _get(block: Any, key: str) -> Any:
    getter = getattr(block, "get", None)
    return getter(key) if callable(getter) else None


def _block(value: Any) -> Any:
    return value if value is not None and callable(getattr(value, "get", None)) else None


def _word(value: Any) -> str | None:
    """The text of a symbol or string value (None for numbers, lists, blocks, ``?``)."""
    for attribute in ("name", "text"):
        text = getattr(value, attribute, None)
        if isinstance(text, str) and text:
            return text
    return value if isinstance(value, str) and value else None


def _first_word(blocks: list[Any], keys: tuple[str, ...]) -> str | None:
    for block in blocks:
        for key in keys:
            word = _word(_get(block, key))
            if word is not None:
                return word
    return None


def _number(blocks: list[Any], key: str) -> float | None:
    for block in blocks:
        value = getattr(_get(block, key), "value", None)
        if isinstance(value, int | float):
            return float(value)
    return None


def _attributes(blocks: list[Any], kb: Any) -> dict[str, str]:
    """Attribute name -> the value asked for, resolved to the knowledge base's name when it has a value kind."""
    words: dict[type[Annotation], str] = {}
    for block in blocks:
        for key in _keys(block):
            annotation_type = _answering_type(kb, key)
            word = _word(_get(block, key))
            if annotation_type is not None and word is not None:
                words.setdefault(annotation_type, word)
    found: dict[str, str] = {}
    for annotation_type in FILTERED_TYPES:
        word = words.get(annotation_type)
        if word is not None:
            kind = _value_kind(kb, annotation_type)
            found[annotation_type.attribute] = word if kind is None else _resolve(kb, word, kind)
    return found


def _keys(block: Any) -> list[str]:
    return [key for key in (getattr(f, "key", None) for f in getattr(block, "fields", ())) if isinstance(key, str)]


def _answering_type(kb: Any, key: str) -> type[Annotation] | None:
    """The filtered annotation type answering ``key``: per the ontology, else the type whose attribute it names."""
    answered_by = getattr(kb, "annotation_type_for_key", None)
    if not callable(answered_by):
        return next((t for t in FILTERED_TYPES if t.attribute == key), None)
    try:
        name = answered_by(key)
    except (KeyError, ValueError, LookupError):
        return None
    return next((t for t in FILTERED_TYPES if t.type_name() == name), None)


def _value_kind(kb: Any, annotation_type: type[Annotation]) -> str | None:
    """The kind of the ontology values ``annotation_type`` carries (None: free text, or no knowledge base)."""
    value_kind = getattr(kb, "value_kind", None)
    return value_kind(annotation_type.type_name()) if callable(value_kind) else None


def _region_word(blocks: list[Any]) -> str | None:
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


def _name_of(found: Any) -> str | None:
    if isinstance(found, str):
        return found or None
    if isinstance(found, tuple | list) and found:
        return _name_of(found[0])
    name = getattr(found, "name", None)
    return name if isinstance(name, str) and name else None


def _resolve(kb: Any, word: str, kind: str | None = None) -> str:
    """The knowledge base's name for ``word`` (restricted to ``kind`` when the KB supports kinds), else ``word``."""
    resolve = getattr(kb, "resolve", None)
    if not callable(resolve):
        return word
    try:
        try:
            found = resolve(word, (kind,)) if kind else resolve(word)
        except TypeError:
            found = resolve(word)
        return _name_of(found) or word
    except (KeyError, ValueError, LookupError):
        return word


def _resolve_region(kb: Any, word: str) -> tuple[str, tuple[Any, ...]]:
    if kb is None:
        return word, ()
    candidates = [word, _resolve(kb, word, "region_class")]
    region = getattr(kb, "region", None)
    if callable(region):
        for name in candidates:
            try:
                box = region(name)
            except (KeyError, ValueError, LookupError):
                continue
            if box is not None:
                return str(getattr(box, "name", name)), (box,)
    of_class = getattr(kb, "regions_of_class", None)
    if callable(of_class):
        for name in candidates:
            try:
                boxes = tuple(of_class(name) or ())
            except (KeyError, ValueError, LookupError):
                continue
            if boxes:
                return name, boxes
    return candidates[-1], ()


def kb_class_test(kb: Any) -> Callable[[str, str], bool] | None:
    """``kb.is_subclass`` as a class test that treats names the KB does not know as equal-or-unrelated."""
    test = getattr(kb, "is_subclass", None)
    if not callable(test):
        return None

    def class_test(a: str, b: str) -> bool:
        try:
            return bool(test(a, b))
        except (KeyError, ValueError, LookupError):
            return a == b

    return class_test
