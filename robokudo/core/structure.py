"""A tree's structure: static checks run when a tree is built or a subtree is inserted, and which leaves run."""

from __future__ import annotations

from collections import Counter

import py_trees
from py_trees.common import Status

from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline, StructureError, enclosing_pipeline, tree_root


def check_structure(root: py_trees.behaviour.Behaviour, attach_to: py_trees.behaviour.Behaviour | None = None) -> None:
    """Raise StructureError when an annotator has no Pipeline above it or two Pipelines share a name.

    ``attach_to`` is the node ``root`` is about to be inserted under (a TaskSlot); Pipelines above it count.
    """
    outer_pipeline = None
    if attach_to is not None:
        outer_pipeline = attach_to if isinstance(attach_to, Pipeline) else enclosing_pipeline(attach_to)
    for node in root.iterate():
        if isinstance(node, Annotator) and enclosing_pipeline(node) is None and outer_pipeline is None:
            raise StructureError(
                f"annotator {node.name!r} ({type(node).__name__}) is not inside any Pipeline, so it would "
                f"have no CAS; put it under a Pipeline"
            )
    names = Counter(p.name for p in root.iterate() if isinstance(p, Pipeline))
    if attach_to is not None:
        names.update(_pipeline_names_outside(tree_root(attach_to), attach_to))
    duplicated = sorted(name for name, count in names.items() if count > 1)
    if duplicated:
        raise StructureError(f"Pipeline names must be unique in a tree; repeated: {', '.join(duplicated)}")


def _pipeline_names_outside(root: py_trees.behaviour.Behaviour, excluded: py_trees.behaviour.Behaviour) -> list[str]:
    """Names of the Pipelines in ``root``'s tree that are not below ``excluded``."""
    names = []
    stack = [root]
    while stack:
        node = stack.pop()
        if isinstance(node, Pipeline):
            names.append(node.name)
        if node is not excluded:
            stack.extend(node.children)
    return names


def running_leaves(root: py_trees.behaviour.Behaviour) -> list[str]:
    """The names of the leaves below ``root`` that are running, in tree order."""
    return [node.name for node in root.iterate() if not node.children and node.status is Status.RUNNING]
