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

from annotators.catalog import AnnotatorCatalog
from queries.model import POINTING_KEY, POINTING_TARGETS, Block, Field, Query, Symbol
from reasoning.planning.plan import Alternatives, Plan, Step
from reasoning.planning.planner import SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.core.composites import Sequence
from robokudo.core.resources import SharedResources
from trees.synthesis import NodeFactory, stage_nodes

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
