"""Which beliefs answer a query for a class: the one rule the live answer and the answer from memory share.

A belief answers a query for class ``C`` when a class its attribute index holds answers to ``C`` (the query's class
test: ``C``, a subclass, a class packaged in it): its fused class when the evidence supports it (the ``class_name``
column), else its leading class, the most probable class the experts stated though below 0.5 (a guess, such as a
can the classifier could not tell from a jar; the answer shows it with "?" and its probability), or any class more
likely than not. A belief whose supported class is more general than the asked one's classes (food, where a can of
food was asked for) answers too when its leading refinement (:func:`leading_refinement`: the most probable class
stated below its supported one, "canned food" under "food") answers to ``C``: a robot that asked "find all objects"
first still finds the can it would have found without asking. A belief whose experts stated no class answers to
none, and neither does one whose supported class is unrelated (a mug for which a can was guessed too).

A live answer is the store's answer restricted to the objects seen in the frame (``BeliefFilter.ids``), so "how many
cans are there" gets the same count live and from memory for the same scene.

How each branch is read (its cost never grows with the guesses of other classes or places): a query narrowed to a
region or to ids reads the beliefs without a supported class there, and those whose class is more general than an
asked one (the class index's NULL key and those classes' keys with the region, or the ids), and checks each by one
seek in the attribute index; it never lists the attribute index's entries for the asked classes, which hold every
belief of those classes (65,000 of 1,000,000 for milk in the benchmark), supported ones included. A query for a
class anywhere lists exactly those entries (as many as the beliefs it answers with, and the guesses of those
classes) and keeps the ones without a supported class or with a more general one.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence

from reasoning.fusion.rule import CLASS_ATTRIBUTE, ClassTest, FusedAttribute

BY_CLASS = "INDEXED BY objects_class"
"""Read ``objects`` through the class index (class, region): a class and a region in one seek."""
BY_ID = "NOT INDEXED"
"""Read ``objects`` by id only (the ids a subquery lists), never walking an index of its own."""

GUESSED_CLASSES = (
    "SELECT DISTINCT a.value FROM objects INDEXED BY objects_class "
    "JOIN attribute_index a ON a.name = ? AND a.object_id = objects.id WHERE objects.class_name IS NULL"
)
"""The classes beliefs without a supported class are indexed under (parameter: :data:`CLASS_ATTRIBUTE`): what the
``classes`` table must list so a query can expand a class to them (read once when an older store is opened)."""


def leading_refinement(fused: FusedAttribute, class_test: ClassTest) -> str | None:
    """The most probable class stated strictly below ``fused``'s value (``class_test(a, b)``: ``a`` is ``b`` or a
    subclass of it), however unlikely: what an object whose class is "food" most likely is more specifically ("canned
    food" at 0.44); None when no such class was stated. The store indexes it beside the fused class."""
    for item in fused.support:  # most probable first
        if item.value != fused.value and class_test(item.value, fused.value):
            return item.value
    return None


def general_classes(known: Iterable[str], classes: Collection[str], class_test: ClassTest) -> list[str]:
    """The ``known`` class names, other than ``classes``, that some of ``classes`` is (``class_test(a, k)``): the
    supported classes a belief may hold while its leading refinement answers the query (food for canned food)."""
    return [k for k in known if k not in classes and any(class_test(a, k) for a in classes)]


def candidate_class_clauses(
    classes: list[str], narrowed: bool, general: Sequence[str] = ()
) -> list[tuple[str, list[object], str]]:
    """The SQL conditions on an ``objects`` row under which a belief answers to one of ``classes`` (the stored class
    names the query's class test accepts), each with its parameters and how a SELECT reading ``objects`` by them
    alone (no ids, no box) should read the table (``INDEXED BY objects_class``, or ``NOT INDEXED``: by id): a
    supported class, or, for a belief without one or with one of the ``general`` classes (:func:`general_classes`),
    a class it is indexed under in the attribute index. ``narrowed``: the query names a region or ids, so those
    beliefs are read there and checked one by one; else they are read from the attribute index's entries of
    ``classes``. The conditions are disjoint: a belief answers by one of them at most."""
    marks = ", ".join("?" * len(classes))
    guessed = (
        f"EXISTS (SELECT 1 FROM attribute_index a WHERE a.name = ? AND a.value IN ({marks}) AND a.object_id = id)"
        if narrowed
        else f"id IN (SELECT object_id FROM attribute_index WHERE name = ? AND value IN ({marks}))"
    )
    general_marks = ", ".join("?" * len(general))
    supported = (f"class_name IN ({marks})", list(classes), BY_CLASS)
    if not narrowed:
        without = f"(class_name IS NULL OR class_name IN ({general_marks}))" if general else "class_name IS NULL"
        return [supported, (f"{without} AND {guessed}", [*general, CLASS_ATTRIBUTE, *classes], BY_ID)]
    ways = [supported, (f"class_name IS NULL AND {guessed}", [CLASS_ATTRIBUTE, *classes], BY_CLASS)]
    if general:
        ways.append((f"class_name IN ({general_marks}) AND {guessed}", [*general, CLASS_ATTRIBUTE, *classes], BY_CLASS))
    return ways
