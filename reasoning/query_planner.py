"""From a parsed query to a Plan: interpretation, then synthesis against the sensor source."""

from __future__ import annotations

from dataclasses import dataclass

from queries.model import Query
from reasoning.interpretation import Interpretation, interpret
from reasoning.knowledge_base import KnowledgeBase
from reasoning.model import Conditions, RegionBox
from reasoning.plan import Plan
from reasoning.planner import SensorSource, plan_requirements

DEPTH_TYPES = frozenset({"DepthImage", "PointCloud"})
REGION_PRECONDITION = "NeedsRegion"


@dataclass(frozen=True)
class QueryPlan:
    """A plan together with the interpretation it was made from."""

    plan: Plan
    interpretation: Interpretation


def region_parameters(box: RegionBox) -> dict[str, object]:
    """Constructor arguments that hand a region box to an annotator needing one (plain data, no ontology types)."""
    return {
        "region": box.name,
        "box_pose": tuple(float(v) for v in box.pose.reshape(-1)),
        "box_size": tuple(float(v) for v in box.size),
    }


def plan_query(query: Query, kb: KnowledgeBase, source: SensorSource) -> QueryPlan:
    """Interpret ``query`` and synthesize the plan that answers it from ``source``'s sensor types."""
    interpretation = interpret(query, kb)
    box = interpretation.region_box
    conditions = Conditions(depth=bool(source.types & DEPTH_TYPES), region=box is not None)
    parameters: dict[str, dict[str, object]] = {}
    if box is not None:
        for spec in kb.annotators():
            if REGION_PRECONDITION in spec.preconditions:
                parameters[spec.name] = region_parameters(box)
    plan = plan_requirements(
        interpretation.task, interpretation.requirements, kb, source, conditions=conditions, parameters=parameters
    )
    return QueryPlan(plan, interpretation)
