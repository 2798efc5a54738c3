"""The query action's goals and the one worker thread that owns the answering service and runs them.

Every goal ends with exactly one terminal result (succeeded, canceled or aborted), sent through the goal's
``send`` callable (thread-safe; the session hands it to its event loop). A new goal preempts every goal submitted
before it that has not ended (they end canceled, naming the new goal). Cancelling a goal that waits in the queue
ends it at once; a running one-shot tree is stopped after the current tick (:meth:`AnsweringService.answer`'s
``stop``), a continuous task is cancelled. Quick jobs (plan, beliefs) run on the worker thread too, between two
ticks of a running goal, so the knowledge base, planner and store are only ever used from that thread.
"""

from __future__ import annotations

import gc
import itertools
import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

from queries import Query, format_query, parse_query
from robokudo.application.server.protocol import GoalStatus, action_feedback, action_result
from robokudo.application.service import AnsweringService, ExecutionMode, QueryCancelledError, TickProgress

Send = Callable[[dict[str, Any]], None]

STOP_KIND = "stop"
"""The query kind that plans nothing: a ``stop`` goal ends every goal submitted before it and succeeds."""

POLL_SECONDS = 0.05
"""How often a continuous goal's worker looks for cancellation and jobs between answers."""


class Goal:
    """One goal of the query action: its id, query text, owner (the session that sent it) and terminal state."""

    def __init__(self, goal_id: str, query: str | Query, owner: object, send: Send) -> None:
        self.id = goal_id
        self.query = query
        self.owner = owner
        self._send = send
        self._lock = threading.Lock()
        self._stop: tuple[int, str] | None = None
        self._ended = False

    @property
    def ended(self) -> bool:
        """True once the terminal result was sent."""
        with self._lock:
            return self._ended

    def stop_requested(self) -> tuple[int, str] | None:
        """The status and reason the goal is to end with, once cancelled, preempted or aborted (else None)."""
        with self._lock:
            return self._stop

    def request_stop(self, goal_status: int, reason: str) -> None:
        """Ask the goal to end with ``goal_status`` and ``reason`` (the first request wins)."""
        with self._lock:
            if self._stop is None and not self._ended:
                self._stop = (goal_status, reason)

    def feedback(self, values: dict[str, Any]) -> None:
        """Send feedback unless the goal ended (never after its result: both are sent under the goal's lock)."""
        with self._lock:
            if not self._ended:
                self._send(action_feedback(self.id, values))

    def progress(self, tick: TickProgress) -> None:
        """Feedback for a tick that ran the goal's tree: the tick's number and the leaves still running."""
        self.feedback({"phase": "running", "running": list(tick.running), "tick": tick.tick})

    def finish(self, goal_status: int, values: dict[str, Any]) -> bool:
        """Send the terminal result; False (nothing sent) when the goal had already ended."""
        with self._lock:
            if self._ended:
                return False
            self._ended = True
            self._send(action_result(self.id, goal_status, values))
        return True

    def finish_stopped(self) -> bool:
        """End with the requested stop's status and reason."""
        goal_status, reason = self.stop_requested() or (GoalStatus.CANCELED, "cancelled")
        return self.finish(goal_status, {"reason": reason})


class _Job:
    def __init__(self, work: Callable[[AnsweringService], Any]) -> None:
        self.work = work
        self.future: Future[Any] = Future()

    def run(self, service: AnsweringService) -> None:
        if not self.future.set_running_or_notify_cancel():
            return
        try:
            self.future.set_result(self.work(service))
        except Exception as error:  # the caller gets the error with its message
            self.future.set_exception(error)


_CLOSE = object()


