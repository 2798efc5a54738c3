"""Calls to a remote expert's actor through a Ray compiled graph: pre-allocated shared-memory channels instead of
Ray's task submission, for a call overhead of tens of microseconds instead of milliseconds.

A :class:`CompiledCalls` holds the compiled graph of one actor (``InputNode -> actor.analyse_packed``), shared by
every node of a resource pool that calls that actor (an actor runs one compiled graph at a time). Its users:

* :meth:`CompiledCalls.call` writes the arguments into the graph's input channel (serialised straight into the
  shared buffer: the one copy the transfer needs) and waits for the answer in short slices, asking ``check``
  between them whether the run was cancelled. The actor answers with its result pickled into bytes, so nothing
  of the answer keeps the output channel's buffer (the arrays in a result would otherwise hold it, and the
  graph's next call would wait for them forever).
* A compiled graph cannot cancel an execution in flight. A cancelled (or timed-out) call leaves it to finish on
  the actor and returns at once; its reference is kept, and the graph's next call, which waits in slices (still
  cancellable) until the actor has finished both, discards that result unread before it returns its own (so it
  gets its own answer, never the stale one; executions finish in order).
* A channel that closes (the actor died: Ray then shuts the graph down) or a graph that can take no more calls
  ends the graph: :meth:`CompiledCalls.reset` tears it down and the next call compiles it anew, on the actor Ray
  restarted.
* Waiting for an answer in Ray's read polls a core for as long as the expert runs; a call can first sleep
  through most of the time the last calls took (:attr:`CompiledCalls.nap_fraction`, off by default: see
  :data:`NAP_FRACTION`), then wait in the read.
* An idle graph's actor polls its input channel (Ray 2.60 spins on it: about half a core or more), so a graph
  that took no call for :data:`IDLE_SECONDS` is torn down; the next call compiles it again (0.1-0.4 s, once).
  While calls keep coming (a camera's frames) the actor polls between them.
* Channels start at :data:`BUFFER_BYTES` (a 640x480 RGB-D frame with its hypotheses fits) and Ray grows them
  when a larger input comes.

Where compiled graphs are not available (a Ray without them, a Ray client connection, a graph that does not
compile), :attr:`CompiledCalls.unavailable` says why and the caller uses plain actor calls. Ray is imported
only by the callers' ``ray`` module argument; this module imports nothing of it.
"""

from __future__ import annotations

import collections
import contextlib
import threading
import time
from collections.abc import Callable
from types import ModuleType
from typing import Any

BUFFER_BYTES = 4 << 20
"""Initial size of a channel's buffer: a 640x480 RGB-D frame (0.9 MB of colour, 1.2 MB of float depth) and its
hypotheses' masks fit; Ray grows a channel for a larger input."""

SUBMIT_SLICE = 0.05
"""Seconds a call waits at most, in one go, for the input channel (the actor takes its input when it starts)."""

IDLE_SECONDS = 2.0
"""A graph that took no call for this long is torn down (the next call compiles it again, in 0.1-0.4 s): an idle
compiled graph's actor polls its input channel, which keeps a core about half busy or more (Ray 2.60)."""

NAP_FRACTION = 0.0
"""A call may sleep through this fraction of the shortest of the last calls' times before it waits in Ray's read of
the answer, which polls (a core busy for the whole wait: as long as the expert's run). 0 (no sleep) by default: on
a loaded 2-core machine, 0.8 cut the caller's CPU per call by about a third in one run and not at all in another,
and the woken thread's delays gave a 90th percentile of 12-26 ms overhead against 5 ms without sleeping
(``bench/bench_ray.py --compare-nap``)."""

VERIFY_SECONDS = 5.0
"""How long a new graph's first, empty call may take. After Ray restarted an actor whose process died, about one
new graph in eight on a loaded 2-core machine never ran its first call (its actor loop's task stayed pending
while the actor answered plain calls); its process is then ended for Ray to restart (:class:`GraphStalledError`)."""

PLAIN_CALLS = "plain actor calls"
COMPILED_GRAPH = "compiled graph (shared-memory channels)"


class ChannelClosedError(Exception):
    """The compiled graph was shut down (its actor died, or it was torn down) or can take no more calls."""


class GraphStalledError(ChannelClosedError):
    """A new graph did not answer its first (empty) call: its actor's process (``process_id``) was ended for Ray
    to restart, and the graph torn down."""

    def __init__(self, message: str, process_id: int) -> None:
        super().__init__(message)
        self.process_id = process_id


