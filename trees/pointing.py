"""The pointing detection as one reusable unit: a planned subtree that finds what a person points at.

:func:`pointing_plan` plans ``detect { pointing: { target: ... } }`` for a sensor source (the planner chooses the
people detector, the activity recognizer and the pointing estimator from their declarations, and the object
segmentation for an object target); :func:`pointing_unit` turns that plan into one Sequence node, leaving out
the steps whose outputs the embedding tree already produces (its reader, its point cloud), so a tracking tree can
run it beside its own experts, e.g. in a Parallel ("track and detect"). The unit writes a PointingTarget into the
CAS of the Pipeline it is embedded in.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import partial

import py_trees

from annotators.catalog import AnnotatorCatalog, CatalogError
from queries.model import POINTING_KEY, POINTING_TARGETS, Block, Field, Query, Symbol
from reasoning.planning.plan import Alternatives, Plan, Step, Unit
from reasoning.planning.planner import SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.core.composites import Sequence
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.resources import SharedResources
from robokudo.core.types import TargetTrack
from trees.synthesis import NodeFactory, instantiate, stage_nodes

UNIT_NAME = "detect pointing"


def pointing_query(target: str = "object") -> Query:
    """``detect { pointing: { target: <target> } }`` (ValueError for a target other than object or region)."""
    if target not in POINTING_TARGETS:
        raise ValueError(f"a pointing target is {' or '.join(POINTING_TARGETS)}, not {target!r}")
    body = Block((Field(POINTING_KEY, Block((Field("target", Symbol(target)),))),))
    return Query("detect", body, f"detect {{ {POINTING_KEY}: {{ target: {target} }} }}")


def pointing_plan(planner: QueryPlanner, source: SensorSource, target: str = "object") -> Plan:
    """The planner's plan for detecting what a person points at from ``source``."""
    return planner.plan(pointing_query(target), source).plan


def without_available(plan: Plan, available: Iterable[str]) -> Plan:
    """``plan`` without the single steps whose every output is ``available`` (already in the embedding CAS)."""
    have = frozenset(available)

    def needed(unit: Step | Alternatives) -> bool:
        return not (isinstance(unit, Step) and unit.outputs and set(unit.outputs) <= have)

    stages = tuple(kept for stage in plan.stages if (kept := tuple(u for u in stage if needed(u))))
    return Plan(task=plan.task, stages=stages, sensor_types=plan.sensor_types | have)


def pointing_unit(
    plan: Plan,
    available: Iterable[str] = (),
    *,
    name: str = UNIT_NAME,
    make: NodeFactory | None = None,
    catalog: AnnotatorCatalog | None = None,
    resources: SharedResources | None = None,
) -> Sequence:
    """The pointing plan as one Sequence node, without the steps producing only ``available`` types."""
    kept = without_available(plan, available)
    children = stage_nodes(kept, make=make, catalog=catalog, resources=resources)
    target = kept.task.pointing or "object"
    return Sequence(name, children, reason=f"detects which {target} a person points at (a reusable planned unit)")


WATCH_NAME = "track and detect"
"""The Parallel of a tracking tree that also watches what the person points at."""


def _step_reads(step: Step, catalog: AnnotatorCatalog | None) -> frozenset[str]:
    """The types a step reads: its required inputs and, when its class is known, its optional ones."""
    reads = set(step.inputs)
    if catalog is not None:
        try:
            cls = catalog[step.annotator]
        except CatalogError:
            cls = None
        if cls is not None:
            reads |= {t.__name__ for t in (*cls.inputs, *cls.optional_inputs)}
    return frozenset(reads)


def _reads(unit: Unit, catalog: AnnotatorCatalog | None = None) -> frozenset[str]:
    """The types a unit reads from before it (for alternatives: what any branch reads and does not make itself)."""
    if isinstance(unit, Step):
        return _step_reads(unit, catalog)
    needed: set[str] = set()
    for branch in unit.branches:
        made: set[str] = set()
        for step in branch:
            needed |= _step_reads(step, catalog) - made
            made |= set(step.outputs)
    return frozenset(needed)


def _makes(unit: Unit) -> frozenset[str]:
    if isinstance(unit, Step):
        return frozenset(unit.outputs)
    return frozenset(t for branch in unit.branches for step in branch for t in step.outputs)


def _closure(units: list[Unit], roots: Iterable[int], catalog: AnnotatorCatalog | None) -> set[int]:
    """The indices of ``roots`` and of every unit they need (what they read, back to the reader)."""
    found, todo = set(), list(roots)
    while todo:
        index = todo.pop()
        if index in found:
            continue
        found.add(index)
        reads = _reads(units[index], catalog)
        todo.extend(i for i in range(index) if _makes(units[i]) & reads)
    return found


def track_types() -> frozenset[str]:
    """The names of the CAS types a tracker writes (TargetTrack and its subtypes)."""
    found, todo = set(), [TargetTrack]
    while todo:
        cls = todo.pop()
        found.add(cls.__name__)
        todo.extend(cls.__subclasses__())
    return frozenset(found)


def split_track_and_point(
    plan: Plan, track_types: Iterable[str], catalog: AnnotatorCatalog | None = None
) -> tuple[Plan, Plan, Plan]:
    """A continuous plan that also watches pointing, split into three plans: the steps both need (reader, cloud,
    people detector), the tracker branch (what only the tracker needs) and the pointing unit (the rest: what
    only the pointing target needs). The last two read only the first, so they may run side by side. With a
    ``catalog`` the steps' optional inputs count as needed too (a people detector that reads the cloud when
    there is one). ValueError when the plan has no tracker (a unit making one of ``track_types``) or no
    pointing step."""
    units = list(plan.units())
    tracks = frozenset(track_types)
    trackers = [i for i, unit in enumerate(units) if _makes(unit) & tracks]
    if not trackers:
        raise ValueError("the plan has no tracker to embed the pointing unit beside")
    tracking = _closure(units, trackers, catalog)
    watching = set(range(len(units))) - tracking
    if not watching:
        raise ValueError("the plan has no pointing step beside its tracker")
    shared = _closure(units, watching, catalog) & tracking

    def part(chosen: set[int]) -> Plan:
        kept, index = [], 0
        for stage in plan.stages:
            picked = tuple(unit for offset, unit in enumerate(stage) if index + offset in chosen)
            index += len(stage)
            if picked:
                kept.append(picked)
        return Plan(task=plan.task, stages=tuple(kept), sensor_types=plan.sensor_types)

    return part(shared), part(tracking - shared), part(watching)


def track_and_detect_nodes(
    plan: Plan,
    make: NodeFactory | None = None,
    catalog: AnnotatorCatalog | None = None,
    resources: SharedResources | None = None,
) -> list[py_trees.behaviour.Behaviour]:
    """The body of a tracking Pipeline that watches pointing (the paper's Fig. 7): the shared stages, then a
    Parallel of the tracker branch and the pointing unit (:func:`pointing_unit`). The Parallel succeeds when
    either succeeds, so a frame where the person does not point still gives the track."""
    catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
    if make is None:
        make = partial(instantiate, catalog=catalog, resources=resources)
    shared, tracking, watching = split_track_and_point(plan, track_types(), catalog)
    tracker = Sequence("follow", stage_nodes(tracking, make=make), reason="follows the person from frame to frame")
    unit = pointing_unit(watching, make=make)
    both = ThresholdParallel(
        WATCH_NAME,
        [tracker, unit],
        n_success=0,
        n_failure=1,
        reason="the track and what the person points at, side by side on one frame (either answers)",
    )
    return [*stage_nodes(shared, make=make), both]
