"""TaskSlot: a placeholder in a root tree that holds the current task's subtree (the seed's Fig. 4)."""

from __future__ import annotations

from collections.abc import Iterator

import py_trees
from py_trees.common import Status

from robokudo.core.explained import Explained


class TaskSlot(Explained, py_trees.composites.Composite):
    """Holds zero or one subtree and passes its status through; an empty slot is idle and succeeds.

    Subtrees are put in and taken out by the engine's task interface between ticks, never by the
    subtree itself.
    """

    def __init__(self, name: str = "task") -> None:
        super().__init__(name=name, children=[])
        self.reason = "placeholder for the current task's subtree"

    @property
    def subtree(self) -> py_trees.behaviour.Behaviour | None:
        """The subtree in the slot, or None."""
        return self.children[0] if self.children else None

    def set_subtree(self, subtree: py_trees.behaviour.Behaviour | None) -> py_trees.behaviour.Behaviour | None:
        """Put ``subtree`` in the slot (None empties it); the old one is stopped and returned."""
        old = self.subtree
        if old is not None:
            if old.status is not Status.INVALID:
                old.stop(Status.INVALID)
            self.remove_child(old)
        if subtree is not None:
            self.add_child(subtree)
        if self.status is Status.RUNNING:
            self.stop(Status.INVALID)
        return old

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        """Tick the subtree, or succeed at once when empty."""
        if self.status is not Status.RUNNING:
            self.initialise()
        subtree = self.subtree
        if subtree is None:
            self.current_child = None
            self.stop(Status.SUCCESS)
            yield self
            return
        self.current_child = subtree
        yield from subtree.tick()
        new_status = subtree.status
        if new_status is not Status.RUNNING:
            self.stop(new_status)
        self.status = new_status
        yield self