class GoalManager:
    """Runs goals and jobs on one worker thread that owns ``service`` (see the module)."""

    def __init__(self, service: AnsweringService, *, collect_after_goals: bool = False) -> None:
        """``collect_after_goals``: run the garbage collector after every goal (see
        :func:`~robokudo.application.server.runner.keep_startup_objects_out_of_collections`; cheap only then)."""
        self.service = service
        self._collect_after_goals = collect_after_goals
        self._queue: queue.SimpleQueue[Goal | _Job | object] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._open: list[Goal] = []
        self._closing: str | None = None
        self._numbers = itertools.count(1)
        self._thread = threading.Thread(target=self._work, name="robokudo-goals", daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ any thread

    def submit(self, goal: Goal) -> None:
        """Queue ``goal``; every earlier goal that has not ended is preempted."""
        with self._lock:
            if self._closing is not None:
                reason = self._closing
            else:
                reason = None
                earlier, self._open = [g for g in self._open if not g.ended], []
                self._open = [*earlier, goal]
        if reason is not None:
            goal.finish(GoalStatus.ABORTED, {"reason": reason})
            return
        for old in earlier:
            old.request_stop(GoalStatus.CANCELED, f"preempted by goal {goal.id}")
        self._queue.put(goal)

    def cancel(self, goal_id: str, owner: object, reason: str = "cancelled by the client") -> bool:
        """Cancel the goal ``goal_id`` of ``owner``; False when it has no such open goal."""
        goals = self._goals(lambda g: g.id == goal_id and g.owner is owner)
        for goal in goals:
            goal.request_stop(GoalStatus.CANCELED, reason)
        return bool(goals)

    def cancel_owner(self, owner: object, reason: str) -> None:
        """Cancel every open goal of ``owner`` (its connection closed)."""
        for goal in self._goals(lambda g: g.owner is owner):
            goal.request_stop(GoalStatus.CANCELED, reason)

    def open_goals(self, owner: object) -> int:
        """How many goals of ``owner`` have not ended."""
        return len(self._goals(lambda g: g.owner is owner))

    def call(self, work: Callable[[AnsweringService], Any]) -> Future[Any]:
        """Run ``work(service)`` on the worker thread (between ticks when a goal runs); its future result."""
        job = _Job(work)
        self._queue.put(job)
        return job.future

    def close(self, reason: str, timeout: float | None = None) -> None:
        """Abort every open goal with ``reason``, stop the worker and close the service (its store)."""
        with self._lock:
            self._closing = reason
            goals, self._open = self._open, []
        for goal in goals:
            goal.request_stop(GoalStatus.ABORTED, reason)
        self._queue.put(_CLOSE)
        self._thread.join(timeout)
        self.service.close()

    def _goals(self, test: Callable[[Goal], bool]) -> list[Goal]:
        with self._lock:
            self._open = [g for g in self._open if not g.ended]
            return [g for g in self._open if test(g)]

    # ------------------------------------------------------------------ worker thread

    def _work(self) -> None:
        while True:
            item = self._queue.get()
            if item is _CLOSE:
                self._drain(final=True)
                return
            if isinstance(item, _Job):
                item.run(self.service)
            elif isinstance(item, Goal):
                self._run(item)
                if self._collect_after_goals:
                    gc.collect()  # the goal's tree is a reference cycle holding its frames: free them now

    def _drain(self, *, final: bool = False) -> None:
        """Run the queued jobs; queued goals are only looked at to end the stopped ones (they wait their turn)."""
        waiting: list[object] = []
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                break
            if isinstance(item, _Job):
                item.run(self.service)
            elif isinstance(item, Goal) and (final or item.stop_requested() is not None):
                if item.stop_requested() is None:
                    item.request_stop(GoalStatus.ABORTED, self._closing or "the server closed")
                item.finish_stopped()
            else:
                waiting.append(item)
        for item in waiting:
            self._queue.put(item)

    def _run(self, goal: Goal) -> None:
        if goal.stop_requested() is not None:
            goal.finish_stopped()
            return
        goal.feedback({"phase": "planning", "running": []})
        try:
            query = parse_query(goal.query) if isinstance(goal.query, str) else goal.query
            if query.kind == STOP_KIND:  # submitting it already preempted every earlier goal
                goal.finish(GoalStatus.SUCCEEDED, {"query": format_query(query), "objects": []})
                return
            mode = self.service.mode_of(query)
            if mode is ExecutionMode.CONTINUOUS:
                self._run_continuous(goal)
                return
            outcome = self.service.answer(goal.query, stop=lambda: self._between_ticks(goal), on_tick=goal.progress)
        except QueryCancelledError:
            goal.finish_stopped()
            return
        except Exception as error:  # any failure of this goal (bad query, plan, expert crash) aborts only it
            goal.finish(GoalStatus.ABORTED, {"reason": str(error) or type(error).__name__})
            return
        if goal.stop_requested() is not None:
            goal.finish_stopped()
        else:
            goal.finish(GoalStatus.SUCCEEDED, {**outcome.answer.to_dict(), "timing": dict(outcome.timing)})

    def _run_continuous(self, goal: Goal) -> None:
        handle = self.service.start(goal.query, on_tick=goal.progress)
        try:
            while True:
                answer = handle.next_answer(timeout=POLL_SECONDS)
                if answer is not None:
                    goal.feedback({"phase": "answer", "running": [], "answer": answer.to_dict()})
                if self._between_ticks(goal):
                    handle.cancel()
                    goal.finish_stopped()
                    return
                if handle.done and answer is None:
                    goal.finish(GoalStatus.ABORTED, {"reason": handle.reason})
                    return
        finally:
            handle.cancel()

    def _between_ticks(self, goal: Goal) -> bool:
        """Run waiting jobs; True when the goal is to stop."""
        self._drain()
        return goal.stop_requested() is not None
