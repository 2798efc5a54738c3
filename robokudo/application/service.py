"""The answering service: one long-lived knowledge base, planner, belief store and engine that answer queries.

Everything that only changes with the ontology or the mission is made once and kept: the KnowledgeBase (its
reload picks up ontology edits), the QueryPlanner with its caches, the BeliefStore, and one Engine whose root
holds a task slot. Each query is parsed, planned and synthesized into a Pipeline that ends in the answer step;
the Pipeline goes into the task slot between ticks, and how it runs follows from the query's kind
(:data:`EXECUTION_MODES`): one-shot kinds run until the tree finishes and return one Answer; continuous kinds
run again and again, one Answer per run, until cancelled or until a run fails. One task runs at a time: a new
task replaces the one in the slot.

A query's ``timeout`` (``detect {obj: {type: Milk}, timeout: 2s}``) is a deadline counted from when the query
is received: when it passes before the tree finished, the tree is stopped (running experts are interrupted,
nothing of the unfinished run is fused) and the answer has ``timed_out`` set and holds the stored beliefs that
match the query (``from_memory``). A continuous task ends with the reason "timed out after ..." instead.
A query naming an object id (``inspect object 3``) is answered with that belief only; an id the store does not
hold raises :class:`UnknownObjectError` before anything runs, and for the built-in kitchen the camera looks at
the region where the object was last seen.

The CLI's ``robokudo query`` uses :meth:`AnsweringService.answer`; a server keeps one service for its lifetime.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from enum import Enum
from pathlib import Path
from types import MappingProxyType, TracebackType

import py_trees
from py_trees.common import Status

from annotators.catalog import AnnotatorCatalog
from queries import Number, Query, parse_query
from reasoning.beliefs.answer import Answer, answer_from_memory
from reasoning.beliefs.filters import belief_filter, kb_class_test
from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.tracking import BeliefTracker
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import QueryPlan, QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.planning import plan_for_input
from robokudo.core.composites import Sequence
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.slot import TaskSlot
from robokudo.core.threaded import has_workers, stop_workers
from robokudo.core.types import CameraIntrinsics, QueryAnswer
from trees.answer_step import AnswerStep
from trees.synthesis import build_tree

TASK_SLOT = "task"
"""The name of the engine's task slot."""

ANSWER_REASON = "fuses the hypotheses into the belief store and answers with the objects matching the query"


class ExecutionMode(Enum):
    """How a query's tree is executed."""

    ONCE = "once"
    """Tick until the tree finishes; its answer is the result."""
    CONTINUOUS = "continuous"
    """Run the tree again after each run; every run's answer is feedback, until cancelled or a run fails."""


EXECUTION_MODES: Mapping[str, ExecutionMode] = MappingProxyType(
    {
        "detect": ExecutionMode.ONCE,
        "inspect": ExecutionMode.ONCE,
        "scan": ExecutionMode.ONCE,
        "track": ExecutionMode.CONTINUOUS,
    }
)
"""Query kind -> execution mode: the one place that says which kinds end with one result. A ``stop`` query
plans no tree: it cancels the running task (:meth:`AnsweringService.cancel`)."""


TIMEOUT_KEY = "timeout"
"""The query key holding the answer's deadline in seconds (the parser converts units such as ``ms``)."""

WORKER_WAIT = 10.0
"""How long (seconds) :meth:`AnsweringService.close` waits for interrupted experts' worker threads to end."""


class PerceptionFailedError(Exception):
    """The tree ran but did not answer; the message names the experts that failed and why."""


class QueryCancelledError(Exception):
    """A one-shot query was stopped (its ``stop`` condition held) before its tree finished; nothing was fused."""


