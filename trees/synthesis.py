"""Turn a Plan into a Perception Pipeline Tree: Pipeline > stages (Parallel when independent) > Fallbacks.

Annotator classes are looked up by the ``implemented_by`` path the ontology names; only classes of the
project's ``annotators`` package can be instantiated.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence

import py_trees

from reasoning.planning.plan import Alternatives, Plan, Step, Unit
from robokudo.core.annotator import Annotator
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline

ALLOWED_PACKAGE = "annotators"


class SynthesisError(Exception):
    """A plan names an annotator class that cannot be used."""


def annotator_class(implemented_by: str) -> type[Annotator]:
    """Import the class ``annotators.module.Class``; anything outside the annotators package is refused."""
    module_name, _, class_name = implemented_by.rpartition(".")
    if not module_name.startswith(ALLOWED_PACKAGE + ".") and module_name != ALLOWED_PACKAGE:
        raise SynthesisError(f"{implemented_by!r} is not in the {ALLOWED_PACKAGE!r} package")
    try:
        cls = getattr(importlib.import_module(module_name), class_name)
    except (ImportError, AttributeError) as error:
        raise SynthesisError(f"cannot load annotator class {implemented_by!r}: {error}") from error
    if not (isinstance(cls, type) and issubclass(cls, Annotator)):
        raise SynthesisError(f"{implemented_by!r} is not an Annotator")
    return cls


def instantiate(step: Step) -> Annotator:
    """A fresh annotator node for a plan step, carrying the step's reason."""
    node = annotator_class(step.implemented_by)(name=step.annotator, **dict(step.parameters))
    node.reason = step.reason
    return node


NodeFactory = Callable[[Step], py_trees.behaviour.Behaviour]


def _unit_node(unit: Unit, make: NodeFactory) -> py_trees.behaviour.Behaviour:
    if isinstance(unit, Step):
        return make(unit)
    return _fallback(unit, make)


def _fallback(alternatives: Alternatives, make: NodeFactory) -> py_trees.composites.Selector:
    branches: list[py_trees.behaviour.Behaviour] = []
    for branch in alternatives.branches:
        if len(branch) == 1:
            branches.append(make(branch[0]))
        else:
            sequence = py_trees.composites.Sequence(
                f"via {branch[-1].annotator}", memory=True, children=[make(step) for step in branch]
            )
            sequence.reason = f"{branch[-1].annotator} with the steps only it needs"
            branches.append(sequence)
    node = py_trees.composites.Selector(f"{alternatives.provides} providers", memory=True, children=branches)
    node.reason = alternatives.reason
    return node


def _stage_node(index: int, stage: Sequence[Unit], make: NodeFactory) -> py_trees.behaviour.Behaviour:
    if len(stage) == 1:
        return _unit_node(stage[0], make)
    parallel = ThresholdParallel(f"stage {index}", [_unit_node(unit, make) for unit in stage])
    parallel.reason = "independent experts run side by side; all must succeed"
    return parallel


def build_tree(
    plan: Plan,
    name: str = "query",
    final_steps: Sequence[py_trees.behaviour.Behaviour] = (),
    make: NodeFactory = instantiate,
    query: object | None = None,
) -> Pipeline:
    """The Pipeline for ``plan`` (stages in order, then ``final_steps`` such as the answer step), validated.

    ``make`` turns a step into a node (default: the annotator class the ontology names); ``query`` is put
    into every new CAS of the pipeline.
    """
    children = [_stage_node(index, stage, make) for index, stage in enumerate(plan.stages, start=1)]
    pipeline = Pipeline(name, [*children, *final_steps], query=query)
    pipeline.reason = f"answers the {plan.task.kind} query"
    validate_data_flow(pipeline)
    return pipeline
