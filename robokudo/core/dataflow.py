"""Static data-flow validation: on every execution path, every declared input is produced before it is read.

The analysis walks the tree with the set of CAS types guaranteed to be present:

* Sequence: children in order, each seeing what the earlier ones produced.
* Fallback (Selector): each child sees only what was present before the Fallback (earlier children failed,
  and a failed annotator commits nothing); afterwards only what *every* child guarantees is present, where a
  child that writes a subtype guarantees its supertypes too (one branch writing PersonHypothesis, another
  ObjectHypothesis guarantee ObjectHypothesis).
* ThresholdParallel: each child sees only what was present before it (children interleave); afterwards a
  type is guaranteed when every set of children large enough to make the parallel succeed contains a
  producer of it.
* Pipeline: owns a fresh CAS, so its children start from nothing (but its query, when it has one); it adds
  nothing to the outer CAS.
* Decorators that can succeed without their child succeeding add nothing.
"""

from __future__ import annotations

from collections.abc import Mapping

import py_trees
from py_trees.common import ParallelPolicy

from robokudo.core.annotator import Annotator
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.slot import TaskSlot
from robokudo.core.types import CasType, QueryView

TypeSet = frozenset[type[CasType]]
_PASS_THROUGH_DECORATORS = (py_trees.decorators.Timeout, py_trees.decorators.Retry)


class DataFlowError(Exception):
    """A tree reads a CAS type that is not guaranteed to be produced before it."""


def satisfied(required: type[CasType], available: TypeSet) -> bool:
    """True when some available type is ``required`` or a subtype of it."""
    return any(issubclass(t, required) for t in available)


def data_flow_violations(
    root: py_trees.behaviour.Behaviour,
    available: TypeSet = frozenset(),
    substitute: Mapping[TaskSlot, py_trees.behaviour.Behaviour | None] | None = None,
) -> list[str]:
    """Every violation in the tree, in execution order, as sentences.

    ``substitute`` evaluates TaskSlots as if they held the given subtrees (used before a swap).
    """
    walker = _Walker(root, dict(substitute or {}))
    walker.flow(root, available)
    return walker.violations


def validate_data_flow(
    root: py_trees.behaviour.Behaviour,
    available: TypeSet = frozenset(),
    substitute: Mapping[TaskSlot, py_trees.behaviour.Behaviour | None] | None = None,
) -> None:
    """Raise DataFlowError describing the first violation, if any."""
    violations = data_flow_violations(root, available, substitute)
    if violations:
        raise DataFlowError(violations[0])


class _Walker:
    def __init__(self, root: py_trees.behaviour.Behaviour, substitute: dict) -> None:
        self.root = root
        self.substitute = substitute
        self.violations: list[str] = []

    def children(self, node: py_trees.behaviour.Behaviour) -> list[py_trees.behaviour.Behaviour]:
        if isinstance(node, TaskSlot) and node in self.substitute:
            replacement = self.substitute[node]
            return [replacement] if replacement is not None else []
        return list(node.children)

    def flow(self, node: py_trees.behaviour.Behaviour, available: TypeSet) -> TypeSet:
        if isinstance(node, Annotator):
            for required in node.inputs:
                if not satisfied(required, available):
                    self.violations.append(self.describe(node, required))
            return available | frozenset(node.outputs)
        children = self.children(node)
        if isinstance(node, Pipeline):
            self.sequence(children, frozenset({QueryView}) if node.query is not None else frozenset())
            return available
        if isinstance(node, py_trees.composites.Selector):
            results = [_with_supertypes(self.flow(child, available)) for child in children]
            return frozenset.intersection(*results) if results else available
        if isinstance(node, ThresholdParallel):
            results = [_with_supertypes(self.flow(child, available)) for child in children]
            return available | self.parallel_guarantees(results, _with_supertypes(available), node.n_success + 1)
        if isinstance(node, py_trees.composites.Parallel):
            results = [_with_supertypes(self.flow(child, available)) for child in children]
            if isinstance(node.policy, ParallelPolicy.SuccessOnOne):
                return frozenset.intersection(*results) if results else available
            return frozenset().union(available, *results)
        if isinstance(node, py_trees.decorators.Decorator):
            result = self.flow(node.decorated, available)
            return result if isinstance(node, _PASS_THROUGH_DECORATORS) else available
        return self.sequence(children, available)

    def sequence(self, children: list[py_trees.behaviour.Behaviour], available: TypeSet) -> TypeSet:
        for child in children:
            available = self.flow(child, available)
        return available

    @staticmethod
    def parallel_guarantees(results: list[TypeSet], before: TypeSet, needed: int) -> TypeSet:
        produced = frozenset().union(*results) - before if results else frozenset()
        guaranteed = set()
        for cas_type in produced:
            without = sum(cas_type not in result for result in results)
            if without < needed:
                guaranteed.add(cas_type)
        return frozenset(guaranteed)

    def describe(self, consumer: Annotator, required: type[CasType]) -> str:
        where = f"in Pipeline {_pipeline_name(consumer)!r}"
        head = f"{consumer.name} reads {required.__name__}, but"
        producers = [
            n
            for n in self.root.iterate()
            if isinstance(n, Annotator)
            and n is not consumer
            and any(issubclass(t, required) for t in n.outputs)
            and _pipeline_name(n) == _pipeline_name(consumer)
        ]
        if not producers:
            return f"{head} nothing {where} produces it"
        producer = producers[0]
        junction = _branching_ancestor(producer, consumer)
        if isinstance(junction, py_trees.composites.Selector):
            return f"{head} {producer.name} produces it only in one branch of Fallback {junction.name!r} {where}"
        if isinstance(junction, ThresholdParallel | py_trees.composites.Parallel):
            return (
                f"{head} {producer.name} produces it in a branch of Parallel {junction.name!r} that may not "
                f"have finished or succeeded {where}"
            )
        return f"{head} its producer {producer.name} does not run before it on every path {where}"


def _with_supertypes(types: TypeSet) -> TypeSet:
    """The types and every CAS type they derive from (what their presence satisfies, made explicit)."""
    return frozenset(c for t in types for c in t.__mro__ if isinstance(c, type) and issubclass(c, CasType))


def _pipeline_name(node: py_trees.behaviour.Behaviour) -> str:
    parent = node.parent
    while parent is not None and not isinstance(parent, Pipeline):
        parent = parent.parent
    return parent.name if parent is not None else ""


def _ancestors(node: py_trees.behaviour.Behaviour) -> list[py_trees.behaviour.Behaviour]:
    chain = []
    while node.parent is not None:
        node = node.parent
        chain.append(node)
    return chain


def _branching_ancestor(
    producer: py_trees.behaviour.Behaviour, consumer: py_trees.behaviour.Behaviour
) -> py_trees.behaviour.Behaviour | None:
    """The nearest Fallback/Parallel above the producer that the consumer is not under, else the common parent."""
    consumer_line = set(map(id, _ancestors(consumer)))
    for ancestor in _ancestors(producer):
        if id(ancestor) in consumer_line:
            return ancestor
        if isinstance(ancestor, py_trees.composites.Selector | ThresholdParallel | py_trees.composites.Parallel):
            return ancestor
    return None
