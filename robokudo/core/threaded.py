"""ThreadedAnnotator: an annotator whose work runs in a worker thread so the tick loop stays responsive."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable

import py_trees
from py_trees.common import Status

from robokudo.core.annotator import Annotator, _Run


class ThreadedAnnotator(Annotator):
    """Runs ``analyse`` in a worker thread and returns RUNNING until it is done.

    Writes are committed on the tick thread once the worker succeeded. When the node is interrupted
    (stopped with INVALID, e.g. a Fallback or Parallel moved on or the subtree was swapped out) or its
    ``timeout`` (seconds) passes, the run is cancelled: its writes are discarded, ``cancelled`` turns True
    for code that polls it, and any further CAS access from the stale worker raises ``RunCancelledError`` inside
    that worker, ending it.
    """

    def __init__(self, name: str | None = None, timeout: float = 10.0) -> None:
        super().__init__(name=name)
        self.timeout = timeout
        self._worker: threading.Thread | None = None
        self._started_at = 0.0
        self._outcome: tuple[Status, str, float] | None = None
        self._active_run: _Run | None = None

    def initialise(self) -> None:
        """Start a worker for a new run."""
        run = _Run(self.cas, thread_ident=None)
        self._active_run = run
        self._outcome = None
        self._started_at = time.perf_counter()
        self._worker = threading.Thread(target=self._work, args=(run,), name=f"annotator:{self.name}", daemon=True)
        self._worker.start()

    def _work(self, run: _Run) -> None:
        run.thread_ident = threading.get_ident()
        outcome = self._execute(run)
        if self._active_run is run:
            self._outcome = outcome

    def update(self) -> Status:
        """RUNNING while the worker works; then commit and report its result."""
        run = self._active_run
        if run is None:
            return Status.FAILURE
        outcome = self._outcome
        if outcome is None:
            if time.perf_counter() - self._started_at > self.timeout:
                self._cancel()
                self.feedback_message = f"timed out after {self.timeout:g} s{self.timeout_detail()}"
                return Status.FAILURE
            self.feedback_message = "working"
            return Status.RUNNING
        status, message, elapsed = outcome
        self.stats.record(elapsed)
        if status is Status.SUCCESS:
            run.cas.apply(run.writes)
        self.feedback_message = message
        self._active_run = None
        return status if status is not Status.INVALID else Status.FAILURE

    def timeout_detail(self) -> str:
        """What a timed-out run's message adds after "timed out after N s" (nothing here; a subclass that knows
        more about why says it, starting with a space)."""
        return ""

    def terminate(self, new_status: Status) -> None:
        """Cancel a run that is still working when the node is interrupted."""
        if new_status is Status.INVALID and self._active_run is not None:
            self._cancel()

    def _cancel(self) -> None:
        run = self._active_run
        if run is not None:
            run.cancelled = True
        self._active_run = None

    def stop_worker(self, timeout: float | None = None) -> bool:
        """Cancel a run in progress and wait up to ``timeout`` s (None: as long as it takes) for the worker thread
        to end; True when no worker of this node is left running."""
        self._cancel()
        worker = self._worker
        if worker is not None and worker is not threading.current_thread():
            worker.join(timeout)
        return not self.is_working()

    def is_working(self) -> bool:
        """True while a worker thread of this node is alive (a cancelled one may still be finishing)."""
        return self._worker is not None and self._worker.is_alive()


def stop_workers(trees: Iterable[py_trees.behaviour.Behaviour], timeout: float) -> list[str]:
    """Cancel the runs of the threaded annotators in ``trees`` and wait (up to ``timeout`` s in all) for their
    worker threads to end; returns the names of those still working.

    A process should not exit while a worker runs native code (e.g. an ONNX session): the runtime may abort it.
    """
    deadline = time.monotonic() + timeout
    left = []
    for tree in trees:
        for node in tree.iterate():
            if isinstance(node, ThreadedAnnotator) and not node.stop_worker(max(0.0, deadline - time.monotonic())):
                left.append(node.name)
    return left


def has_workers(tree: py_trees.behaviour.Behaviour) -> bool:
    """True while a worker thread of a threaded annotator in ``tree`` is alive."""
    return any(isinstance(node, ThreadedAnnotator) and node.is_working() for node in tree.iterate())
