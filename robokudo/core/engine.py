"""The analysis engine: ticks a tree at a fixed rate and swaps task subtrees at run time."""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import py_trees
from py_trees.common import Status

from robokudo.core.annotator import Annotator
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.slot import TaskSlot
from robokudo.core.stats import RunStats
from robokudo.core.structure import check_structure


@dataclass
class _SlotChange:
    slot: TaskSlot
    subtree: py_trees.behaviour.Behaviour | None
    restart: bool = False
    only_replacing: py_trees.behaviour.Behaviour | None = None
    applied: threading.Event = field(default_factory=threading.Event)
    previous: py_trees.behaviour.Behaviour | None = None


class TaskInterface:
    """Inserts, replaces or removes the subtree in a named TaskSlot while the engine keeps ticking.

    Changes are queued and applied by the engine between two ticks, so a tick never sees a half-swapped
    tree; the subtree taken out is stopped (its running annotators are interrupted).
    """

    def __init__(self, engine: Engine) -> None:
        self._engine = engine
        self._changes: queue.SimpleQueue[_SlotChange] = queue.SimpleQueue()

    def slot(self, name: str) -> TaskSlot:
        """The TaskSlot called ``name``; raises KeyError listing the slots present."""
        slots = [n for n in self._engine.root.iterate() if isinstance(n, TaskSlot)]
        for found in slots:
            if found.name == name:
                return found
        raise KeyError(f"no TaskSlot named {name!r} (slots: {', '.join(s.name for s in slots) or 'none'})")

    def replace(
        self,
        slot_name: str,
        subtree: py_trees.behaviour.Behaviour | None,
        timeout: float = 5.0,
        *,
        restart: bool = False,
    ) -> py_trees.behaviour.Behaviour | None:
        """Put ``subtree`` into the slot (None removes); returns the subtree taken out.

        The tree structure is checked first, so a bad subtree is rejected before anything changes. When the
        engine ticks in a background thread this waits (up to ``timeout`` s) until the change is applied.
        ``restart`` also ends the root's current run, so the next tick starts the root from its first child (in
        the Fig. 4 shape: the new task starts on a freshly perceived frame).
        """
        slot = self.slot(slot_name)
        if subtree is not None:
            check_structure(subtree, attach_to=slot)
            validate_data_flow(self._engine.root, substitute={slot: subtree})
        change = _SlotChange(slot, subtree, restart)
        self._changes.put(change)
        if self._engine.is_running_in_background():
            if not change.applied.wait(timeout):
                raise TimeoutError(f"the engine did not apply the change to slot {slot_name!r} in {timeout} s")
        else:
            self.apply_pending()
        return change.previous

    def schedule(
        self,
        slot_name: str,
        subtree: py_trees.behaviour.Behaviour | None,
        *,
        only_replacing: py_trees.behaviour.Behaviour | None = None,
    ) -> None:
        """Queue a change for the start of the next tick without waiting (callable from the engine's own thread,
        e.g. a post-tick handler, so every handler still sees this tick's tree). With ``only_replacing`` the
        change is dropped unless the slot still holds that subtree then (a change queued meanwhile wins)."""
        slot = self.slot(slot_name)
        if subtree is not None:
            check_structure(subtree, attach_to=slot)
        self._changes.put(_SlotChange(slot, subtree, only_replacing=only_replacing))

    def insert(self, slot_name: str, subtree: py_trees.behaviour.Behaviour) -> None:
        """Put ``subtree`` into an empty slot."""
        if self.slot(slot_name).subtree is not None:
            raise ValueError(f"slot {slot_name!r} is occupied; use replace()")
        self.replace(slot_name, subtree)

    def remove(self, slot_name: str) -> py_trees.behaviour.Behaviour | None:
        """Empty the slot; returns the subtree taken out."""
        return self.replace(slot_name, None)

    def apply_pending(self) -> None:
        """Apply queued changes (called by the engine between ticks)."""
        while True:
            try:
                change = self._changes.get_nowait()
            except queue.Empty:
                return
            if change.only_replacing is not None and change.slot.subtree is not change.only_replacing:
                change.applied.set()
                continue
            change.previous = change.slot.set_subtree(change.subtree)
            if change.restart and self._engine.root.status is Status.RUNNING:
                self._engine.root.stop(Status.INVALID)
            change.applied.set()


class Engine:
    """Ticks a behaviour tree at ``hz`` ticks per second; owns the task interface."""

    def __init__(self, root: py_trees.behaviour.Behaviour, hz: float = 10.0) -> None:
        """Check the tree's structure and data flow (raising StructureError / DataFlowError), then wrap it."""
        check_structure(root)
        validate_data_flow(root)
        if hz <= 0:
            raise ValueError(f"tick frequency must be positive, got {hz}")
        self.root = root
        self.hz = hz
        self.tree = py_trees.trees.BehaviourTree(root)
        self.tasks = TaskInterface(self)
        self.tick_count = 0
        self.tick_started = 0.0
        """When the current (or last) tick began (``time.monotonic``)."""
        self.tick_stats = RunStats()
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()

    def tick(self) -> Status:
        """Apply pending task changes, then tick the tree once; returns the root's status."""
        self.tasks.apply_pending()
        start = time.perf_counter()
        self.tick_started = time.monotonic()
        self.tree.tick()
        self.tick_stats.record(time.perf_counter() - start)
        self.tick_count += 1
        return self.root.status

    def run(self, ticks: int | None = None, until: Callable[[Status], bool] | None = None) -> Status:
        """Tick at the fixed rate until ``ticks`` ticks were done, ``until(status)`` holds or stop() is called."""
        period = 1.0 / self.hz
        next_tick = time.perf_counter()
        done = 0
        status = self.root.status
        while not self._stop.is_set() and (ticks is None or done < ticks):
            status = self.tick()
            done += 1
            if until is not None and until(status):
                break
            next_tick += period
            delay = next_tick - time.perf_counter()
            if delay > 0:
                self._stop.wait(delay)
            else:
                next_tick = time.perf_counter()  # overran: do not try to catch up with a burst of ticks
        return status

    def start(self) -> None:
        """Tick in a background thread until stop()."""
        if self.is_running_in_background():
            raise RuntimeError("the engine is already running")
        self._stop.clear()
        self._thread = threading.Thread(target=self.run, name="robokudo-engine", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop ticking and interrupt whatever is running."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
            self._stop.clear()  # the background run has ended; a later run() or start() may tick again
        if self.root.status is Status.RUNNING:
            self.root.stop(Status.INVALID)
        self.tasks.apply_pending()

    def is_running_in_background(self) -> bool:
        """True while the background tick thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    def annotator_stats(self) -> dict[str, RunStats]:
        """Run-time statistics of every annotator in the tree, by node name."""
        return {node.name: node.stats for node in self.root.iterate() if isinstance(node, Annotator)}
