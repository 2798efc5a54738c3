"""The running tree with each node's status, as the ``/robokudo/tree_status`` topic publishes it after each tick.

Each node has its ``name`` and ``status`` (``reason`` when it explains itself, ``message`` when it has a feedback
message). An annotator also
has ``timing``: ``last_ms``, the duration of its last run in milliseconds, and ``runs``, how often it ran (its
:class:`~robokudo.core.stats.RunStats`); ``runs`` tells a client whether the node ran since the previous message.
Composites carry no timing. The message is built after every tick, so it reads only counters, never the
statistics' median over the recent window. The message carries its tick number and wall-clock ``stamp``.
"""

from __future__ import annotations

import time
from typing import Any

import py_trees

from robokudo.core.annotator import Annotator
from robokudo.core.explained import reason_of


def node_timing(node: Annotator) -> dict[str, Any]:
    """The annotator's last run duration (ms) and run count."""
    stats = node.stats
    return {"last_ms": round(stats.last_seconds * 1e3, 3), "runs": stats.count}


def node_status(node: py_trees.behaviour.Behaviour) -> dict[str, Any]:
    """``node`` and its children: name, status, the planner's reason (nodes that explain themselves), feedback
    message and an annotator's timing."""
    entry: dict[str, Any] = {"name": node.name, "status": node.status.name}
    reason = reason_of(node)
    if reason:
        entry["reason"] = reason
    if node.feedback_message:
        entry["message"] = node.feedback_message
    if isinstance(node, Annotator):
        entry["timing"] = node_timing(node)
    if node.children:
        entry["children"] = [node_status(child) for child in node.children]
    return entry


def tree_status(root: py_trees.behaviour.Behaviour, tick: int) -> dict[str, Any]:
    """The ``/robokudo/tree_status`` message of tick number ``tick``, stamped with the wall-clock time it was made
    (seconds since the epoch)."""
    return {"tick": tick, "stamp": time.time(), "tree": node_status(root)}
