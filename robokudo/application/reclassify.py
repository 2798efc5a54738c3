"""Keeping the belief store consistent with the ontology when an object class is removed.

The beliefs of a removed class move to its parent class: the removed class's support in the ``class`` attribute
becomes the parent's (added to what the parent already had), every other class alternative stays as it was,
and the belief's class is the parent. Without a parent the removed value is dropped and the class is left
unknown. Each belief is rewritten as a whole (:meth:`BeliefStore.put`); its observation history is kept as it
was recorded.
"""

from __future__ import annotations

from dataclasses import replace

from reasoning.beliefs.filters import kb_class_test
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.rule import CLASS_ATTRIBUTE, AttributeBelief, ClassTest
from reasoning.fusion.tracking import ObjectBelief
from reasoning.knowledge.editing import EditResult, OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase


def reclassify(store: BeliefStore, removed: str, parent: str | None, class_test: ClassTest | None = None) -> list[int]:
    """Move the stored beliefs of class ``removed`` (gone ones too) to ``parent``; returns their ids."""
    beliefs = store.query(BeliefFilter(object_class=removed, include_gone=True))
    if not beliefs:
        return []
    store.put([_moved(belief, removed, parent) for belief in beliefs], class_test)
    return [belief.id for belief in beliefs]


def _moved(belief: ObjectBelief, removed: str, parent: str | None) -> ObjectBelief:
    attributes = dict(belief.attributes)
    stated = attributes.get(CLASS_ATTRIBUTE)
    if stated is not None:
        moved = AttributeBelief(CLASS_ATTRIBUTE)
        moved.merge(AttributeBelief(CLASS_ATTRIBUTE, {v: s for v, s in stated.values.items() if v != removed}))
        if parent is not None and removed in stated.values:
            moved.merge(AttributeBelief(CLASS_ATTRIBUTE, {parent: stated.values[removed]}))
        attributes[CLASS_ATTRIBUTE] = moved
    return replace(belief, attributes=attributes, class_name=parent)


def remove_object_class(
    kb: KnowledgeBase, editor: OntologyEditor, name: str, store: BeliefStore | None
) -> tuple[EditResult, str | None, list[int]]:
    """Remove the user class ``name`` (validated and locked, as every edit), then move the beliefs of it in
    ``store`` to its parent class; the edit, the parent (None without one) and the ids of the moved beliefs."""
    try:
        parents = sorted(kb.superclasses(name, direct=True))  # read before the class is gone
    except LookupError:
        parents = []  # remove_object says what is wrong with the name
    result = editor.remove_object(name)
    parent = parents[0] if parents else None
    moved = reclassify(store, result.name, parent, kb_class_test(kb)) if store is not None else []
    return result, parent, moved
