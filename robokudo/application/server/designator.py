"""A query action goal as a query: the query text, or the structured object designator of RoboKudo's message.

A goal carries either ``query`` (text in any form ``robokudo parse`` accepts) or ``obj``, the designator
(``robokudo_msgs/ObjectDesignator``), with an optional ``type`` naming the query kind (default ``detect``).
Designator fields map onto the query's ``obj`` block:

=====================  ===================  =========================================================================
designator field       in the message       query
=====================  ===================  =========================================================================
``type``               ``string``           ``obj.type``, a class name (``Milk``); one class only
``color``              ``string[]``         ``obj.color``; several: ``[red, blue]``, objects of any of them
``shape``              ``string[]``         ``obj.shape``; several: any of them
``size``               ``string``           ``obj.size`` (``small``, ``medium``, ``large``); several: any of them
``location``           ``string``           ``obj.location``, a region (``fridge``); one region only
``attribute``/``text`` ``string[]``         ``obj.text``, text written on the object; several (from either field or
                                            both): any of them read
``uid``                ``string``           ``obj.id``, a belief id from an earlier answer (a whole number); one only
``pose``               ``PoseStamped[]``    refused: a query restricts the search to a named region (``location``),
                                            not to a point; the reason names the point and its frame
``description``,       ``string[]``,        refused: no query key holds them
``shape_size``         ``ShapeSize[]``
=====================  ===================  =========================================================================

Each field may be a string or a list of strings. Empty values (``""``, ``[]``, ``null``, a ``PoseStamped`` with an
empty frame and the origin as position, which is what a client filling the whole message sends) mean the field is
not asked for. Several values of one field are alternatives, as RoboKudo matches them: an object qualifies when it
has any of them (every field given must hold). A field whose values the query cannot hold (several classes,
regions or ids; a uid that is no whole number; a pose), an unknown field or a value that is no name raises
:class:`GoalError` naming the field; the goal is then aborted with that reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from queries import Query, QueryError, query_from_json
from robokudo.application.server.protocol import GOAL_QUERY_FIELD

GOAL_DESIGNATOR_FIELD = "obj"
GOAL_KIND_FIELD = "type"

ONE_VALUE_FIELDS: Mapping[str, str] = MappingProxyType({"type": "type", "location": "location"})
"""Designator field -> query key, for the name fields a query holds one value of."""

ALTERNATIVE_FIELDS: Mapping[str, str] = MappingProxyType({"color": "color", "shape": "shape", "size": "size"})
"""Designator field -> query key, for the name fields whose several values are alternatives."""

TEXT_FIELDS = ("attribute", "text")
"""Designator fields holding text written on the object (``obj.text``)."""

UID_FIELD = "uid"
POSE_FIELD = "pose"
UNMAPPED_FIELDS = ("description", "shape_size")
"""Fields of RoboKudo's message no query key holds: refused unless empty."""


class GoalError(ValueError):
    """The goal's designator does not map onto a query."""


class MissingQueryError(GoalError):
    """The goal carries neither query text nor a designator."""


def goal_query(args: Mapping[str, Any]) -> str | Query:
    """The goal's query: its text, or the query its designator maps to (see the module)."""
    text = args.get(GOAL_QUERY_FIELD)
    if isinstance(text, str) and text.strip():
        return text
    designator = args.get(GOAL_DESIGNATOR_FIELD)
    if not isinstance(designator, Mapping):
        raise MissingQueryError(
            f"the goal needs the field {GOAL_QUERY_FIELD!r} (the query text) or {GOAL_DESIGNATOR_FIELD!r} "
            "(an object designator)"
        )
    kind = args.get(GOAL_KIND_FIELD) or "detect"
    if not isinstance(kind, str):
        raise GoalError(f"the goal's {GOAL_KIND_FIELD!r} must be a query kind such as detect")
    block = designator_block(designator)
    if not block:
        raise GoalError("the goal's designator is empty")
    try:
        return query_from_json({"kind": kind, "body": {"obj": {"block": block}}})
    except QueryError as error:
        raise GoalError(f"the designator does not make a query: {error}") from None


