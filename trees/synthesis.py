"""Turn a Plan into a Perception Pipeline Tree: Pipeline > stages (Parallel when independent) > Fallbacks.

A continuous query's tree (:func:`build_task_tree` for a kind of ``queries.CONTINUOUS_KINDS``, e.g. ``track``) is
that Pipeline inside a :class:`~robokudo.core.loop.Loop` (the paper's ↻): it analyses one frame per run and runs
again until the task is cancelled; a failed run (nobody seen in a frame) is a frame without an answer.

A plan names annotators; their classes come from an :class:`~annotators.catalog.AnnotatorCatalog` (by default
the ``annotators`` package's, plus any classes a caller adds), the only place that turns names into classes.
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Sequence as Ordered
from functools import partial

import py_trees

from annotators.catalog import AnnotatorCatalog, CatalogError
from queries.model import CONTINUOUS_KINDS
from reasoning.knowledge.capabilities import implementation_path
from reasoning.planning.plan import Alternatives, Plan, Step, Unit
from robokudo.core.annotator import Annotator
from robokudo.core.composites import Fallback, Sequence
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.loop import Loop
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.resources import SharedResources


class SynthesisError(Exception):
    """A plan names an annotator class that cannot be used."""


def instantiate(step: Step, catalog: AnnotatorCatalog, resources: SharedResources | None = None) -> Annotator:
    """A fresh node of the catalog's class for a plan step, with the step's parameters and reason (and the shared
    ``resources`` pool, when given, instead of its own).

    SynthesisError when the catalog has no class of that name, or a different class than the plan was made for.
    """
    try:
        cls = catalog[step.annotator]
    except CatalogError as error:
        raise SynthesisError(f"cannot build plan step {step.annotator}: {error}") from None
    path = implementation_path(cls)
    if step.implemented_by and path != step.implemented_by:
        raise SynthesisError(
            f"cannot build plan step {step.annotator}: the plan was made for {step.implemented_by}, "
            f"but the catalog's {step.annotator} is {path}"
        )
    node = cls(name=step.annotator, **dict(step.parameters))
    node.reason = step.reason
    if resources is not None:
        node.resources = resources
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


def stage_nodes(
    plan: Plan,
    make: NodeFactory | None = None,
    catalog: AnnotatorCatalog | None = None,
    resources: SharedResources | None = None,
) -> list[py_trees.behaviour.Behaviour]:
    """One node per stage of ``plan`` (a threshold Parallel of independent units, a Fallback of alternatives, or
    a leaf), in order: the body of a Pipeline, or of a subtree embedded in another tree."""
    if make is None:
        catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
        make = partial(instantiate, catalog=catalog, resources=resources)
    return [_stage_node(index, stage, make) for index, stage in enumerate(plan.stages, start=1)]


def build_tree(
    plan: Plan,
    name: str = "query",
    final_steps: Ordered[py_trees.behaviour.Behaviour] = (),
    make: NodeFactory | None = None,
    query: object | None = None,
    catalog: AnnotatorCatalog | None = None,
    resources: SharedResources | None = None,
    body: Ordered[py_trees.behaviour.Behaviour] | None = None,
) -> Pipeline:
    """The Pipeline for ``plan`` (stages in order, then ``final_steps`` such as the answer step), validated.

    ``make`` turns a step into a node; by default each step becomes an instance of the ``catalog``'s class of
    that name (default catalog: :meth:`AnnotatorCatalog.discover`), sharing the ``resources`` pool (loaded
    models) when given. ``query`` is put into every new CAS of the pipeline. ``body``, when given, is the plan's
    stages already built (a tree shape other than one node per stage). SynthesisError when a step names no
    class of the catalog.
    """
    children = list(body) if body is not None else stage_nodes(plan, make=make, catalog=catalog, resources=resources)
    pipeline = Pipeline(name, [*children, *final_steps], query=query, reason=f"answers the {plan.task.kind} query")
    validate_data_flow(pipeline)
    return pipeline


def build_task_tree(
    plan: Plan,
    name: str = "query",
    final_steps: Ordered[py_trees.behaviour.Behaviour] = (),
    make: NodeFactory | None = None,
    query: object | None = None,
    catalog: AnnotatorCatalog | None = None,
    resources: SharedResources | None = None,
) -> Pipeline | Loop:
    """The tree running ``plan`` as its task: :func:`build_tree`'s Pipeline for a one-shot kind; for a continuous
    kind that Pipeline (named "every frame") in a Loop that repeats it until stopped, tolerating failed runs. A
    continuous plan that also watches pointing runs its tracker and the pointing unit side by side in a Parallel
    (:func:`trees.pointing.track_and_detect_nodes`)."""
    continuous = plan.task.kind in CONTINUOUS_KINDS
    body = None
    if continuous and plan.task.pointing is not None:
        from trees.pointing import track_and_detect_nodes  # the pointing unit is built on this module

        body = track_and_detect_nodes(plan, make=make, catalog=catalog, resources=resources)
    pipeline = build_tree(
        plan,
        name="every frame" if continuous else name,
        final_steps=final_steps,
        make=make,
        query=query,
        catalog=catalog,
        resources=resources,
        body=body,
    )
    if not continuous:
        return pipeline
    pipeline.reason = f"analyses one frame for the {plan.task.kind} query"
    return Loop(
        name,
        pipeline,
        runs=None,
        max_failures=None,
        reason=f"a {plan.task.kind} query runs once per frame until it is cancelled or its target is lost",
    )
