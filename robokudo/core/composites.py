"""Sequence and Fallback with a reason: py_trees' own composites, explained (see :mod:`robokudo.core.explained`).

They behave exactly like ``py_trees.composites.Sequence`` and ``Selector`` (with memory by default, as the
seed's trees run each child to completion once per run); only the reason is added.
"""

from __future__ import annotations

from collections.abc import Sequence as Children

import py_trees

from robokudo.core.explained import Explained


class Sequence(Explained, py_trees.composites.Sequence):
    """Ticks its children in order; fails as soon as one fails, succeeds when all succeeded."""

    def __init__(
        self, name: str, children: Children[py_trees.behaviour.Behaviour] = (), memory: bool = True, reason: str = ""
    ) -> None:
        super().__init__(name=name, memory=memory, children=list(children))
        self.reason = reason


class Fallback(Explained, py_trees.composites.Selector):
    """Ticks its children in order until one succeeds (alternatives in rank order); fails when all failed."""

    def __init__(
        self, name: str, children: Children[py_trees.behaviour.Behaviour] = (), memory: bool = True, reason: str = ""
    ) -> None:
        super().__init__(name=name, memory=memory, children=list(children))
        self.reason = reason