def designator_block(designator: Mapping[str, Any]) -> dict[str, Any]:
    """The query's ``obj`` block (tagged JSON form) the designator's fields map to; GoalError naming a field that
    cannot be mapped."""
    block: dict[str, Any] = {}
    texts: list[str] = []
    for name, value in designator.items():
        if name == POSE_FIELD:
            _refuse_pose(value)
            continue
        if name in UNMAPPED_FIELDS:
            if _is_empty(value):
                continue
            raise GoalError(f"designator field {name!r} is not mapped onto a query: no query key holds it")
        if name not in ONE_VALUE_FIELDS and name not in ALTERNATIVE_FIELDS and name not in (*TEXT_FIELDS, UID_FIELD):
            raise GoalError(f"unknown designator field {name!r}; the fields are {', '.join(_FIELD_NAMES)}")
        values = _strings(name, value)
        if not values:
            continue
        if name in TEXT_FIELDS:
            texts.extend(values)
        elif name in ALTERNATIVE_FIELDS:
            block[ALTERNATIVE_FIELDS[name]] = _tagged("symbol", values)
        elif len(values) > 1:
            what = "a belief id" if name == UID_FIELD else f"one {'class' if name == 'type' else 'region'}"
            raise GoalError(f"designator field {name!r} has {len(values)} values, but a query asks for {what}")
        elif name == UID_FIELD:
            block["id"] = {"number": _belief_id(values[0])}
        else:
            block[ONE_VALUE_FIELDS[name]] = {"symbol": values[0]}
    if texts:
        block["text"] = _tagged("string", list(dict.fromkeys(texts)))
    return block


_FIELD_NAMES = (*ONE_VALUE_FIELDS, *ALTERNATIVE_FIELDS, *TEXT_FIELDS, UID_FIELD, POSE_FIELD, *UNMAPPED_FIELDS)


def _is_empty(value: object) -> bool:
    return value is None or value == "" or value == [] or value == {}


def _strings(name: str, value: object) -> list[str]:
    """The field's non-empty strings (a string or a list of strings); GoalError for anything else."""
    if value is None:
        return []
    items = value if isinstance(value, list) else [value]
    if not all(isinstance(item, str) for item in items):
        raise GoalError(f"designator field {name!r} must be a string or a list of strings")
    return list(dict.fromkeys(item.strip() for item in items if item.strip()))


def _tagged(tag: str, values: list[str]) -> dict[str, Any]:
    """One tagged value, or a tagged list of several."""
    if len(values) == 1:
        return {tag: values[0]}
    return {"list": [{tag: value} for value in values]}


def _belief_id(text: str) -> float:
    if not text.isdigit():
        raise GoalError(f"designator field {UID_FIELD!r} must be a belief id from an earlier answer (a whole number)")
    return float(text)


def _refuse_pose(value: object) -> None:
    """Accept only an empty pose; GoalError naming the field (and the point, when readable) otherwise."""
    poses = value if isinstance(value, list) else [value]
    for pose in poses:
        if _is_empty(pose):
            continue
        frame, point = _stamped_point(pose)
        if frame == "" and point == (0.0, 0.0, 0.0):
            continue  # a default PoseStamped: nothing asked
        x, y, z = point
        raise GoalError(
            f"designator field {POSE_FIELD!r} (the point ({x:g}, {y:g}, {z:g}) in frame {frame!r}) cannot be searched "
            "for: a query restricts the search to a named region (the field 'location'), not to a point"
        )


def _stamped_point(pose: object) -> tuple[str, tuple[float, float, float]]:
    """The frame and position of a ``geometry_msgs/PoseStamped`` as rosbridge sends it."""
    shape = (
        f"designator field {POSE_FIELD!r} must be a geometry_msgs/PoseStamped or a list of them "
        "({header: {frame_id}, pose: {position: {x, y, z}, orientation: {x, y, z, w}}})"
    )
    if not isinstance(pose, Mapping):
        raise GoalError(shape)
    header, body = pose.get("header", {}), pose.get("pose")
    position = body.get("position") if isinstance(body, Mapping) else None
    frame = header.get("frame_id", "") if isinstance(header, Mapping) else None
    if not isinstance(frame, str) or not isinstance(position, Mapping):
        raise GoalError(shape)
    coordinates = [position.get(axis, 0.0) for axis in "xyz"]
    if not all(isinstance(c, int | float) and not isinstance(c, bool) for c in coordinates):
        raise GoalError(shape)
    x, y, z = (float(c) for c in coordinates)
    return frame, (x, y, z)
