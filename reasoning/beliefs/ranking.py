"""Which of the beliefs matching a query answer it best: the order a query with ``max_results`` is cut in.

"find a cup" asks for one object. Of the beliefs the filter lets through, the one most likely to be what was asked
comes first: the probability that the object exists times the probability that it answers to the asked class (the
fused class distribution's mass on the classes the query's class test accepts, each counted once: a paper cup's
support counts for "cup", a mustard's for "bottle"; :func:`~reasoning.fusion.rule.answer_probability`) and the fused
probability of every asked attribute value (``color: red``). A belief
the query's class was only guessed for (no stored evidence of that class) ranks after every belief with evidence.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping

from reasoning.beliefs.store import BeliefFilter
from reasoning.fusion.rule import CLASS_ATTRIBUTE, ClassTest, ValueSupport, answer_probability, fuse_values
from reasoning.fusion.tracking import ObjectBelief
from robokudo.core.types import Text


def _best_probability(
    name: str, values: Mapping[str, ValueSupport], accepts: Callable[[str], bool], class_test: ClassTest | None
) -> float:
    """The largest fused probability among the stated values ``accepts`` (0 when none of them was stated)."""
    if not values:
        return 0.0
    fused = fuse_values(name, values, class_test)
    return max((item.confidence for item in fused.support if accepts(item.value)), default=0.0)


def _alternatives(wanted: str | tuple[str, ...]) -> tuple[str, ...]:
    return (wanted,) if isinstance(wanted, str) else tuple(wanted)


def match_probability(belief: ObjectBelief, belief_filter: BeliefFilter) -> float:
    """How likely ``belief`` is what ``belief_filter`` asks for: its existence confidence times the probability of
    the object answering to the asked class and of each asked attribute value (read text is matched, not scored,
    and counts 1)."""
    probability = belief.confidence
    asked = belief_filter.object_class
    if asked:
        classes = belief.attributes.get(CLASS_ATTRIBUTE)
        probability *= answer_probability(classes.values, asked, belief_filter.class_test) if classes else 0.0
    for name, wanted in belief_filter.attributes.items():
        if name == Text.attribute:
            continue
        attribute = belief.attributes.get(name)
        names = frozenset(value.lower() for value in _alternatives(wanted))
        probability *= _best_probability(
            name, attribute.values if attribute else {}, lambda value, names=names: value.lower() in names, None
        )
    return probability


def answer_order(belief: ObjectBelief, belief_filter: BeliefFilter) -> tuple[float, float, int]:
    """The sort key of a belief in a cut answer: the most likely to answer ``belief_filter`` first, then the more
    confident, then the older."""
    return (-match_probability(belief, belief_filter), -belief.confidence, belief.id)


def best_first(beliefs: Iterable[ObjectBelief], belief_filter: BeliefFilter) -> list[ObjectBelief]:
    """``beliefs`` in :func:`answer_order`, cut to the filter's ``limit`` when it has one."""
    ranked = sorted(beliefs, key=lambda b: answer_order(b, belief_filter))
    return ranked if belief_filter.limit is None else ranked[: belief_filter.limit]
