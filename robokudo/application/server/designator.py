"""A query action goal as a query: the query text, or the structured object designator of RoboKudo's message.

A goal carries either ``query`` (text in any form ``robokudo parse`` accepts) or ``obj``, the designator, with an
optional ``type`` naming the query kind (default ``detect``). Designator fields map onto the query's ``obj`` block:

========================  ===========================================
designator field          query
========================  ===========================================
``type``                  ``obj.type`` (a class name, e.g. ``Milk``)
``color``                 ``obj.color``
``shape``                 ``obj.shape``
``size``                  ``obj.size`` (``small``, ``medium``, ``large``)
``location``              ``obj.location`` (a region, e.g. ``fridge``)
``text`` / ``attribute``  ``obj.text`` (text written on the object)
``uid``                   ``obj.id`` (a belief id from an earlier answer)
========================  ===========================================

A field may be a string or a list holding one string (the message's ``string[]``). ``pose`` and designators
with several values in one field are not mapped yet: such a goal is refused with the reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from queries import Query, QueryError, query_from_json
from robokudo.application.server.protocol import GOAL_QUERY_FIELD

GOAL_DESIGNATOR_FIELD = "obj"
GOAL_KIND_FIELD = "type"

SYMBOL_FIELDS: Mapping[str, str] = MappingProxyType(
    {"type": "type", "color": "color", "shape": "shape", "size": "size", "location": "location"}
)
"""Designator field -> query key, for the fields whose value is a name."""

TEXT_FIELDS = ("text", "attribute")
NOT_MAPPED = ("pose",)


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
    block: dict[str, Any] = {}
    for name, value in designator.items():
        if name in NOT_MAPPED or (value in ("", [], None)):
            if value not in ("", [], None):
                raise GoalError(f"designator field {name!r} is not mapped onto a query yet")
            continue
        single = _single(name, value)
        if name in SYMBOL_FIELDS:
            block[SYMBOL_FIELDS[name]] = {"symbol": single}
        elif name in TEXT_FIELDS:
            block["text"] = {"string": single}
        elif name == "uid":
            block["id"] = {"number": float(single)} if single.isdigit() else {"symbol": single}
        else:
            raise GoalError(f"unknown designator field {name!r}")
    if not block:
        raise GoalError("the goal's designator is empty")
    try:
        return query_from_json({"kind": kind, "body": {"obj": {"block": block}}})
    except QueryError as error:
        raise GoalError(f"the designator does not make a query: {error}") from None


def _single(name: str, value: object) -> str:
    if isinstance(value, list) and len(value) == 1:
        value = value[0]
    if not isinstance(value, str):
        raise GoalError(f"designator field {name!r} must be a string or a list of one string (several: not yet)")
    return value