class UnknownObjectError(LookupError):
    """The query names an object id the belief store does not hold (``no object 999``)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "no such object"


@dataclass(frozen=True)
class Outcome:
    """The result of a one-shot query: the answer, and the tree that produced it (with its final statuses)."""

    answer: Answer
    tree: Pipeline
    plan: QueryPlan


class TaskHandle:
    """A continuous task in the engine: its answers as they come, and a way to cancel it.

    ``next_answer`` and ``answers`` block until the engine produced the next answer or the task ended;
    ``reason`` says why it ended (cancelled, replaced by another task, or the failure of a run).
    """

    def __init__(
        self,
        kind: str,
        tree: Pipeline,
        plan: QueryPlan,
        service: AnsweringService,
        *,
        timeout: float | None = None,
        started: float = 0.0,
    ) -> None:
        self.kind = kind
        self.tree = tree
        self.plan = plan
        self.timeout = timeout
        self._deadline = None if timeout is None else started + timeout
        self._service = service
        self._answers: queue.SimpleQueue[Answer | None] = queue.SimpleQueue()
        self._ended = threading.Event()
        self._reason = ""

    @property
    def done(self) -> bool:
        """True once the task ended."""
        return self._ended.is_set()

    @property
    def reason(self) -> str:
        """Why the task ended ("" while it runs)."""
        return self._reason

    def next_answer(self, timeout: float | None = None) -> Answer | None:
        """The next answer; None when the task ended (or nothing came within ``timeout`` seconds)."""
        try:
            return self._answers.get(timeout=timeout)
        except queue.Empty:
            return None

    def answers(self) -> Iterator[Answer]:
        """Every answer until the task ends."""
        while (answer := self.next_answer()) is not None:
            yield answer

    def cancel(self) -> None:
        """End the task (its running experts are interrupted); no-op when it already ended."""
        self._service.cancel(self)

    def _publish(self, answer: Answer) -> None:
        self._answers.put(answer)

    def _expired(self) -> bool:
        return self._deadline is not None and time.monotonic() >= self._deadline

    def _end(self, reason: str) -> None:
        if not self._ended.is_set():
            self._reason = reason
            self._ended.set()
            self._answers.put(None)


class AnsweringService:
    """Answers perception queries with one knowledge base, planner, belief store and engine (see the module)."""

    def __init__(
        self,
        kb: KnowledgeBase,
        store: BeliefStore,
        *,
        catalog: AnnotatorCatalog | None = None,
        input_path: str | None = None,
        frame: int = 0,
        hz: float = 100.0,
        intrinsics: CameraIntrinsics | None = None,
    ) -> None:
        self.kb = kb
        self.intrinsics = intrinsics
        self.store = store
        self.catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
        self.input_path = input_path
        self.frame = frame
        self.planner = QueryPlanner(kb)
        root = Sequence("robot", [TaskSlot(TASK_SLOT)], reason="the robot's perception: the current task")
        self.engine = Engine(root, hz=hz)
        self.engine.tree.add_post_tick_handler(self._after_tick)
        self._lock = threading.Lock()
        self._continuous: TaskHandle | None = None
        self._retired: list[py_trees.behaviour.Behaviour] = []

    @classmethod
    def open(
        cls,
        store_path: str | Path | None = None,
        *,
        input_path: str | None = None,
        frame: int = 0,
        hz: float = 100.0,
        catalog: AnnotatorCatalog | None = None,
        intrinsics: CameraIntrinsics | None = None,
    ) -> AnsweringService:
        """A service over the shipped and user ontology and the belief store at ``store_path`` (default store
        when None), with the annotators of ``catalog`` (default: this project's).

        The store is opened (and checked) first, so an unusable store raises BeliefStoreError before the
        knowledge base is loaded or anything runs.
        """
        store = BeliefStore(Path(store_path) if store_path is not None else BeliefStore.default_path())
        try:
            catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
            kb = load_knowledge_base(catalog=catalog)
        except BaseException:
            store.close()
            raise
        return cls(kb, store, catalog=catalog, input_path=input_path, frame=frame, hz=hz, intrinsics=intrinsics)

    # ------------------------------------------------------------------ planning

    def plan(self, query: str | Query) -> QueryPlan:
        """Interpret and plan ``query`` for this service's input (the kitchen camera looks at the query's region,
        else at the region of the object the query names by id)."""
        parsed = parse_query(query) if isinstance(query, str) else query
        look_at = None
        for object_id in self.object_ids(parsed) or ():
            known = self.store.get(object_id)
            look_at = known.region if known is not None and known.region else look_at
        return plan_for_input(
            self.planner, parsed, self.input_path, self.frame, look_at=look_at, intrinsics=self.intrinsics
        )

    def object_ids(self, query: Query) -> tuple[int, ...] | None:
        """The object ids ``query`` names (None when it names none); UnknownObjectError for an id not stored."""
        ids = belief_filter(query).ids
        for object_id in ids or ():
            if self.store.get(object_id) is None:
                raise UnknownObjectError(f"no object {object_id}")
        return ids

    def tree(self, query: Query, query_plan: QueryPlan) -> Pipeline:
        """The Pipeline answering ``query``: the synthesized experts, then the answer step into this store."""
        step = AnswerStep(
            self.store,
            tracker=BeliefTracker(class_test=kb_class_test(self.kb), regions=self.kb.regions()),
            filter_for=lambda q: belief_filter(q, self.kb),
            label_of=self.kb.label,
        )
        step.reason = ANSWER_REASON
        return build_tree(query_plan.plan, final_steps=[step], query=query, catalog=self.catalog)

    # ------------------------------------------------------------------ running

    def answer(self, query: str | Query, *, stop: Callable[[], bool] | None = None) -> Outcome:
        """Answer a one-shot query (detect, inspect, scan): plan, run once in the task slot, fuse, answer.

        ``stop`` is asked after every tick (on the calling thread); when it holds before the tree finished, the
        tree is stopped (running experts are interrupted, nothing is fused) and QueryCancelledError is raised.

        Raises QueryError / PlanningError / SynthesisError for a query that cannot be answered by any tree,
        ValueError for a continuous kind (use :meth:`start`), UnknownObjectError for an object id the store does
        not hold, PerceptionFailedError when the tree failed. When the query's timeout passes first, the answer
        is the stored beliefs matching the query, with ``timed_out`` set (see the module).
        """
        started = time.monotonic()
        parsed = parse_query(query) if isinstance(query, str) else query
        mode = self.mode_of(parsed)
        if mode is not ExecutionMode.ONCE:
            raise ValueError(f"a {parsed.kind} query runs continuously; start it with start() and read its answers")
        timeout = query_timeout(parsed)
        deadline = None if timeout is None else started + timeout
        self.object_ids(parsed)  # an id that is not stored is refused before anything runs
        query_plan = self.plan(parsed)
        pipeline = self.tree(parsed, query_plan)
        if self.engine.is_running_in_background():
            self._end_continuous("replaced by a one-shot query")
            self.engine.stop()

        def finished() -> bool:
            return pipeline.status in (Status.SUCCESS, Status.FAILURE)

        def expired() -> bool:
            return deadline is not None and time.monotonic() >= deadline

        def stopped() -> bool:
            return stop is not None and stop()

        # The finished tree stays in the slot (with its statuses, for explanations) until the next task.
        self._retire(self.engine.tasks.replace(TASK_SLOT, pipeline))
        if not expired():
            self.engine.run(until=lambda _: finished() or expired() or stopped())
        if not finished():
            self._retire(self.engine.tasks.remove(TASK_SLOT))  # stops the tree: running experts are interrupted
            if stopped():
                raise QueryCancelledError("stopped before the tree finished")
            return Outcome(self._remembered(parsed, timed_out=True), pipeline, query_plan)
        found = pipeline.cas.view(QueryAnswer) if pipeline.status is Status.SUCCESS else None
        if found is None or not isinstance(found.answer, Answer):
            raise PerceptionFailedError(f"perception failed: {failure_reason(pipeline)}")
        return Outcome(found.answer, pipeline, query_plan)

    def recall(self, query: str | Query) -> Answer:
        """The stored beliefs matching ``query``, answered from memory (nothing runs)."""
        return self._remembered(parse_query(query) if isinstance(query, str) else query)

    def _remembered(self, query: Query, *, timed_out: bool = False) -> Answer:
        """The stored beliefs matching ``query``, as an answer from memory."""
        answer = answer_from_memory(self.store, belief_filter(query, self.kb), query.source, label_of=self.kb.label)
        return replace(answer, timed_out=timed_out)

    def start(self, query: str | Query) -> TaskHandle:
        """Start a continuous query (track): the engine ticks in the background and every run of the tree
        yields an answer on the returned handle until it is cancelled or a run fails."""
        started = time.monotonic()
        parsed = parse_query(query) if isinstance(query, str) else query
        if self.mode_of(parsed) is not ExecutionMode.CONTINUOUS:
            raise ValueError(f"a {parsed.kind} query ends with one answer; ask it with answer()")
        self.object_ids(parsed)  # an id that is not stored is refused before anything runs
        query_plan = self.plan(parsed)
        pipeline = self.tree(parsed, query_plan)
        handle = TaskHandle(parsed.kind, pipeline, query_plan, self, timeout=query_timeout(parsed), started=started)
        repeat = py_trees.decorators.Repeat(f"every run of {pipeline.name}", pipeline, num_success=-1)
        self._end_continuous("replaced by another task")
        with self._lock:
            self._continuous = handle
        self._retire(self.engine.tasks.replace(TASK_SLOT, repeat))
        if not self.engine.is_running_in_background():
            self.engine.start()
        return handle

    def cancel(self, handle: TaskHandle | None = None) -> None:
        """Cancel the running continuous task (``handle``, or whichever runs); its experts are interrupted."""
        with self._lock:
            current = self._continuous
        if current is None or (handle is not None and handle is not current):
            return
        self._end_continuous("cancelled")
        if self.engine.is_running_in_background():
            self.engine.stop()
        self._retire(self.engine.tasks.remove(TASK_SLOT))

    @staticmethod
    def mode_of(query: Query) -> ExecutionMode:
        """How a query of this kind runs (ValueError for ``stop``, which plans nothing)."""
        try:
            return EXECUTION_MODES[query.kind]
        except KeyError:
            raise ValueError(f"a {query.kind} query plans no perception tree") from None

    def close(self) -> None:
        """Stop the engine (ending any continuous task), wait for interrupted experts' worker threads to end
        (up to :data:`WORKER_WAIT` s) and close the belief store."""
        self._end_continuous("the service closed")
        try:
            self.engine.stop()
            with self._lock:
                retired, self._retired = self._retired, []
            stop_workers([self.engine.root, *retired], WORKER_WAIT)
        finally:
            self.store.close()

    def __enter__(self) -> AnsweringService:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.close()

    # ------------------------------------------------------------------ engine side

    def _after_tick(self, _: py_trees.trees.BehaviourTree) -> None:
        """After every tick (engine thread): hand a finished run's answer to the continuous task's handle."""
        with self._lock:
            handle = self._continuous
        if handle is None or handle.done:
            return
        pipeline = handle.tree
        if pipeline.status is Status.SUCCESS:
            found = pipeline.cas.view(QueryAnswer)
            if found is not None and isinstance(found.answer, Answer):
                handle._publish(found.answer)
        failed = pipeline.status is Status.FAILURE
        if failed or handle._expired():
            why = f"a run failed: {failure_reason(pipeline)}" if failed else f"timed out after {handle.timeout:g} s"
            handle._end(why)
            with self._lock:
                self._continuous = None
            # Between two ticks on the engine thread, the slot may be emptied directly (as the engine does).
            self._retire(self.engine.tasks.slot(TASK_SLOT).set_subtree(None))

    def _retire(self, tree: py_trees.behaviour.Behaviour | None) -> None:
        """Remember a tree taken out of the slot while its experts' worker threads finish (:meth:`close` waits)."""
        if tree is None:
            return
        with self._lock:
            self._retired = [t for t in self._retired if has_workers(t)]
            if has_workers(tree):
                self._retired.append(tree)

    def _end_continuous(self, reason: str) -> None:
        with self._lock:
            handle, self._continuous = self._continuous, None
        if handle is not None:
            handle._end(reason)


def query_timeout(query: Query) -> float | None:
    """The query's ``timeout`` in seconds (None when it sets none)."""
    value = query.get(TIMEOUT_KEY)
    return float(value.value) if isinstance(value, Number) else None


def failure_reason(tree: py_trees.behaviour.Behaviour) -> str:
    """The failed nodes of ``tree`` with their messages, or a note that the tree did not finish."""
    failed = [n for n in tree.iterate() if n.status is Status.FAILURE and n.feedback_message]
    return "; ".join(f"{n.name}: {n.feedback_message}" for n in failed) or "the tree did not finish"
