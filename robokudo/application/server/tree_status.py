"""The running tree with each node's status, as the ``/robokudo/tree_status`` topic publishes it after each tick."""

from __future__ import annotations

import time
from typing import Any

import py_trees

from robokudo.core.explained import reason_of


def node_status(node: py_trees.behaviour.Behaviour) -> dict[str, Any]:
    """``node`` and its children: name, status, the planner's reason (nodes that explain themselves) and feedback
    message."""
    entry: dict[str, Any] = {"name": node.name, "status": node.status.name}
    reason = reason_of(node)
    if reason:
        entry["reason"] = reason
    if node.feedback_message:
        entry["message"] = node.feedback_message
    if node.children:
        entry["children"] = [node_status(child) for child in node.children]
    return entry


def tree_status(root: py_trees.behaviour.Behaviour, tick: int) -> dict[str, Any]:
    """The ``/robokudo/tree_status`` message of tick number ``tick``, stamped with the wall-clock time it was made
    (seconds since the epoch)."""
    return {"tick": tick, "stamp": time.time(), "tree": node_status(root)}
