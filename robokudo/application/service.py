"""The answering service: one long-lived knowledge base, planner, belief store and engine that answer queries.

Everything that only changes with the ontology or the mission is made once and kept: the KnowledgeBase (its
reload picks up ontology edits), the QueryPlanner with its caches, the BeliefStore, and one Engine whose root
holds a task slot. Each query is parsed, planned and synthesized into a Pipeline that ends in the answer step;
the Pipeline goes into the task slot between ticks, and how it runs follows from the query's kind
(:data:`EXECUTION_MODES`): a one-shot task runs until its tree finishes and has one Answer; a continuous task's
tree is a Loop (the paper's ↻) around the Pipeline that analyses one frame, one Answer per successful run, until
it is cancelled or its target is lost: not seen for longer than the query's ``lost_after`` (``track { human: {},
lost_after: 2s }``) or the service's default (:data:`DEFAULT_LOST_AFTER`), which ends it with the reason
"target lost: ... not seen for X s" (:mod:`robokudo.application.target_watch`). One task runs at a
time: a new task replaces the one in the slot. Without a task the slot holds an idle subtree.

Over a live stream (``stream=``, as ``robokudo serve`` runs it) the root is the paper's Fig. 4 shape: a perceive
pipeline reads the stream's newest frame, then the task slot; the engine ticks at its fixed rate in the
background for the service's lifetime (:meth:`AnsweringService.run_in_background`), every task starts on a freshly
perceived frame (:class:`~annotators.readers.streams.PerceivedFrameReader` is its first step), and the kitchen
camera is pointed at the task's region (at the table and the person behind it for a query about a person, when the
kitchen holds one). When perception fails (the source ended, a frame cannot be read) the
running task ends with that reason; once the source ended, new tasks are refused with it
(:class:`SourceEndedError`). Without a stream (``robokudo query``), each task's tree reads its own frame and the
engine ticks on the calling thread while :meth:`AnsweringService.answer` waits.

A query's ``timeout`` (``detect {obj: {type: Milk}, timeout: 2s}``) is a deadline counted from when the query
is received: when it passes before the tree finished, the tree is stopped (running experts are interrupted,
nothing of the unfinished run is fused) and the answer has ``timed_out`` set and holds the stored beliefs that
match the query (``from_memory``). A continuous task ends with the reason "timed out after ..." instead.
The knowledge base is reloaded before a query is planned when an ontology file changed since (one ``stat`` per file),
so an ontology edit (``robokudo ontology add-object``, from any process) is seen by the next query without a
restart. A query naming an object id (``inspect object 3``) is answered with that belief only; an id the store does not
hold raises :class:`UnknownObjectError` before anything runs, and for the built-in kitchen the camera looks at
the region where the object was last seen.

The CLI's ``robokudo query`` uses :meth:`AnsweringService.answer`; a server keeps one service for its lifetime.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable, Collection, Iterator, Mapping
from dataclasses import dataclass, field, replace
from enum import Enum
from pathlib import Path
from types import MappingProxyType, TracebackType

import py_trees
from py_trees.common import Status

from annotators.catalog import AnnotatorCatalog
from annotators.readers.streams import PERCEPTION_PIPELINE, FrameStream, KitchenCameraStream, StreamReader
from queries import CONTINUOUS_KINDS, LOST_AFTER_KEY, Number, Query, parse_query
from reasoning.beliefs.answer import Answer, answer_from_memory
from reasoning.beliefs.filters import belief_filter, kb_class_test, searched_only
from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.tracking import BeliefTracker, TrackStep
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.focus import object_focus
from reasoning.planning.query_planner import QueryPlan, QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.planning import plan_for_input
from robokudo.application.sensor_sources import kitchen_view_for, served_source
from robokudo.application.target_watch import TargetWatch
from robokudo.core.composites import Sequence
from robokudo.core.engine import Engine
from robokudo.core.loop import Loop, frame_pipeline
from robokudo.core.pipeline import Pipeline
from robokudo.core.placement import Placement
from robokudo.core.regions import RegionBox
from robokudo.core.remote import place_remote
from robokudo.core.resources import SharedResources
from robokudo.core.slot import Idle, PerceiveThenTask, TaskSlot
from robokudo.core.structure import running_leaves
from robokudo.core.threaded import has_workers, stop_workers
from robokudo.core.types import (
    PERSON_CLASS,
    CameraInfo,
    CameraIntrinsics,
    ObjectHypothesis,
    PersonHypothesis,
    QueryAnswer,
)
from trees.answer_step import AnswerStep
from trees.synthesis import build_task_tree

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
        kind: ExecutionMode.CONTINUOUS if kind in CONTINUOUS_KINDS else ExecutionMode.ONCE
        for kind in ("detect", "inspect", "scan", "track")
    }
)
"""Query kind -> execution mode (continuous for ``queries.CONTINUOUS_KINDS``, whose trees synthesis builds as a
Loop). A ``stop`` query plans no tree: it cancels the running task (:meth:`AnsweringService.cancel`)."""

DEFAULT_LOST_AFTER = 5.0
"""How long (seconds) a continuous task's target may go unseen when neither the query nor the service says."""


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
    timing: Mapping[str, float] = field(default_factory=dict)
    """Where the time went (:meth:`TaskHandle.timing`)."""


