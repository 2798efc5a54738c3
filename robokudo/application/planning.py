"""Planning a query for an input: the reader the input needs, then the plan (the camera follows the region)."""

from __future__ import annotations

from queries import Query
from reasoning.planning.query_planner import QueryPlan, QueryPlanner
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.regions import RegionBox
from robokudo.core.types import CameraIntrinsics


def plan_for_input(
    planner: QueryPlanner,
    query: Query,
    input_path: str | None,
    frame: int = 0,
    *,
    look_at: str | None = None,
    intrinsics: CameraIntrinsics | None = None,
    person: str | None = None,
    focus: RegionBox | None = None,
) -> QueryPlan:
    """Plan ``query`` to run on ``input_path`` (the built-in kitchen when None).

    For the kitchen the simulated camera is pointed at the region the query names, else at ``look_at`` (e.g.
    where the object a query names by id was last seen), so the plan is made twice only when the reader
    depends on that region. ``person`` puts a person into the kitchen (see ``sensor_source``); ``focus`` is the box
    an inspection of one object looks in (:meth:`QueryPlanner.plan`).
    """
    draft = planner.plan(
        query, sensor_source(planner.kb, input_path, frame, intrinsics=intrinsics, person=person), focus
    )
    region = draft.interpretation.task.region or look_at
    if input_path is None and region is not None:
        return planner.plan(query, sensor_source(planner.kb, input_path, frame, region, person=person), focus)
    return draft
