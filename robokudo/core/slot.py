"""TaskSlot: a placeholder in a root tree that holds the current task's subtree (the paper's Fig. 4), and Idle,
the subtree a slot holds while there is no task."""

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
        """Put ``subtree`` in the slot (None empties it) and return the old one.

        A running old subtree is stopped (its running annotators are interrupted); a finished one keeps its final
        statuses, so it can still be explained after it was taken out.
        """
        old = self.subtree
        if old is not None:
            if old.status is Status.RUNNING:
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


class Idle(Explained, py_trees.behaviour.Behaviour):
    """The subtree of a slot without a task: succeeds at once on every tick, so the root keeps perceiving."""

    def __init__(self, name: str = "idle", reason: str = "no task: waits for the next one") -> None:
        super().__init__(name=name)
        self.reason = reason

    def update(self) -> Status:
        """Nothing to do."""
        return Status.SUCCESS


class PerceiveThenTask(Explained, py_trees.composites.Composite):
    """The served root (the paper's Fig. 4): perceive, then the task; perception runs on every tick.

    Each tick the ``perception`` child runs (it stays RUNNING while no new frame is due); the ``task`` child (the
    slot) runs when perception just delivered a frame, or when the task is already running (a task in the middle of
    a run, or a continuous task's loop, goes on every tick). So a task starts on a freshly perceived frame, and a
    continuous task's loop sees every new frame. Fails when perception fails (the task is left to its owner to end);
    otherwise its status is the task's (RUNNING while perception waits and no task runs).
    """

    def __init__(self, name: str, perception: py_trees.behaviour.Behaviour, task: py_trees.behaviour.Behaviour,
                 reason: str = "") -> None:  # fmt: skip
        super().__init__(name=name, children=[perception, task])
        self.reason = reason

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        """Tick perception, then the task when it has a frame to work on or is running."""
        if self.status is not Status.RUNNING:
            self.initialise()
        perception, task = self.children
        self.current_child = perception
        yield from perception.tick()
        if perception.status is Status.FAILURE:
            self.stop(Status.FAILURE)
            yield self
            return
        if perception.status is Status.SUCCESS or task.status is Status.RUNNING:
            self.current_child = task
            yield from task.tick()
            status = task.status
        else:
            status = Status.RUNNING
        if status is not Status.RUNNING:
            self.stop(status)
        self.status = status
        yield self
