"""The rosbridge v2 messages the server understands and sends, and their validation.

Incoming text is checked before anything acts on it: size (:data:`MAX_MESSAGE_BYTES`), JSON, an object with a
known ``op`` and the fields that op needs, each of the right type. A message failing a check raises
:class:`ProtocolError`, which the session answers with a ``status`` error naming the problem.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

MAX_MESSAGE_BYTES = 1 << 20
"""Largest message accepted (1 MiB); larger ones get a status error."""

QUERY_ACTION = "/robokudo/query"
QUERY_ACTION_TYPE = "robokudo_msgs/action/Query"
PLAN_SERVICE = "/robokudo/plan"
BELIEFS_SERVICE = "/robokudo/beliefs"
ONTOLOGY_SERVICE = "/robokudo/ontology"
TREE_STATUS_TOPIC = "/robokudo/tree_status"
IMAGE_TOPIC = "/robokudo/image"
DEPTH_TOPIC = "/robokudo/depth"
BELIEFS_TOPIC = "/robokudo/beliefs"
"""The topic of belief changes (a topic and a service may share a name in ROS)."""

GOAL_QUERY_FIELD = "query"
"""The goal field holding the query text (any form ``robokudo parse`` accepts)."""


class GoalStatus:
    """ROS 2 action goal statuses (action_msgs/msg/GoalStatus), as rosbridge reports them."""

    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6


REQUIRED_FIELDS: Mapping[str, Mapping[str, type]] = MappingProxyType(
    {
        "auth": MappingProxyType({"mac": str}),
        "send_action_goal": MappingProxyType({"id": str, "action": str, "args": dict}),
        "cancel_action_goal": MappingProxyType({"id": str, "action": str}),
        "call_service": MappingProxyType({"service": str}),
        "subscribe": MappingProxyType({"topic": str}),
        "unsubscribe": MappingProxyType({"topic": str}),
    }
)
"""op -> the fields it must carry and their types; the keys are every op the server handles."""

OPTIONAL_FIELDS: Mapping[str, type | tuple[type, ...]] = MappingProxyType(
    {"id": str, "args": dict, "action_type": str, "type": str, "feedback": bool}
)
"""Fields that, when present, must have this type (whatever the op)."""


class ProtocolError(ValueError):
    """A message the server cannot act on; ``id`` is the message's id when it had a readable one."""

    def __init__(self, message: str, id: str | None = None) -> None:
        super().__init__(message)
        self.id = id


def parse_message(raw: str | bytes) -> dict[str, Any]:
    """The message in ``raw``, checked (see the module); ProtocolError when it fails a check."""
    size = len(raw) if isinstance(raw, bytes) else len(raw.encode("utf-8"))
    if size > MAX_MESSAGE_BYTES:
        raise ProtocolError(f"message of {size} bytes exceeds the limit of {MAX_MESSAGE_BYTES} bytes")
    try:
        message = json.loads(raw)
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ProtocolError(f"malformed JSON: {error}") from None
    if not isinstance(message, dict):
        raise ProtocolError(f"a message must be a JSON object, got {type(message).__name__}")
    raw_id = message.get("id")
    message_id = raw_id if isinstance(raw_id, str) else None
    op = message.get("op")
    if not isinstance(op, str):
        raise ProtocolError("the message has no 'op' string", message_id)
    required = REQUIRED_FIELDS.get(op)
    if required is None:
        raise ProtocolError(f"unknown op {op!r}", message_id)
    for name in required:
        if name not in message:
            raise ProtocolError(f"op {op!r} needs the field {name!r}", message_id)
    for name, value in message.items():
        kind = required.get(name) or OPTIONAL_FIELDS.get(name)
        if kind is not None and not _has_type(value, kind):
            raise ProtocolError(f"field {name!r} of op {op!r} must be {_type_name(kind)}", message_id)
    return message


def _has_type(value: object, kind: type | tuple[type, ...]) -> bool:
    return isinstance(value, kind) and not (isinstance(value, bool) and kind is not bool)


def _type_name(kind: type | tuple[type, ...]) -> str:
    names = {str: "a string", dict: "an object", bool: "a boolean", int: "an integer"}
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return " or ".join(names.get(k, k.__name__) for k in kinds)


def status(level: str, msg: str, id: str | None = None) -> dict[str, Any]:
    """A rosbridge ``status`` message (level ``error``, ``warning`` or ``info``)."""
    message: dict[str, Any] = {"op": "status", "level": level, "msg": msg}
    if id is not None:
        message["id"] = id
    return message


def action_feedback(goal_id: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """An ``action_feedback`` message for the goal ``goal_id`` of the query action."""
    return {"op": "action_feedback", "id": goal_id, "action": QUERY_ACTION, "values": dict(values)}


def action_result(goal_id: str, goal_status: int, values: Mapping[str, Any], *, result: bool = True) -> dict[str, Any]:
    """An ``action_result`` message: ``result`` is False only when the goal could not be handled at all."""
    return {
        "op": "action_result",
        "id": goal_id,
        "action": QUERY_ACTION,
        "values": dict(values),
        "status": goal_status,
        "result": result,
    }


def service_response(service: str, id: str | None, values: Mapping[str, Any], *, result: bool) -> dict[str, Any]:
    """A ``service_response`` message (``result`` False: ``values`` holds the error)."""
    message: dict[str, Any] = {"op": "service_response", "service": service, "values": dict(values), "result": result}
    if id is not None:
        message["id"] = id
    return message


def publish(topic: str, msg: Mapping[str, Any]) -> dict[str, Any]:
    """A ``publish`` message on ``topic``."""
    return {"op": "publish", "topic": topic, "msg": dict(msg)}
