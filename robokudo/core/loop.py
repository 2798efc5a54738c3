"""Loop: the paper's ↻ decorator, which runs its subtree again after every run (a continuous task's per-frame part).

A :class:`Loop` ticks its child; when a run of the child finishes the loop counts it and stays RUNNING, so the
child starts its next run on the next tick (never twice in one tick, so a run that finishes at once cannot spin).
It ends by itself only

* with SUCCESS once ``runs`` successful runs were made (``runs=None``: never, it runs until it is stopped from
  outside - cancelled, or taken out of its slot), or
* with FAILURE once more than ``max_failures`` runs failed in a row (``None``: never; a failed run is a frame
  without an answer and the next run starts on the next tick).

:func:`frame_pipeline` finds the Pipeline that analyses one frame in a task tree (the loop's child, or the task).
"""

from __future__ import annotations

import py_trees
from py_trees.common import Status

from robokudo.core.explained import Explained
from robokudo.core.pipeline import Pipeline


class Loop(Explained, py_trees.decorators.Decorator):
    """Runs its child again after every run until stopped, ``runs`` successes, or too many failures in a row."""

    def __init__(
        self,
        name: str,
        child: py_trees.behaviour.Behaviour,
        *,
        runs: int | None = None,
        max_failures: int | None = 0,
        reason: str = "",
    ) -> None:
        if runs is not None and (isinstance(runs, bool) or not isinstance(runs, int) or runs < 1):
            raise ValueError(f"Loop runs must be a whole number >= 1 or None, not {runs!r}")
        if max_failures is not None and (
            isinstance(max_failures, bool) or not isinstance(max_failures, int) or max_failures < 0
        ):
            raise ValueError(f"Loop max_failures must be a whole number >= 0 or None, not {max_failures!r}")
        super().__init__(name=name, child=child)
        self.runs = runs
        self.max_failures = max_failures
        self.reason = reason
        self.succeeded = 0
        """Successful runs of the child since the loop started."""
        self.failed = 0
        """Failed runs of the child since the loop started."""
        self.failures_in_a_row = 0
        """Failed runs since the last successful one."""
        self.last_failure = ""
        """The feedback message of the child's last failed run ("" when none failed)."""

    @property
    def completed(self) -> int:
        """Finished runs (successful and failed) since the loop started."""
        return self.succeeded + self.failed

    def initialise(self) -> None:
        """A new loop: no runs counted."""
        self.succeeded = self.failed = self.failures_in_a_row = 0
        self.last_failure = ""

    def update(self) -> Status:
        """Count the run that just finished (if one did) and say whether the loop goes on."""
        status = self.decorated.status
        if status is Status.SUCCESS:
            self.succeeded += 1
            self.failures_in_a_row = 0
            if self.runs is not None and self.succeeded >= self.runs:
                self.feedback_message = f"{self.succeeded} runs done"
                return Status.SUCCESS
        elif status is Status.FAILURE:
            self.failed += 1
            self.failures_in_a_row += 1
            self.last_failure = _failure_message(self.decorated)
            if self.max_failures is not None and self.failures_in_a_row > self.max_failures:
                self.feedback_message = f"run {self.completed} failed: {self.last_failure}"
                return Status.FAILURE
        self.feedback_message = f"run {self.completed + 1}"
        return Status.RUNNING


def _failure_message(node: py_trees.behaviour.Behaviour) -> str:
    """The messages of the failed nodes under ``node`` (the failed leaves say why)."""
    failed = [n for n in node.iterate() if n.status is Status.FAILURE and n.feedback_message and not n.children]
    return "; ".join(f"{n.name}: {n.feedback_message}" for n in failed) or f"{node.name} failed"


def frame_pipeline(task: py_trees.behaviour.Behaviour | None) -> Pipeline | None:
    """The Pipeline that analyses one frame of a task tree: the task when it is a Pipeline, the pipeline a
    loop repeats when the task is a Loop (possibly nested in decorators), else None."""
    node = task
    while isinstance(node, py_trees.decorators.Decorator):
        node = node.decorated
    return node if isinstance(node, Pipeline) else None
