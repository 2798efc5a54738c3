"""Which beliefs answer a query for a class: the one rule the live answer and the answer from memory share.

A belief answers a query for class ``C`` when a class its attribute index holds answers to ``C`` (the query's class
test: ``C``, a subclass, a class packaged in it): its fused class when the evidence supports it (the ``class_name``
column), else its leading class, the most probable class the experts stated though below 0.5 (a guess, such as a
can the classifier could not tell from a jar; the answer shows it with "?" and its probability), or any class more
likely than not. A belief whose experts stated no class answers to none.

A live answer is the store's answer restricted to the objects seen in the frame (``BeliefFilter.ids``), so "how many
cans are there" gets the same count live and from memory for the same scene.

How each branch is read (its cost never grows with the guesses of other classes or places): a query narrowed to a
region or to ids reads the beliefs without a supported class there (the class index's NULL key with the region, or
the ids) and checks each by one seek in the attribute index; it never lists the attribute index's entries for the
asked classes, which hold every belief of those classes (65,000 of 1,000,000 for milk in the benchmark), supported
ones included. A query for a class anywhere lists exactly those entries (as many as the beliefs it answers with,
and the guesses of those classes) and keeps the ones without a supported class.
"""

from __future__ import annotations

from reasoning.fusion.rule import CLASS_ATTRIBUTE

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


def candidate_class_clauses(classes: list[str], narrowed: bool) -> list[tuple[str, list[object], str]]:
    """The SQL conditions on an ``objects`` row under which a belief answers to one of ``classes`` (the stored class
    names the query's class test accepts), each with its parameters and how a SELECT reading ``objects`` by them
    alone (no ids, no box) should read the table (``INDEXED BY objects_class``, or ``NOT INDEXED``: by id): a
    supported class, or, for a belief without one, a class it is indexed under in the attribute index. ``narrowed``:
    the query names a region or ids, so the beliefs without a supported class are read there and checked one by
    one; else they are read from the attribute index's entries of ``classes``."""
    marks = ", ".join("?" * len(classes))
    guessed = (
        f"EXISTS (SELECT 1 FROM attribute_index a WHERE a.name = ? AND a.value IN ({marks}) AND a.object_id = id)"
        if narrowed
        else f"id IN (SELECT object_id FROM attribute_index WHERE name = ? AND value IN ({marks}))"
    )
    return [
        (f"class_name IN ({marks})", list(classes), BY_CLASS),
        (f"class_name IS NULL AND {guessed}", [CLASS_ATTRIBUTE, *classes], BY_CLASS if narrowed else BY_ID),
    ]
