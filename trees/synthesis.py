"""Turn a Plan into a Perception Pipeline Tree: Pipeline > stages (Parallel when independent) > Fallbacks.

Annotator classes are looked up by the ``implemented_by`` path the ontology names; only classes of the
project's ``annotators`` package can be instantiated.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from collections.abc import Sequence as Ordered
from functools import partial

import py_trees

from annotators.catalog import AnnotatorCatalog
from reasoning.planning.plan import Alternatives, Plan, Step, Unit
from robokudo.core.annotator import Annotator
from robokudo.core.composites import Fallback, Sequence
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


def _from_catalog(catalog: AnnotatorCatalog, step: Step) -> Annotator:
    node = catalog[step.annotator](name=step.annotator, **dict(step.parameters))
    node.reason = step.reason
    return node


NodeFactory = Callable[[Step], py_trees.behaviour.Behaviour]


def _unit_node(unit: Unit, make: NodeFactory) -> py_trees.behaviour.Behaviour:
    if isinstance(unit, Step):
        return make(unit)
    return _fallback(unit, make)


def _fallback(alternatives: Alternatives, make: NodeFactory) -> Fallback:
    branches: list[py_trees.behaviour.Behaviour] = []
    for branch in alternatives.branches:
        if len(branch) == 1:
            branches.append(make(branch[0]))
        else:
            branches.append(
                Sequence(
                    f"via {branch[-1].annotator}",
                    [make(step) for step in branch],
                    reason=f"{branch[-1].annotator} with the steps only it needs",
                )
            )
    return Fallback(f"{alternatives.provides} providers", branches, reason=alternatives.reason)


def _stage_node(index: int, stage: Ordered[Unit], make: NodeFactory) -> py_trees.behaviour.Behaviour:
    if len(stage) == 1:
        return _unit_node(stage[0], make)
    return ThresholdParallel(
        f"stage {index}",
        [_unit_node(unit, make) for unit in stage],
        reason="independent experts run side by side; all must succeed",
    )


def build_tree(
    plan: Plan,
    name: str = "query",
    final_steps: Ordered[py_trees.behaviour.Behaviour] = (),
    make: NodeFactory = instantiate,
    query: object | None = None,
    catalog: AnnotatorCatalog | None = None,
) -> Pipeline:
    """The Pipeline for ``plan`` (stages in order, then ``final_steps`` such as the answer step), validated.

    ``make`` turns a step into a node (default: the annotator class the ontology names); ``query`` is put
    into every new CAS of the pipeline.
    """
    if catalog is not None:
        make = partial(_from_catalog, catalog)
    children = [_stage_node(index, stage, make) for index, stage in enumerate(plan.stages, start=1)]
    pipeline = Pipeline(name, [*children, *final_steps], query=query, reason=f"answers the {plan.task.kind} query")
    validate_data_flow(pipeline)
    return pipeline
