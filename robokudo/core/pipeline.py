"""Pipeline: a Sequence that owns one CAS (the seed's phi), and the lookup from a node to its CAS."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import py_trees
from py_trees.common import Status

from robokudo.core.cas import CAS
from robokudo.core.explained import Explained
from robokudo.core.types import QueryView


class Pipeline(Explained, py_trees.composites.Sequence):
    """A Sequence owning a CAS; every annotator below it (up to a nested Pipeline) works on this CAS.

    A fresh CAS is created each time the pipeline starts a new run, so every frame is analysed on a clean
    structure; the last run's CAS stays readable (``pipeline.cas``) until the next run begins. A pipeline
    made for a query puts it into every new CAS as the QueryView.
    """

    def __init__(
        self,
        name: str,
        children: Sequence[py_trees.behaviour.Behaviour] | None = None,
        memory: bool = True,
        query: object | None = None,
        reason: str = "",
    ) -> None:
        super().__init__(name=name, memory=memory, children=list(children or []))
        self.query = query
        self.cas = self._new_cas()
        self.reason = reason

    def _new_cas(self) -> CAS:
        cas = CAS()
        if self.query is not None:
            cas.set_view(QueryView(self.query))
        return cas

    def initialise(self) -> None:
        """Start a new run on a new CAS."""
        super().initialise()
        self.cas = self._new_cas()


class StructureError(Exception):
    """The tree is malformed (e.g. an annotator that no Pipeline owns)."""


def enclosing_pipeline(node: py_trees.behaviour.Behaviour) -> Pipeline | None:
    """The nearest Pipeline above ``node`` (not ``node`` itself), or None."""
    parent = node.parent
    while parent is not None:
        if isinstance(parent, Pipeline):
            return parent
        parent = parent.parent
    return None


def tree_root(node: py_trees.behaviour.Behaviour) -> py_trees.behaviour.Behaviour:
    """The root of the tree ``node`` belongs to."""
    while node.parent is not None:
        node = node.parent
    return node


def pipelines(root: py_trees.behaviour.Behaviour) -> Iterator[Pipeline]:
    """Every Pipeline in the tree under ``root`` (inclusive), depth first."""
    for node in root.iterate():
        if isinstance(node, Pipeline):
            yield node


def finished_run_cas(node: py_trees.behaviour.Behaviour | None) -> CAS | None:
    """The CAS of ``node``'s last run when ``node`` is a Pipeline whose run ended (SUCCESS or FAILURE), else None
    (how a server finds the frame a task just analysed). A decorated pipeline (a continuous task's loop) counts as
    the pipeline it decorates."""
    while isinstance(node, py_trees.decorators.Decorator):
        node = node.decorated
    if isinstance(node, Pipeline) and node.status in (Status.SUCCESS, Status.FAILURE):
        return node.cas
    return None


def pipeline_named(root: py_trees.behaviour.Behaviour, name: str) -> Pipeline:
    """The Pipeline called ``name`` in the tree; raises KeyError listing the names present."""
    found = [p for p in pipelines(root) if p.name == name]
    if not found:
        names = ", ".join(sorted(p.name for p in pipelines(root))) or "none"
        raise KeyError(f"no Pipeline named {name!r} in this tree (pipelines: {names})")
    return found[0]
