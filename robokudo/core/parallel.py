"""ThresholdParallel: the seed's parallel node with n_success / n_failure thresholds.

Semantics, per tick:

* Every child that has not yet finished in the current run is ticked, in order. A child that returned
  SUCCESS or FAILURE keeps that result and is not ticked again until the parallel starts a new run.
* Let ``s`` and ``f`` be the numbers of children that succeeded and failed so far.
  ``f > n_failure`` gives FAILURE; otherwise ``s > n_success`` gives SUCCESS; otherwise RUNNING.
  A tie - both thresholds crossed on the same tick - is FAILURE: failure is checked first.
* When every child has finished and neither threshold was crossed, the thresholds can never be reached,
  so the parallel returns FAILURE instead of running forever.
* When the parallel finishes, children still RUNNING are stopped (interrupted) so none dangles.

With ``n_success = len(children) - 1`` and ``n_failure = 0`` this is "all must succeed"; with
``n_success = 0`` and ``n_failure = len(children) - 1`` it is "one success is enough".
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import py_trees
from py_trees.common import Status

from robokudo.core.explained import Explained

# Status members looked up once: on Python 3.11 each ``Status.X`` costs ~100 ns, and tick compares every child.
_SUCCESS, _FAILURE, _RUNNING, _INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID


class ThresholdParallel(Explained, py_trees.composites.Composite):
    """Ticks its children side by side and decides by counting successes and failures."""

    def __init__(
        self,
        name: str,
        children: Sequence[py_trees.behaviour.Behaviour] | None = None,
        n_success: int | None = None,
        n_failure: int = 0,
        reason: str = "",
    ) -> None:
        """``n_success`` defaults to ``len(children) - 1`` (all must succeed)."""
        super().__init__(name=name, children=list(children or []))
        self._n_success = n_success
        self.n_failure = n_failure
        self.reason = reason

    @property
    def n_success(self) -> int:
        """Successes needed minus one (SUCCESS when strictly more children succeeded)."""
        return self._n_success if self._n_success is not None else max(len(self.children) - 1, 0)

    def decide(self, statuses: Sequence[Status]) -> Status:
        """The parallel's status for these child statuses (pure; used by tick and by tests)."""
        succeeded = sum(s is _SUCCESS for s in statuses)
        failed = sum(s is _FAILURE for s in statuses)
        return self._decide_counts(succeeded, failed, len(statuses))

    def _decide_counts(self, succeeded: int, failed: int, total: int) -> Status:
        if failed > self.n_failure:
            return _FAILURE
        if succeeded > self.n_success:
            return _SUCCESS
        if not total:
            return _SUCCESS
        if succeeded + failed == total:
            return _FAILURE
        return _RUNNING

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        """Tick unfinished children, then decide."""
        if self.status is not _RUNNING:
            for child in self.children:
                if child.status is not _INVALID:
                    child.stop(_INVALID)
            self.initialise()
        succeeded = failed = 0
        for child in self.children:
            status = child.status
            if status is _RUNNING or status is _INVALID:
                yield from child.tick()
                status = child.status
            if status is _SUCCESS:
                succeeded += 1
            elif status is _FAILURE:
                failed += 1
        new_status = self._decide_counts(succeeded, failed, len(self.children))
        self.current_child = self.children[-1] if self.children else None
        if new_status is not _RUNNING:
            self.stop(new_status)
        self.status = new_status
        yield self

    def stop(self, new_status: Status = Status.INVALID) -> None:
        """Interrupt children that are still running, then stop."""
        for child in self.children:
            if child.status is _RUNNING:
                child.stop(_INVALID)
        super().stop(new_status)
