"""Explained nodes: tree nodes of our own that carry the reason they are in their tree.

A synthesized tree is explainable (``robokudo plan --explain``): every node says why the planner put it there.
The reason lives on the node classes this package defines (Annotator, Pipeline, ThresholdParallel, TaskSlot,
Sequence, Fallback); py_trees' own node objects are never given extra attributes.
"""

from __future__ import annotations

import py_trees


class Explained:
    """Mixin for node classes that carry ``reason``: why the node is in its tree (empty when nobody said)."""

    reason: str = ""


def reason_of(node: py_trees.behaviour.Behaviour) -> str:
    """The reason ``node`` is in its tree, or "" for nodes that carry none (e.g. plain py_trees nodes)."""
    return node.reason if isinstance(node, Explained) else ""