class CompiledCalls:
    """The compiled graph of one actor, built on first use, thread-safe (see the module)."""

    def __init__(
        self,
        ray: ModuleType,
        actor: Any,
        method: str = "analyse_packed",
        process_id_method: str = "process_id",
        buffer_bytes: int = BUFFER_BYTES,
        idle_seconds: float = IDLE_SECONDS,
    ) -> None:
        self._ray = ray
        self._actor = actor
        self._method = method
        self._process_id_method = process_id_method
        self._process_id = 0
        """The process id of the actor the graph was compiled on."""
        self._verified: Any = None
        """The graph whose first call answered."""
        self.buffer_bytes = buffer_bytes
        self.idle_seconds = idle_seconds
        self._lock = threading.Lock()
        self.nap_fraction = NAP_FRACTION
        self._took: collections.deque[float] = collections.deque(maxlen=8)
        """Seconds the last calls took from their input sent to their answer in hand."""
        self._calls_in_progress = 0
        self._last_call = 0.0
        self._watcher: threading.Thread | None = None
        self._graph: Any = None
        self._stale: list[Any] = []
        """The references of cancelled calls' executions, oldest first (dropping one would make Ray wait for its
        result at once, in the thread that drops it)."""
        self.unavailable: str | None = unavailable_reason(ray)
        """Why compiled graphs cannot be used for this actor (None while they can)."""
        self.compiles = 0
        """How often the graph was compiled (a new graph after each reset or idle release)."""
        self.idle_releases = 0
        """How often the graph was torn down for want of calls."""

    def path(self) -> str:
        """Which path calls take: the compiled graph, or plain actor calls and why."""
        return COMPILED_GRAPH if self.unavailable is None else f"{PLAIN_CALLS} ({self.unavailable})"

    def _compiled(self) -> Any:
        """The compiled graph, compiled now when there is none (under the lock). A failure that is not the actor's
        death makes compiled graphs unavailable for this actor (the caller then makes plain calls)."""
        if self._graph is None:
            ray = self._ray
            from ray.dag import InputNode

            with InputNode() as arguments:
                graph = getattr(self._actor, self._method).bind(arguments)
            try:
                self._process_id = ray.get(getattr(self._actor, self._process_id_method).remote())
                self._graph = graph.experimental_compile(
                    _buffer_size_bytes=self.buffer_bytes, _submit_timeout=SUBMIT_SLICE
                )
            except ray.exceptions.RayActorError:
                raise
            except Exception as error:  # any other reason the graph cannot run here
                self.unavailable = f"the graph did not compile: {type(error).__name__}: {error}"[:300]
                raise ChannelClosedError(self.unavailable) from None
            self.compiles += 1
            self._last_call = time.monotonic()
            if self._watcher is None:
                self._watcher = threading.Thread(target=self._release_when_idle, name="idle graph", daemon=True)
                self._watcher.start()
        return self._graph

    def _verify(self, graph: Any, check: Callable[[], None], poll: float) -> None:
        """Make the new ``graph``'s first call, an empty one (``None``), and wait for its answer up to
        :data:`VERIFY_SECONDS` (under the lock); GraphStalledError when none comes."""
        ray = self._ray
        reference = graph.execute(None)
        deadline = time.monotonic() + VERIFY_SECONDS
        while True:
            try:
                graph._execute_until(reference._execution_index, reference._channel_index, poll)
            except ray.exceptions.RayChannelTimeoutError:
                if time.monotonic() > deadline:
                    break
                try:
                    check()
                except BaseException:
                    self._stale.append(reference)
                    raise
                continue
            except ray.exceptions.RayChannelError:
                pass  # closed: the get names the cause
            ray.get(reference)
            self._verified = graph
            return
        self._stale.append(reference)
        process_id = self._process_id
        ray.kill(self._actor, no_restart=False)
        self._teardown()
        raise GraphStalledError(
            f"the new compiled graph did not answer its first call in {VERIFY_SECONDS:g} s: its actor's process "
            f"{process_id} was ended for Ray to restart",
            process_id,
        )

    def _release_when_idle(self) -> None:
        """Tear the graph down once it took no call for ``idle_seconds`` (ends with the graph)."""
        while True:
            time.sleep(self.idle_seconds / 4)
            with self._lock:
                if self._graph is not None:
                    idle = time.monotonic() - self._last_call >= self.idle_seconds
                    if not idle or self._calls_in_progress or self._stale:
                        continue
                    self._teardown()
                    self.idle_releases += 1
                self._watcher = None
                return

    def call(self, arguments: Any, check: Callable[[], None], poll: float) -> Any:
        """The actor's answer to ``arguments`` (unpickled). ``check()`` is called every ``poll`` seconds while the
        call waits and ends it by raising (the execution's result is then dropped unread). ChannelClosedError
        when the graph is shut down or unavailable; Ray's errors of the call as they are."""
        ray = self._ray
        with self._lock:
            if self.unavailable is not None:
                raise ChannelClosedError(self.unavailable)
            self._calls_in_progress += 1
        pending = _Pending()
        try:
            with self._lock:
                graph = self._compiled()
                if self._verified is not graph:
                    self._verify(graph, check, poll)
            while pending.reference is None:
                with self._lock:
                    try:
                        pending.reference = graph.execute(arguments)
                    except ray.exceptions.RayChannelTimeoutError:  # the actor has not taken the last input yet
                        pass
                    except (ray.exceptions.RayChannelError, ray.exceptions.RayCgraphCapacityExceeded) as error:
                        raise ChannelClosedError(f"{type(error).__name__}: {_first_line(error)}") from None
                if pending.reference is None:
                    check()
            sent = time.perf_counter()
            self._nap(sent, check, poll)
            while True:
                with self._lock:
                    try:
                        graph._execute_until(pending.reference._execution_index, pending.reference._channel_index, poll)
                    except ray.exceptions.RayChannelTimeoutError:
                        finished = False
                    except ray.exceptions.RayChannelError:
                        finished = True  # closed: Ray's get below names the cause (the actor's death, say)
                    else:
                        finished = True
                    if finished:
                        reference, pending.reference = pending.reference, None
                        packed = ray.get(reference)
                        self._took.append(time.perf_counter() - sent)
                        self._drain()
                        break
                check()
        except ray.exceptions.RayChannelError as error:
            raise ChannelClosedError(f"{type(error).__name__}: {_first_line(error)}") from None
        finally:
            with self._lock:
                if pending.reference is not None:  # left to finish on the actor; a later call discards its result
                    self._stale.append(pending.reference)
                    pending.reference = None
                self._calls_in_progress -= 1
                self._last_call = time.monotonic()
        return ray.cloudpickle.loads(packed)

    def _nap(self, sent: float, check: Callable[[], None], poll: float) -> None:
        """Sleep through most of the time the answer is expected to take (``nap_fraction`` of the shortest of the
        last calls), checking ``check()`` every ``poll`` seconds: waiting in Ray's read polls a core."""
        with self._lock:
            if not self._took or self._stale:
                return
            wake = sent + self.nap_fraction * min(self._took)
        while (left := wake - time.perf_counter()) > 0:
            time.sleep(min(left, poll))
            check()

    def _drain(self) -> None:
        """Discard the results of the abandoned executions that have finished (under the lock). Their results
        are read when a later call reads past them (executions finish in order); read now, they free the graph's
        result buffer."""
        ray, graph = self._ray, self._graph
        while self._stale:
            reference = self._stale[0]
            try:
                graph._execute_until(reference._execution_index, reference._channel_index, 0)
            except ray.exceptions.RayChannelTimeoutError:
                return
            except ray.exceptions.RayChannelError:
                pass  # closed: the get below ends it
            self._stale.pop(0)
            with contextlib.suppress(Exception):  # an abandoned call's error is as unwanted as its answer
                ray.get(reference)

    def reset(self) -> None:
        """Tear the graph down (after its actor died, or before the actor is stopped); the next call compiles a
        new one."""
        with self._lock:
            self._teardown()

    def _teardown(self) -> None:
        """Tear the graph down (under the lock)."""
        graph, self._graph = self._graph, None
        if graph is not None:
            with contextlib.suppress(Exception):  # a graph whose actor is gone may fail to tear down; dropped
                graph.teardown()
        self._stale.clear()  # (a torn-down graph's references are dropped without waiting)


class _Pending:
    """The reference of the execution a call waits for (held in one place, so dropping it drops the last one)."""

    __slots__ = ("reference",)

    def __init__(self) -> None:
        self.reference: Any = None


def unavailable_reason(ray: ModuleType) -> str | None:
    """Why this Ray cannot run compiled graphs for remote experts (None when it can)."""
    try:
        from ray.dag import InputNode  # noqa: F401
        from ray.dag.compiled_dag_node import CompiledDAG
    except ImportError as error:
        return f"this Ray has no compiled graphs ({error})"
    if not hasattr(CompiledDAG, "_execute_until"):
        return "this Ray's compiled graphs cannot be waited for in slices"
    for name in ("RayChannelError", "RayChannelTimeoutError", "RayCgraphCapacityExceeded"):
        if not hasattr(ray.exceptions, name):
            return f"this Ray has no {name}"
    try:
        if ray.util.client.ray.is_connected():
            return "compiled graphs do not run through a Ray client connection"
    except AttributeError:
        pass
    return None


def _first_line(error: BaseException) -> str:
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__
