"""Which beliefs answer a query for a class: the one rule the live answer and the answer from memory share.

A belief answers a query for class ``C`` when a class its attribute index holds answers to ``C`` (the query's class
test: ``C``, a subclass, a class packaged in it): its fused class when the evidence supports it (the ``class_name``
column), else its leading class, the most probable class the experts stated though below 0.5 (a guess, such as a
can the classifier could not tell from a jar; the answer shows it with "?" and its probability), or any class more
likely than not. A belief whose experts stated no class answers to none.

A live answer is the store's answer restricted to the objects seen in the frame (``BeliefFilter.ids``), so "how many
cans are there" gets the same count live and from memory for the same scene.
"""

from __future__ import annotations

from reasoning.fusion.rule import CLASS_ATTRIBUTE


def candidate_class_clauses(classes: list[str]) -> list[tuple[str, list[object], bool]]:
    """The SQL conditions on an ``objects`` row under which a belief answers to one of ``classes`` (the stored class
    names the query's class test accepts), each with its parameters and whether the class index serves it: a
    supported class, or, for a belief without one, a leading class in the attribute index."""
    marks = ", ".join("?" * len(classes))
    return [
        (f"class_name IN ({marks})", list(classes), True),
        (
            "class_name IS NULL AND id IN "
            f"(SELECT object_id FROM attribute_index WHERE name = ? AND value IN ({marks}))",
            [CLASS_ATTRIBUTE, *classes],
            False,
        ),
    ]
