"""Remote experts: any annotator runs on a Ray actor while its node stays in the tree as a threaded annotator.

:func:`place_remote` replaces the annotators of a tree that are to run elsewhere (their class declares
``Placement(remote=True)``, or the caller names them) by :class:`RemoteAnnotator` nodes. Such a node has the
annotator's name, reason, ports and capability; on each run its worker thread

1. takes the annotator's *declared* inputs from the CAS (the views of its input types, the annotations of its
   input types; a hypothesis goes without the annotations other experts attached to it unless they are of a
   declared input type too, as a shallow copy that shares its arrays, and with its mask cut to its ``roi``
   when nothing of the mask lies outside: the actor restores the full-frame mask, so the expert sees what
   it would see locally),
2. sends them to the actor through the actor's Ray compiled graph (:mod:`robokudo.core.compiled_call`: the
   views and annotations are serialised straight into a pre-allocated shared-memory channel, the one copy the
   transfer needs, nothing else is copied here; a call costs tens of microseconds instead of Ray's task
   submission's milliseconds), or, where compiled graphs are not available or the placement asks for it
   (``Placement(compiled_graph=False)``), by a plain actor call: each view put into Ray's object store once per
   frame (:class:`FrameStore`: every remote expert of a resource pool that reads the frame's image sends the
   same reference) and the call made with the references and the (small) annotations. On the actor's node the
   arrays are read in place, read-only. :attr:`RemoteAnnotator.call_path` says which path the calls take,
3. waits (the node is RUNNING, the tick loop goes on), polling its cancel flag: a cancelled or timed-out run
   discards its result, as a local threaded annotator does (a plain call is also cancelled in Ray; a compiled
   graph's execution cannot be, so it finishes on the actor and Ray releases its result unread when the next
   call reads past it),
4. commits what the actor's annotator wrote through its own port checks (attachments go to the local
   hypotheses they were made for).

The actor rebuilds the annotator from its class and its own attributes (its parameters; framework state is
left behind), so an annotator whose attributes cannot be pickled cannot be placed (:class:`PlacementError`
names the attribute). A dead actor makes the run FAIL with the reason; Ray restarts the actor's process (up to
``max_restarts`` times), its compiled graph is torn down and the next run compiles a new one on the new
process. Actors are kept in the node's
:class:`~robokudo.core.resources.SharedResources` under the class and parameters, so every tree built with
one pool (a serving instance's) shares one actor per expert.

Ray is optional (``pip install 'robokudo[ray]'``) and imported only when something is placed remotely; this
module imports nothing else above the runtime core.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import os
import threading
import time
from collections import OrderedDict
from collections.abc import Collection, Hashable
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any, ClassVar

import numpy as np
import py_trees

from robokudo.core import compiled_call
from robokudo.core.annotator import Annotator, PortError, RunCancelledError, _Run
from robokudo.core.cas import CAS, AddAnnotation, SetView
from robokudo.core.compiled_call import (
    COMPILED_GRAPH,
    PLAIN_CALLS,
    ChannelClosedError,
    CompiledCalls,
    GraphStalledError,
)
from robokudo.core.pipeline import StructureError
from robokudo.core.placement import Placement
from robokudo.core.threaded import ThreadedAnnotator
from robokudo.core.types import Annotation, CasType, ObjectHypothesis, View

INSTALL_HINT = "Ray is not installed: pip install 'robokudo[ray]' (or ray)"

POLL_SECONDS = 0.05
"""How often a waiting worker checks whether its run was cancelled."""

DEFAULT_TIMEOUT = 60.0
"""Seconds a remote run may take (the first run also waits for the actor's process to start)."""

ACTOR_ENV: dict[str, str] = {
    "MALLOC_MMAP_THRESHOLD_": str(32 << 20),
    "MALLOC_TRIM_THRESHOLD_": str(1 << 30),
}
"""Environment of an actor's process: its C allocator (glibc; others ignore these) keeps the memory an expert's
run freed for the next run. An actor runs one expert over and over; with glibc's defaults its process hands each
run's large temporaries back to the system and takes them again, page by page, on the next run (the colour expert
on the kitchen frame: about 800 page faults, 8 ms per run instead of 5 on a 2-core VM, none in the tree's process,
whose earlier large frees had raised glibc's adaptive thresholds). Blocks below 32 MB come from the heap, which
is not trimmed below 1 GB of free memory: the process keeps about its peak use, which every run needs anyway."""


class PlacementError(Exception):
    """An annotator cannot be placed on a Ray actor (Ray missing, parameters that cannot be sent, bad name)."""


def require_ray() -> ModuleType:
    """The ``ray`` module; PlacementError with the install hint when it is not installed."""
    try:
        import ray
    except ImportError:
        raise PlacementError(f"remote experts need Ray. {INSTALL_HINT}") from None
    return ray


# --------------------------------------------------------------------------------------------- the recipe


@functools.cache
def _framework_attributes() -> frozenset[str]:
    """The instance attributes every (threaded) annotator has from the framework; the rest are parameters."""
    return frozenset(vars(ThreadedAnnotator(name="probe")))


@dataclass(frozen=True)
class Recipe:
    """How the actor rebuilds an annotator: its class, its name and its parameters (its own attributes)."""

    cls: type[Annotator]
    name: str
    parameters: dict[str, Any]

    @classmethod
    def of(cls, annotator: Annotator) -> Recipe:
        """The recipe of ``annotator``; PlacementError when a parameter cannot be sent to another process."""
        ray = require_ray()
        framework = _framework_attributes()
        parameters = {key: value for key, value in vars(annotator).items() if key not in framework}
        for key, value in parameters.items():
            try:
                ray.cloudpickle.dumps(value)
            except Exception as error:
                raise PlacementError(
                    f"cannot place {annotator.name!r} ({type(annotator).__name__}) remotely: its attribute {key!r} "
                    f"cannot be sent to another process ({type(error).__name__}: {error})"
                ) from None
        return cls(type(annotator), annotator.name, parameters)

    def key(self) -> Hashable:
        """Equal for recipes that build the same annotator (the actor a resource pool shares)."""
        ray = require_ray()
        parameters = ray.cloudpickle.dumps(self.parameters)
        return ("remote expert", self.cls.__module__, self.cls.__qualname__, self.name, parameters)

    def build(self) -> Annotator:
        """A fresh annotator of the class with these parameters (its framework state new)."""
        annotator = self.cls.__new__(self.cls)
        Annotator.__init__(annotator, name=self.name)
        vars(annotator).update(self.parameters)
        return annotator


# --------------------------------------------------------------------------------------------- the actor side

Write = tuple[str, Any] | tuple[str, int, Annotation]


class ExpertHost:
    """What a Ray actor holds: one annotator, run on the inputs each call brings in a CAS of their own."""

    def __init__(self, recipe: Recipe) -> None:
        self._annotator = recipe.build()

    def process_id(self) -> int:
        """The actor's process id (to watch or stop it)."""
        return os.getpid()

    def analyse(
        self, annotations: list[Annotation], *views: View
    ) -> tuple[str, str, list[Write], float, tuple[float, float]]:
        """Run the annotator on the ``annotations`` (as :func:`in_transit` made them) and ``views``; its status
        name, message, writes (each attachment naming its hypothesis by its index among the annotations), its
        run time in seconds and when this method was entered and left (``time.perf_counter()`` here)."""
        entered = time.perf_counter()
        annotations = [restored(annotation) for annotation in annotations]
        cas = CAS()
        for view in views:
            cas.set_view(view)
        for annotation in annotations:
            cas.add(annotation)
        run = _Run(cas, thread_ident=None)
        status, message, seconds = self._annotator._execute(run)
        if status.name != "SUCCESS":
            return status.name, message, [], seconds, (entered, time.perf_counter())
        position = {id(annotation): index for index, annotation in enumerate(annotations)}
        writes: list[Write] = []
        for write in run.writes:
            if isinstance(write, SetView):
                writes.append(("view", write.view))
            elif isinstance(write, AddAnnotation):
                writes.append(("add", write.annotation))
            elif id(write.hypothesis) in position:
                writes.append(("attach", position[id(write.hypothesis)], write.annotation))
            else:
                message = "attached an annotation to a hypothesis it was not sent"
                return "FAILURE", message, [], seconds, (entered, time.perf_counter())
        return status.name, message, writes, seconds, (entered, time.perf_counter())

    def analyse_packed(self, inputs: tuple[list[Annotation], list[View]] | None) -> bytes:
        """:meth:`analyse` on ``(annotations, views)`` as a compiled graph's call brings them, its answer pickled
        (so no array of the answer keeps the graph's output channel once the caller has read it); None for None
        (a new graph's first call)."""
        import ray

        if inputs is None:
            return ray.cloudpickle.dumps(None)
        annotations, views = inputs
        return ray.cloudpickle.dumps(self.analyse(annotations, *views))


@functools.cache
def _actor_class() -> Any:
    return require_ray().remote(ExpertHost)


# --------------------------------------------------------------------------------------------- the tree side


class RemoteAnnotator(ThreadedAnnotator):
    """An annotator placed on a Ray actor (see the module); build it with :func:`remote_annotator`."""

    local_type: ClassVar[type[Annotator]] = Annotator

    def __init__(self, recipe: Recipe, placement: Placement, timeout: float = DEFAULT_TIMEOUT) -> None:
        super().__init__(name=recipe.name, timeout=timeout)
        if not placement.remote:
            placement = replace(placement, remote=True)
        self.recipe = recipe
        self.where = placement
        self._actor: Any = None
        self._actor_failed = False
        self._answered = False
        """Whether this node's actor has answered a run yet (its first run also waits for its process to start)."""
        self.remote_seconds = 0.0
        """The expert's own run time on the actor in the last run that got an answer (seconds)."""
        self.call_times = CallTimes()
        """Where the time of the last successful run went."""

    def actor(self) -> Any:
        """The Ray actor handle (started on first use; shared through this node's resources)."""
        if self._actor is None:
            placement = self.where

            def start() -> Any:
                return (
                    _actor_class()
                    .options(
                        num_cpus=placement.num_cpus,
                        num_gpus=placement.num_gpus,
                        max_restarts=placement.max_restarts,
                        max_task_retries=0,
                        runtime_env={"env_vars": ACTOR_ENV},
                    )
                    .remote(self.recipe)
                )

            self._actor = self.resources.get((*self.recipe.key(), placement), start)
        return self._actor

    def compiled_calls(self) -> CompiledCalls | None:
        """The compiled graph of this node's actor (shared like the actor), None when the placement asks for plain
        actor calls."""
        if not self.where.compiled_graph:
            return None
        ray = require_ray()
        actor = self.actor()
        key = (*self.recipe.key(), self.where, "compiled graph")
        return self.resources.get(key, lambda: CompiledCalls(ray, actor))

    @property
    def call_path(self) -> str:
        """Which path this node's calls take: the compiled graph, or plain actor calls (and why)."""
        if not self.where.compiled_graph:
            return f"{PLAIN_CALLS} (as placed: compiled_graph=False)"
        if self._actor is None:  # not started: what its calls would take, without starting it
            missing = compiled_call.unavailable_reason(require_ray())
            return COMPILED_GRAPH if missing is None else f"{PLAIN_CALLS} ({missing})"
        return self.compiled_calls().path()  # type: ignore[union-attr]

    def actor_process_id(self, timeout: float = 60.0) -> int:
        """The process id of the actor's current process (waits for it to start)."""
        ray = require_ray()
        return int(ray.get(self.actor().process_id.remote(), timeout=timeout))

    def _inputs(self) -> tuple[list[View], list[Annotation], list[Annotation]]:
        """The declared inputs present: views, the annotations to send and the local annotations they stand for."""
        declared = self.inputs + self.optional_inputs
        views: list[View] = []
        for cas_type in declared:
            if issubclass(cas_type, View):
                view = self.optional_view(cas_type)
                if view is not None and all(view is not v for v in views):
                    views.append(view)
        local: list[Annotation] = []
        seen: set[int] = set()
        for cas_type in declared:
            if issubclass(cas_type, Annotation):
                for annotation in self.annotations(cas_type):
                    if id(annotation) not in seen:
                        seen.add(id(annotation))
                        local.append(annotation)
        annotation_types = tuple(t for t in declared if issubclass(t, Annotation))
        sent = [in_transit(annotation, annotation_types) for annotation in local]
        return views, sent, local

    def frames(self) -> FrameStore:
        """The object-store references of the frames' views, shared by the remote experts of this node's pool."""
        return self.resources.get(FrameStore.KEY, FrameStore)

    def analyse(self) -> None:
        """Send the declared inputs, wait for the actor's answer, commit its writes."""
        ray = require_ray()
        times = CallTimes()
        start = time.perf_counter()
        views, sent, local = self._inputs()
        _, times.inputs = _lap(start)
        actor = self.actor()
        compiled = self.compiled_calls()
        if self._actor_failed:
            self._await_restart(ray, actor)
        try:
            stamp = time.perf_counter()
            answer = None
            if compiled is not None and compiled.unavailable is None:
                answer = self._compiled_call(ray, actor, compiled, (sent, views))
            called = stamp
            if answer is None:
                references = self.frames().references(ray, views)
                stamp, times.put = _lap(stamp)
                pending = actor.analyse.remote(sent, *references)
                stamp, times.call = _lap(stamp)
                called = stamp
                answer = self._wait(ray, pending)
            status, message, writes, times.expert, (entered, left) = answer
            self._answered = True
            stamp, times.answer = _lap(called)
            times.actor = left - entered
            times.to_actor, times.from_actor = entered - called, stamp - left
            self.remote_seconds = times.expert
        except ray.exceptions.RayTaskError as error:
            cause = getattr(error, "cause", None)
            if isinstance(cause, PortError | StructureError | NotImplementedError):
                raise cause from None
            self.fail(f"remote {self.name} raised {_summary(error)}")
        except (ray.exceptions.RayActorError, ray.exceptions.ActorUnavailableError) as error:
            self._actor_failed = True
            if compiled is not None:
                compiled.reset()  # Ray shut the graph down; the next run compiles one on the restarted actor
            self.fail(f"remote actor of {self.name} died: {_summary(error)}")
        except ray.exceptions.RayError as error:
            self.fail(f"remote {self.name} failed: {type(error).__name__}: {_summary(error)}")
        if status != "SUCCESS":
            self.fail(message or f"remote {self.name} ended {status}")
        for write in writes:
            if write[0] in ("view", "add"):
                self.write(write[1])
            else:
                _, index, annotation = write
                if not 0 <= index < len(local) or not isinstance(local[index], ObjectHypothesis):
                    self.fail(f"remote {self.name} attached to hypothesis {index}, which it was not sent")
                self.attach(local[index], annotation)  # type: ignore[arg-type]
        _, times.commit = _lap(stamp)
        self.call_times = times

    def _wait(self, ray: ModuleType, pending: Any) -> Any:
        """The result of the call ``pending``, polling this run's cancel flag meanwhile (a cancelled run asks Ray
        to cancel the call and ends with RunCancelledError)."""
        try:
            while True:
                try:
                    return ray.get(pending, timeout=POLL_SECONDS)
                except ray.exceptions.GetTimeoutError:
                    if self.cancelled:  # (reading it raises RunCancelledError once the run is cancelled)
                        raise RunCancelledError() from None
        except RunCancelledError:
            _cancel(ray, pending)
            raise

    def _compiled_call(self, ray: ModuleType, actor: Any, compiled: CompiledCalls, inputs: tuple) -> Any:
        """The actor's answer through its compiled graph; None when this run is to go as a plain call (the graph
        closed: the next run compiles a new one)."""
        for _ in range(2):
            try:
                return compiled.call(inputs, self._check_cancelled, POLL_SECONDS)
            except GraphStalledError as stalled:  # its actor's process restarts: wait for it, compile again
                self._await_restart(ray, actor, stalled.process_id)
            except ChannelClosedError:
                compiled.reset()
                return None
        return None

    def _check_cancelled(self) -> None:
        """RunCancelledError once this run is cancelled."""
        if self.cancelled:  # (reading it raises RunCancelledError once the run is cancelled)
            raise RunCancelledError()

    def _await_restart(self, ray: ModuleType, actor: Any, old_process_id: int | None = None) -> None:
        """After the actor died (or its process ``old_process_id`` was ended): wait until Ray has restarted it (a
        call sent while it restarts would fail)."""
        while True:
            try:
                process_id = self._wait(ray, actor.process_id.remote())
            except ray.exceptions.ActorUnavailableError:
                time.sleep(POLL_SECONDS)
                continue
            except ray.exceptions.RayActorError as error:
                self.fail(f"remote actor of {self.name} is gone: {_summary(error)}")
            if process_id == old_process_id:  # the ended process has not gone yet
                time.sleep(POLL_SECONDS)
                continue
            self._actor_failed = False
            return

    def timeout_detail(self) -> str:
        """Says when the actor never answered: its process may still be starting (tens of seconds on a loaded
        machine) or the cluster may lack what it reserves."""
        if self._answered:
            return ""
        reserved = self.where.describe().removeprefix("remote ").strip("()")
        return (
            f" (its actor had not answered yet: its process may still be starting, or no node has the {reserved} "
            "it reserves free)"
        )

    def stop_actor(self) -> None:
        """End the actor's process now (an actor also ends when the last handle to it is gone)."""
        if self._actor is not None:
            calls = self.compiled_calls()
            # the actor first: a run still waiting for it (one that never started holds the graph's lock while it
            # asks for its process) then ends, and the graph can be torn down
            require_ray().kill(self._actor, no_restart=True)
            if calls is not None:
                calls.reset()
            self._actor = None


@dataclass(slots=True)
class CallTimes:
    """Where one remote call's time went, in seconds, stage by stage (a few clock reads per call)."""

    inputs: float = 0.0
    """Declared inputs gathered from the CAS and packed for transit."""
    put: float = 0.0
    """The frame's views put into the object store (nothing when another expert of the pool put them)."""
    call: float = 0.0
    """The actor call handed to Ray (its small arguments serialised)."""
    answer: float = 0.0
    """From the call handed over to the answer in hand (the actor's time included)."""
    to_actor: float = 0.0
    """From the call handed over to the actor's method entered (its inputs in hand). Only meaningful when the
    actor runs on this machine (the clocks of two machines differ), as are ``from_actor``."""
    from_actor: float = 0.0
    """From the actor's method left to the answer in hand here."""
    actor: float = 0.0
    """In the actor's method: inputs restored, the expert's run, its writes packed."""
    expert: float = 0.0
    """The expert's own run on the actor."""
    commit: float = 0.0
    """The answer's writes checked and queued."""

    def stages(self) -> dict[str, float]:
        """The stages of the node's latency, in order (they add up to it, but for a wait for a restarted actor)."""
        return {
            "inputs": self.inputs,
            "put": self.put,
            "call": self.call,
            "to actor": self.to_actor,
            "from actor": self.from_actor,
            "actor unpack/pack": self.actor - self.expert,
            "expert": self.expert,
            "commit": self.commit,
        }


def _lap(since: float) -> tuple[float, float]:
    """Now, and the seconds since ``since``."""
    now = time.perf_counter()
    return now, now - since


@dataclass(frozen=True, slots=True)
class CroppedMask:
    """A hypothesis mask in transit: its part inside the hypothesis' ``roi`` and the full frame's shape."""

    inside: np.ndarray
    shape: tuple[int, ...]

    def full(self, roi: tuple[int, int, int, int]) -> np.ndarray:
        """The full-frame mask again (False outside ``roi``)."""
        x0, y0, x1, y1 = roi
        mask = np.zeros(self.shape, dtype=self.inside.dtype)
        mask[y0:y1, x0:x1] = self.inside
        return mask


@dataclass(frozen=True, slots=True)
class MaskIndices:
    """Hypothesis point indices in transit that are exactly the flat indices of its mask (of this dtype)."""

    dtype: str

    def of(self, mask: CroppedMask, roi: tuple[int, int, int, int]) -> np.ndarray:
        """The indices again, from the mask as it was sent."""
        inside = np.ascontiguousarray(mask.inside)
        width, frame_width = inside.shape[1], mask.shape[1]
        flat = np.flatnonzero(inside)  # row * width + column inside the roi
        indices = flat + (flat // max(width, 1)) * (frame_width - width) + (roi[1] * frame_width + roi[0])
        return indices.astype(self.dtype, copy=False)


def in_transit(annotation: Annotation, declared: tuple[type[CasType], ...]) -> Annotation:
    """What is sent for ``annotation``: itself, or for a hypothesis a shallow copy (arrays shared) whose
    attached annotations are those of the ``declared`` types only, whose mask is a :class:`CroppedMask` when
    no pixel of it lies outside the hypothesis' ``roi``, and whose point indices are a :class:`MaskIndices` when
    they are the mask's flat indices (the actor restores both: :func:`restored`)."""
    if not isinstance(annotation, ObjectHypothesis):
        return annotation
    kept = [a for a in annotation.annotations if isinstance(a, declared)]
    cut = _inside_roi(annotation.mask, annotation.roi)
    if len(kept) == len(annotation.annotations) and cut is None:
        return annotation
    sent = copy.copy(annotation)
    sent.annotations = kept
    if cut is not None:
        inside, count = cut
        if _are_mask_indices(annotation.point_indices, annotation.mask, count):
            sent.point_indices = MaskIndices(annotation.point_indices.dtype.str)  # type: ignore[assignment]
        sent.mask = CroppedMask(inside, annotation.mask.shape)  # type: ignore[assignment]
    return sent


def restored(annotation: Annotation) -> Annotation:
    """An annotation as it was before :func:`in_transit` (a hypothesis gets its full-frame mask and its point
    indices back)."""
    if isinstance(annotation, ObjectHypothesis) and isinstance(annotation.mask, CroppedMask):
        if isinstance(annotation.point_indices, MaskIndices):
            annotation.point_indices = annotation.point_indices.of(annotation.mask, annotation.roi)
        annotation.mask = annotation.mask.full(annotation.roi)
    return annotation


def _are_mask_indices(indices: Any, mask: np.ndarray, count: int) -> bool:
    """True when ``indices`` (an integer array) are the flat indices, in order, of the ``count`` set pixels of
    ``mask``: as many, strictly increasing, in range and all on set pixels (no scan of the whole mask)."""
    if not isinstance(indices, np.ndarray) or indices.ndim != 1 or indices.dtype.kind not in "iu":
        return False
    if indices.shape[0] != count:
        return False
    if count == 0:
        return True
    if indices[0] < 0 or indices[-1] >= mask.size or not np.all(indices[1:] > indices[:-1]):
        return False
    return bool(mask.reshape(-1)[indices].all())


def _inside_roi(mask: Any, roi: Any) -> tuple[np.ndarray, int] | None:
    """The part of a 2-D ``mask`` inside ``roi`` (x0, y0, x1, y1) and the mask's number of set pixels, when that
    part holds all of them and is smaller than the mask; else None."""
    if not isinstance(mask, np.ndarray) or mask.ndim != 2 or not isinstance(roi, tuple) or len(roi) != 4:
        return None
    x0, y0, x1, y1 = (int(v) for v in roi)
    height, width = mask.shape
    if not (0 <= x0 <= x1 <= width and 0 <= y0 <= y1 <= height) or (x1 - x0) * (y1 - y0) == mask.size:
        return None
    inside = mask[y0:y1, x0:x1]
    count = np.count_nonzero(mask)
    if np.count_nonzero(inside) != count:
        return None
    return inside, count


class FrameStore:
    """The object-store references of the views remote experts sent lately, one ``ray.put`` per view object.

    A frame's views are new objects (a reader writes new ones for every frame), so the references are kept per
    view object, the view held with its reference so its id stays its own; the ``size`` latest are kept
    (several trees of one pool may work on a few frames at once). Thread-safe: the workers of several remote
    experts call it at once.
    """

    KEY: ClassVar[Hashable] = ("remote expert frames",)

    def __init__(self, size: int = 8) -> None:
        self.size = size
        self._lock = threading.Lock()
        self._references: OrderedDict[int, tuple[View, Any]] = OrderedDict()

    def references(self, ray: ModuleType, views: list[View]) -> list[Any]:
        """The object references of ``views`` (put into the object store on first request)."""
        return [self._reference(ray, view) for view in views]

    def _reference(self, ray: ModuleType, view: View) -> Any:
        with self._lock:
            known = self._references.get(id(view))
            if known is not None and known[0] is view:
                self._references.move_to_end(id(view))
                return known[1]
        reference = ray.put(view)
        with self._lock:
            self._references[id(view)] = (view, reference)
            self._references.move_to_end(id(view))
            while len(self._references) > self.size:
                self._references.popitem(last=False)
        return reference


def _cancel(ray: ModuleType, pending: Any) -> None:
    with contextlib.suppress(Exception):  # best effort: the result is discarded anyway
        ray.cancel(pending)


def _summary(error: BaseException, limit: int = 300) -> str:
    """The first meaningful line of a Ray error, shortened."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    text = lines[0] if lines else type(error).__name__
    detail = next((line for line in lines[1:] if "exit" in line.lower() or "signal" in line.lower()), "")
    if detail and detail not in text:
        text = f"{text} ({detail})"
    return text if len(text) <= limit else text[: limit - 3] + "..."


@functools.cache
def _remote_class(cls: type[Annotator]) -> type[RemoteAnnotator]:
    """The RemoteAnnotator subclass with ``cls``'s ports and capability (one per annotator class)."""
    return type(
        f"Remote{cls.__name__}",
        (RemoteAnnotator,),
        {
            "__module__": __name__,
            "__doc__": cls.__doc__,
            "inputs": cls.inputs,
            "optional_inputs": cls.optional_inputs,
            "outputs": cls.outputs,
            "capability": cls.capability,
            "local_type": cls,
        },
    )


def remote_annotator(
    annotator: Annotator, placement: Placement | None = None, timeout: float = DEFAULT_TIMEOUT
) -> RemoteAnnotator:
    """A node that runs ``annotator`` on a Ray actor (hints: ``placement``, default the class's declaration);
    it takes over the annotator's name, reason and resource pool. PlacementError as :meth:`Recipe.of` says."""
    if isinstance(annotator, RemoteAnnotator):
        raise PlacementError(f"{annotator.name!r} is placed remotely already")
    cls = type(annotator)
    node = _remote_class(cls)(Recipe.of(annotator), placement or cls.placement, timeout)
    node.reason = annotator.reason
    node.resources = annotator.resources
    if isinstance(annotator, ThreadedAnnotator):
        node.timeout = max(node.timeout, annotator.timeout)
    return node


def wants_remote(annotator: Annotator, names: Collection[str]) -> bool:
    """True when ``annotator`` is to run remotely: its class declares it, or ``names`` holds its name or class."""
    if isinstance(annotator, RemoteAnnotator):
        return False
    return type(annotator).placement.remote or annotator.name in names or type(annotator).__name__ in names


def place_remote(
    root: py_trees.behaviour.Behaviour,
    names: Collection[str] = (),
    hints: Placement | None = None,
    *,
    start: bool = True,
) -> list[RemoteAnnotator]:
    """Replace the annotators of ``root`` that are to run remotely (:func:`wants_remote`) by RemoteAnnotators,
    in place; the new nodes. ``hints`` overrides the classes' resource hints for annotators chosen by ``names``;
    ``start`` starts their actors at once (they boot while the tree's first steps run). PlacementError as
    :func:`remote_annotator` says, or when the root itself would be replaced (it has no parent to hold the node).
    """
    chosen = [node for node in root.iterate() if isinstance(node, Annotator) and wants_remote(node, names)]
    placed = []
    for node in chosen:
        parent = node.parent
        if not isinstance(parent, py_trees.composites.Composite):
            where = "it is the root of the tree" if parent is None else f"its parent {parent.name!r} is no composite"
            raise PlacementError(f"cannot place {node.name!r} remotely: {where}")
        declared = type(node).placement
        placement = declared if declared.remote or hints is None else hints
        remote = remote_annotator(node, placement)
        parent.replace_child(node, remote)
        placed.append(remote)
    if start:
        for remote in placed:
            remote.actor()
    return placed