@dataclass(frozen=True)
class TickProgress:
    """What one tick did to a running task: the tick's number and the task's leaves still running after it."""

    tick: int
    running: tuple[str, ...]


class TaskHandle:
    """A task in the engine: its answers as they come (continuous) or its one answer (one-shot), and a way to
    cancel it.

    ``next_answer`` and ``answers`` block until the engine produced the next answer or the task ended;
    ``reason`` says why it ended (finished, cancelled, replaced by another task, timed out, or a failure).
    """

    def __init__(
        self,
        query: Query,
        mode: ExecutionMode,
        tree: Pipeline | Loop,
        plan: QueryPlan,
        service: AnsweringService,
        *,
        timeout: float | None = None,
        started: float = 0.0,
        watch: TargetWatch | None = None,
    ) -> None:
        self.query = query
        self.kind = query.kind
        self.mode = mode
        self.tree = tree
        """The task's tree: a one-shot task's Pipeline, or a continuous task's Loop around its frame Pipeline."""
        self.plan = plan
        self.timeout = timeout
        self.watch = watch
        """When a continuous task's target counts as lost (None for a one-shot task)."""
        self.runs = 0
        """Finished runs of a continuous task's loop seen so far."""
        self.last_failure = ""
        """Why the last run of a continuous task that analysed a frame failed ("" when none failed)."""
        self._deadline = None if timeout is None else started + timeout
        self._service = service
        self._answers: queue.SimpleQueue[Answer | None] = queue.SimpleQueue()
        self._tick_listener: Callable[[TickProgress], None] | None = None
        self._ended = threading.Event()
        self._reason = ""
        self._result: Answer | None = None
        self._timed_out = False
        self.submitted = started
        """When the query was received (``time.monotonic``)."""
        self.planned = started
        """When its tree was planned and built (set by the service)."""
        self.first_tick: float | None = None
        """When the first tick that ran its tree began (None before)."""
        self.ended_at: float | None = None
        """When the task ended (None while it runs)."""

    @property
    def pipeline(self) -> Pipeline:
        """The Pipeline that analyses one frame (the tree itself for a one-shot task)."""
        found = frame_pipeline(self.tree)
        if found is None:
            raise TypeError(f"the task's tree {self.tree.name!r} holds no frame Pipeline")
        return found

    @property
    def done(self) -> bool:
        """True once the task ended."""
        return self._ended.is_set()

    @property
    def reason(self) -> str:
        """Why the task ended ("" while it runs)."""
        return self._reason

    @property
    def result(self) -> Answer | None:
        """A one-shot task's answer once its tree succeeded (None before, and when it did not)."""
        return self._result

    @property
    def timed_out(self) -> bool:
        """True when the task ended because its timeout passed."""
        return self._timed_out

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the task ended (at most ``timeout`` seconds); True when it has."""
        return self._ended.wait(timeout)

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

    def on_tick(self, listener: Callable[[TickProgress], None] | None) -> None:
        """Have ``listener`` called after every tick that ran this task's tree, with that tick's progress (on the
        engine thread, so it must be quick; None removes it)."""
        self._tick_listener = listener

    def timing(self) -> dict[str, float]:
        """Where the time went, in milliseconds: ``plan_ms`` (parse, plan, build), ``wait_ms`` (until a tick first ran
        the tree: the swap and the wait for a fresh frame), ``run_ms`` (from that tick to the end); the parts known
        so far."""
        parts = {"plan_ms": self.planned - self.submitted}
        if self.first_tick is not None:
            parts["wait_ms"] = self.first_tick - self.planned
            if self.ended_at is not None:
                parts["run_ms"] = self.ended_at - self.first_tick
        return {name: round(seconds * 1e3, 3) for name, seconds in parts.items()}

    def _publish(self, answer: Answer) -> None:
        self._answers.put(answer)

    def _ticked(self, tick: int) -> None:
        listener = self._tick_listener
        if listener is not None:
            listener(TickProgress(tick, tuple(running_leaves(self.tree))))

    def _expired(self) -> bool:
        return self._deadline is not None and time.monotonic() >= self._deadline

    def _end(self, reason: str, *, result: Answer | None = None, timed_out: bool = False) -> bool:
        """End the task once (False when it had ended already)."""
        if self._ended.is_set():
            return False
        self._reason = reason
        self._result = result
        self._timed_out = timed_out
        self.ended_at = time.monotonic()
        self._ended.set()
        self._answers.put(None)
        return True


class SourceEndedError(Exception):
    """The live source ended (a recording played once reached its end): no task can perceive any more."""


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
        stream: FrameStream | None = None,
        remote: Collection[str] = (),
        remote_hints: Placement | None = None,
        lost_after: float = DEFAULT_LOST_AFTER,
        person: str | None = None,
    ) -> None:
        TargetWatch(lost_after)  # checks the default now rather than at the first continuous task
        self.lost_after = lost_after
        """How long (seconds) a continuous task's target may go unseen when its query does not say."""
        self.kb = kb
        self.intrinsics = intrinsics
        self.person = person
        """A person put into the built-in kitchen (a ``kitchen_person`` spec), None for none."""
        self.store = store
        self.catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
        self.input_path = input_path
        self.frame = frame
        self.stream = stream
        self.planner = QueryPlanner(kb)
        self.resources = SharedResources()
        """Loaded models shared by every task's tree (the first task loads them), and remote experts' actors."""
        self.remote = frozenset(remote)
        """Annotators (class names) every task's tree runs on Ray actors, besides those whose class says so."""
        self.remote_hints = remote_hints
        self._idle = Idle(reason="no task: the engine keeps perceiving until the next one")
        self._slot = TaskSlot(TASK_SLOT)
        self._slot.set_subtree(self._idle)
        self._reader: StreamReader | None = None
        self._perception: Pipeline | None = None
        if stream is None:
            root = Sequence("robot", [self._slot], reason="the robot's perception: the current task")
        else:
            self._reader = StreamReader(stream, wait=False, name="read frame")
            self._reader.reason = f"reads the newest frame of {stream.name}"
            self._perception = Pipeline(PERCEPTION_PIPELINE, [self._reader], reason="perceives: the newest frame")
            root = PerceiveThenTask(
                "robot", self._perception, self._slot, reason="perceive every frame, then the current task"
            )
        self.engine = Engine(root, hz=hz)
        self.engine.tree.add_post_tick_handler(self._after_tick)
        self._lock = threading.Lock()
        self._current: TaskHandle | None = None
        self._retired: list[py_trees.behaviour.Behaviour] = []
        self._source_ended: str | None = None
        self._belief_listeners: list[Callable[[TrackStep], None]] = []

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
        stream: FrameStream | None = None,
        remote: Collection[str] = (),
        remote_hints: Placement | None = None,
        lost_after: float = DEFAULT_LOST_AFTER,
        person: str | None = None,
        write_behind: int = 0,
    ) -> AnsweringService:
        """A service over the shipped and user ontology and the belief store at ``store_path`` (default store
        when None), with the annotators of ``catalog`` (default: this project's); the annotators named in
        ``remote`` run on Ray actors (with ``remote_hints``, default their classes' placement hints).
        ``write_behind`` frames may be fused before their commit (the store's writer process; 0: each frame is
        committed before the next is fused).

        The store is opened (and checked) first, so an unusable store raises BeliefStoreError before the
        knowledge base is loaded or anything runs.
        """
        path = Path(store_path) if store_path is not None else BeliefStore.default_path()
        store = BeliefStore(path, write_behind=write_behind)
        try:
            catalog = catalog if catalog is not None else AnnotatorCatalog.discover()
            kb = load_knowledge_base(catalog=catalog)
        except BaseException:
            store.close()
            raise
        return cls(
            kb,
            store,
            catalog=catalog,
            input_path=input_path,
            frame=frame,
            hz=hz,
            stream=stream,
            intrinsics=intrinsics,
            remote=remote,
            remote_hints=remote_hints,
            lost_after=lost_after,
            person=person,
        )

    # ------------------------------------------------------------------ planning

    def plan(self, query: str | Query) -> QueryPlan:
        """Interpret and plan ``query`` for this service's input (the kitchen camera looks at the query's region,
        else at the region of the object the query names by id; an ``inspect`` of one object by id searches only
        the box around where that object is believed to be)."""
        self.kb.reload_if_changed()
        parsed = parse_query(query) if isinstance(query, str) else query
        focus = self._focus(parsed)
        if self.stream is not None:
            return self.planner.plan(parsed, served_source(self.kb, self.stream), focus)
        return plan_for_input(
            self.planner,
            parsed,
            self.input_path,
            self.frame,
            look_at=self._remembered_region(parsed),
            intrinsics=self.intrinsics,
            person=self.person,
            focus=focus,
        )

    def _focus(self, query: Query) -> RegionBox | None:
        """The box around the one object an ``inspect`` query names by id, where the store believes it is (None
        for other queries, and when the belief is not in the world frame)."""
        ids = belief_filter(query).ids if query.kind == "inspect" else None
        if not ids or len(ids) != 1:
            return None
        known = self.store.get(ids[0])
        if known is None:
            return None
        return object_focus(known.id, known.position, known.dimensions, known.frame)

    def _remembered_region(self, query: Query) -> str | None:
        """Where the last object the query names by id was last seen (None when it names none, or no region)."""
        region = None
        for object_id in self.object_ids(query) or ():
            known = self.store.get(object_id)
            region = known.region if known is not None and known.region else region
        return region

    def object_ids(self, query: Query) -> tuple[int, ...] | None:
        """The object ids ``query`` names (None when it names none); UnknownObjectError for an id not stored."""
        ids = belief_filter(query).ids
        for object_id in ids or ():
            if self.store.get(object_id) is None:
                raise UnknownObjectError(f"no object {object_id}")
        return ids

    def tree(self, query: Query, query_plan: QueryPlan) -> Pipeline | Loop:
        """The tree answering ``query``: the synthesized experts (those to run remotely placed on their actors),
        then the answer step into this store (a Pipeline; for a continuous kind that Pipeline in a Loop,
        :func:`trees.synthesis.build_task_tree`)."""
        step = AnswerStep(
            self.store,
            tracker=BeliefTracker(class_test=kb_class_test(self.kb), regions=self.kb.regions()),
            filter_for=lambda q: searched_only(belief_filter(q, self.kb), query_plan.plan.task.region),
            label_of=self.kb.label,
            on_integrated=self._beliefs_changed,
            free_space=query_plan.plan.task.footprint is not None,
            looks_for=self._looked_for(query_plan),
        )
        step.reason = ANSWER_REASON
        tree = build_task_tree(
            query_plan.plan, final_steps=[step], query=query, catalog=self.catalog, resources=self.resources
        )
        place_remote(tree, self.remote, self.remote_hints)
        return tree

    def _looked_for(self, query_plan: QueryPlan) -> Callable[[str], bool] | None:
        """The stored classes the plan's detectors report: people only, everything but people, or (None) both."""
        outputs = {output for step in query_plan.plan.steps() for output in step.outputs}
        finds_people, finds_objects = PersonHypothesis.__name__ in outputs, ObjectHypothesis.__name__ in outputs
        if finds_people == finds_objects:
            return None
        class_test = kb_class_test(self.kb)  # names it does not know ("" for no class) are no person
        if class_test is None:
            return None

        def is_person(name: str) -> bool:
            return class_test(name, PERSON_CLASS)

        return is_person if finds_people else lambda name: not is_person(name)

    # ------------------------------------------------------------------ running

    def submit(self, query: str | Query, *, on_tick: Callable[[TickProgress], None] | None = None) -> TaskHandle:
        """Plan ``query`` and put its tree into the task slot (replacing the running task); its handle.
        ``on_tick`` is the handle's tick listener from the first tick on (:meth:`TaskHandle.on_tick`).

        Raises QueryError / PlanningError / SynthesisError for a query no tree can answer, ValueError for a
        ``stop`` query, UnknownObjectError for an object id the store does not hold, SourceEndedError once the
        live source ended. Nothing changes in the engine when it raises.
        """
        started = time.monotonic()
        self.kb.reload_if_changed()  # an ontology edit made meanwhile (CLI, another process) counts at once
        parsed = parse_query(query) if isinstance(query, str) else query
        mode = self.mode_of(parsed)
        if self._source_ended is not None:
            raise SourceEndedError(self._source_ended)
        self.object_ids(parsed)  # an id that is not stored is refused before anything runs
        query_plan = self.plan(parsed)
        pipeline = self.tree(parsed, query_plan)
        watch = None
        if mode is ExecutionMode.CONTINUOUS:
            lost_after = query_duration(parsed, LOST_AFTER_KEY)
            watch = TargetWatch(self.lost_after if lost_after is None else lost_after, self.target_label(query_plan))
        handle = TaskHandle(
            parsed, mode, pipeline, query_plan, self, timeout=query_timeout(parsed), started=started, watch=watch
        )
        handle.planned = time.monotonic()
        handle.on_tick(on_tick)
        if isinstance(self.stream, KitchenCameraStream):
            region = query_plan.interpretation.task.region or self._remembered_region(parsed)
            task = query_plan.plan.task
            people = self.stream.person is not None and (task.pointing is not None or task.object_class == PERSON_CLASS)
            self.stream.set_view(kitchen_view_for(region, people=people))
        with self._lock:
            previous, self._current = self._current, handle
        if previous is not None:
            previous._end("replaced by another task")
        self._retire(self.engine.tasks.replace(TASK_SLOT, pipeline, restart=True))
        return handle

    def target_label(self, query_plan: QueryPlan) -> str:
        """How a reason names the query's target: ``the blue cup``, ``the human``, ``the object``."""
        task = query_plan.plan.task
        words = [c.value.lower() for c in task.constraints if c.annotation_type != "Classification" and c.value]
        words.append(self.kb.label(task.object_class) if task.object_class else "object")
        return "the " + " ".join(words)

    def answer(
        self,
        query: str | Query,
        *,
        stop: Callable[[], bool] | None = None,
        on_tick: Callable[[TickProgress], None] | None = None,
    ) -> Outcome:
        """Answer a one-shot query (detect, inspect, scan): plan, run once in the task slot, fuse, answer.

        ``stop`` is asked after every tick period (on the calling thread); when it holds before the tree finished,
        the tree is stopped (running experts are interrupted, nothing is fused) and QueryCancelledError is raised.
        ``on_tick`` hears every tick that ran the task (:meth:`TaskHandle.on_tick`). When the engine ticks in the
        background (a served instance) this waits for the task; otherwise the engine ticks on the calling thread
        until the task ended.

        Raises what :meth:`submit` raises, ValueError for a continuous kind (use :meth:`start`),
        PerceptionFailedError when the tree failed. When the query's timeout passes first, the answer is the
        stored beliefs matching the query, with ``timed_out`` set (see the module).
        """
        started = time.monotonic()
        parsed = parse_query(query) if isinstance(query, str) else query
        if self.mode_of(parsed) is not ExecutionMode.ONCE:
            raise ValueError(f"a {parsed.kind} query runs continuously; start it with start() and read its answers")
        timeout = query_timeout(parsed)
        handle = self.submit(parsed, on_tick=on_tick)
        if timeout is not None and time.monotonic() - started >= timeout:
            self.cancel(handle)  # the deadline passed while planning: answer from memory without running
            return Outcome(self._remembered(parsed, timed_out=True), handle.pipeline, handle.plan)

        def stopped() -> bool:
            return stop is not None and stop()

        if self.engine.is_running_in_background():
            while not handle.wait(1.0 / self.engine.hz):
                if stopped():
                    break
        else:
            self.engine.run(until=lambda _: handle.done or stopped())
            self.engine.tasks.apply_pending()  # the finished tree leaves the slot now, not at the next tick
        if not handle.done:
            self.cancel(handle)
            raise QueryCancelledError("stopped before the tree finished")
        if handle.timed_out:
            return Outcome(self._remembered(parsed, timed_out=True), handle.pipeline, handle.plan, handle.timing())
        if handle.result is None:
            raise PerceptionFailedError(f"perception failed: {handle.reason}")
        return Outcome(handle.result, handle.pipeline, handle.plan, handle.timing())

    def recall(self, query: str | Query) -> Answer:
        """The stored beliefs matching ``query``, answered from memory (nothing runs)."""
        self.kb.reload_if_changed()
        return self._remembered(parse_query(query) if isinstance(query, str) else query)

    def _remembered(self, query: Query, *, timed_out: bool = False) -> Answer:
        """The stored beliefs matching ``query``, as an answer from memory."""
        answer = answer_from_memory(
            self.store, belief_filter(query, self.kb), query.source, counted=query.counted, label_of=self.kb.label
        )
        return replace(answer, timed_out=timed_out)

    def start(self, query: str | Query, *, on_tick: Callable[[TickProgress], None] | None = None) -> TaskHandle:
        """Start a continuous query (track): the engine ticks in the background and every successful run of the
        tree's loop yields an answer on the returned handle until it is cancelled or its target is lost; ``on_tick``
        hears every tick that ran it (:meth:`TaskHandle.on_tick`)."""
        parsed = parse_query(query) if isinstance(query, str) else query
        if self.mode_of(parsed) is not ExecutionMode.CONTINUOUS:
            raise ValueError(f"a {parsed.kind} query ends with one answer; ask it with answer()")
        handle = self.submit(parsed, on_tick=on_tick)
        self.run_in_background()
        return handle

    def run_in_background(self) -> None:
        """Tick the engine at its rate on its own thread until :meth:`close` (no-op when it already does)."""
        if not self.engine.is_running_in_background():
            self.engine.start()

    def cancel(self, handle: TaskHandle | None = None) -> None:
        """Cancel the running task (``handle``, or whichever runs); its experts are interrupted and the slot
        becomes idle."""
        with self._lock:
            current = self._current
            if current is None or (handle is not None and handle is not current):
                return
            self._current = None
        current._end("cancelled")
        self._retire(self.engine.tasks.replace(TASK_SLOT, self._idle))

    @property
    def perception(self) -> Pipeline | None:
        """The perceive pipeline of the served root (its CAS holds the newest frame); None without a stream."""
        return self._perception

    @property
    def task_tree(self) -> py_trees.behaviour.Behaviour | None:
        """What the task slot holds now (the idle subtree without a task); read it on the engine thread."""
        return self._slot.subtree

    @property
    def source_ended(self) -> str | None:
        """Why the live source ended (None while it has frames, and without a stream)."""
        return self._source_ended

    @staticmethod
    def mode_of(query: Query) -> ExecutionMode:
        """How a query of this kind runs (ValueError for ``stop``, which plans nothing)."""
        try:
            return EXECUTION_MODES[query.kind]
        except KeyError:
            raise ValueError(f"a {query.kind} query plans no perception tree") from None

    def close(self) -> None:
        """Stop the engine (ending the running task), close the stream, wait for interrupted experts' worker
        threads to end (up to :data:`WORKER_WAIT` s) and close the belief store."""
        with self._lock:
            current, self._current = self._current, None
        if current is not None:
            current._end("the service closed")
        try:
            if self.stream is not None:
                self.stream.close()
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

    def add_belief_listener(self, listener: Callable[[TrackStep], None]) -> None:
        """Call ``listener`` with every frame's changes to the belief store (on the engine's thread, right after
        they are written; keep it short)."""
        self._belief_listeners.append(listener)

    # ------------------------------------------------------------------ engine side

    def _beliefs_changed(self, step: TrackStep) -> None:
        for listener in self._belief_listeners:
            listener(step)

    def _after_tick(self, _: py_trees.trees.BehaviourTree) -> None:
        """After every tick (engine thread): end a finished one-shot task or hand a continuous task's answer to
        its handle; end the task when perception failed, its run failed or its deadline passed."""
        perception_failure = None
        if self._perception is not None and self._perception.status is Status.FAILURE:
            perception_failure = failure_reason(self._perception)
            if self._reader is not None and self._reader.ended:
                self._source_ended = perception_failure
        with self._lock:
            handle = self._current
        if handle is None or handle.done or self._slot.subtree is not handle.tree:
            return  # no task, or its tree is not in the slot yet (the swap is applied at the next tick)
        if handle.tree.status is not Status.INVALID:  # this tick ran the task's tree
            if handle.first_tick is None:
                handle.first_tick = self.engine.tick_started
            handle._ticked(self.engine.tick_count)
        pipeline = handle.pipeline
        if perception_failure is not None:
            self._finish(handle, f"perception failed: {perception_failure}")
        elif isinstance(handle.tree, Loop):
            self._after_run(handle, handle.tree, pipeline)
        elif pipeline.status is Status.SUCCESS:
            found = pipeline.cas.view(QueryAnswer)
            answer = found.answer if found is not None and isinstance(found.answer, Answer) else None
            if handle.mode is ExecutionMode.ONCE:
                self._finish(handle, "answered", result=answer)
            elif answer is not None:
                handle._publish(answer)
        elif pipeline.status is Status.FAILURE:
            reason = failure_reason(pipeline)
            self._finish(handle, reason if handle.mode is ExecutionMode.ONCE else f"a run failed: {reason}")
        if not handle.done and handle._expired():
            self._finish(handle, f"timed out after {handle.timeout:g} s", timed_out=True)

    def _after_run(self, handle: TaskHandle, loop: Loop, pipeline: Pipeline) -> None:
        """A continuous task after a tick: when its loop finished a run, publish the run's answer and end the task
        when its target is lost (or when the loop itself ended)."""
        if loop.completed > handle.runs:
            handle.runs = loop.completed
            answer = None
            if pipeline.status is Status.SUCCESS:
                found = pipeline.cas.view(QueryAnswer)
                answer = found.answer if found is not None and isinstance(found.answer, Answer) else None
            if answer is not None:
                handle._publish(answer)
            info = pipeline.cas.view(CameraInfo)
            if info is None:  # the run read no frame (perception between two frames): it saw nothing, nor missed
                return
            stamp = info.timestamp if info.timestamp > 0 else time.monotonic()
            seen = answer is not None and (answer.track.seen if answer.track is not None else bool(answer.objects))
            if not seen and pipeline.status is Status.FAILURE:
                handle.last_failure = failure_reason(pipeline)
            lost = handle.watch.observe(stamp, seen) if handle.watch is not None else None
            if lost is not None:
                if handle.last_failure and not seen:
                    lost += f"; the last run failed: {handle.last_failure}"
                self._finish(handle, lost)
                return
        if loop.status is Status.FAILURE:
            self._finish(handle, f"a run failed: {loop.last_failure or failure_reason(pipeline)}")
        elif loop.status is Status.SUCCESS:
            self._finish(handle, f"finished after {loop.succeeded} runs")

    def _finish(
        self, handle: TaskHandle, reason: str, *, result: Answer | None = None, timed_out: bool = False
    ) -> None:
        """End ``handle`` (engine thread, after a tick) and have the idle subtree put into the slot before the next
        tick (so every post-tick handler still sees the task's final statuses; a task submitted meanwhile wins)."""
        with self._lock:
            if self._current is handle:
                self._current = None
        handle._end(reason, result=result, timed_out=timed_out)
        if handle.tree.status is Status.RUNNING:  # timed out or perception failed: stop it now, not a tick later
            handle.tree.stop(Status.INVALID)
        self.engine.tasks.schedule(TASK_SLOT, self._idle, only_replacing=handle.tree)
        self._retire(handle.tree)

    def _retire(self, tree: py_trees.behaviour.Behaviour | None) -> None:
        """Remember a tree taken out of the slot while its experts' worker threads finish (:meth:`close` waits)."""
        if tree is None:
            return
        with self._lock:
            self._retired = [t for t in self._retired if has_workers(t)]
            if has_workers(tree):
                self._retired.append(tree)


def query_timeout(query: Query) -> float | None:
    """The query's ``timeout`` in seconds (None when it sets none)."""
    return query_duration(query, TIMEOUT_KEY)


def query_duration(query: Query, key: str) -> float | None:
    """The duration (seconds; the parser converts units) the query gives under ``key``, None when it gives none."""
    value = query.get(key)
    return float(value.value) if isinstance(value, Number) else None


def failure_reason(tree: py_trees.behaviour.Behaviour) -> str:
    """The failed nodes of ``tree`` with their messages, or a note that the tree did not finish."""
    failed = [n for n in tree.iterate() if n.status is Status.FAILURE and n.feedback_message]
    return "; ".join(f"{n.name}: {n.feedback_message}" for n in failed) or "the tree did not finish"
