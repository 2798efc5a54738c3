"""Data-parallel work on a Ray cluster: one task per item, at most N at a time, results in the items' order.

Used by ``robokudo eval ... --workers N [--address ...]``: each scene is a Ray task (one CPU), run on a local
cluster (default) or the one at the address, with a progress bar on a terminal. The tasks run the same code as
the sequential loop, so the figures are the same. An exception a task raises is raised here as itself.

On a given cluster (``--address``, which may grow) or a local one with more CPUs than N the tasks run in a
placement group of N one-CPU bundles, so at most N run at once; on a local cluster of N CPUs or fewer (the one
``--workers N`` starts) one-CPU tasks cannot run more than N at once anyway, and no group is made: Ray returns
a removed group's resources asynchronously, so a group made right after another waits 0.5-1 s for them. Twice
as many tasks are handed to Ray as run: the next item is waiting on a worker's node when its task ends (no round
trip to this process between two items). Ray reuses its worker processes, so each loads the code once.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from tqdm import tqdm

from robokudo.application.cluster import ray_cluster

RETRIES = 3
"""How often a task whose worker process died (e.g. killed by Ray's memory monitor when the machine runs low on
memory) is run again; an exception the function raises is not retried."""

FAILURE_WAIT_SECONDS = 60.0
"""How long a map whose task failed waits for the tasks still in flight before it raises that task's exception;
tasks still running then are left to the cluster (a local one stops them as it shuts down)."""

T = TypeVar("T")
R = TypeVar("R")


def progress(total: int, label: str) -> tqdm:
    """A progress bar on stderr (shown only when stderr is a terminal)."""
    return tqdm(total=total, desc=label, unit="item", file=sys.stderr, disable=None, leave=False)


def run_in_order(function: Callable[..., R], items: Sequence[T], *extra: Any, label: str = "") -> list[R]:
    """``function(item, *extra)`` for each item in this process, with a progress bar."""
    results = []
    with progress(len(items), label) as bar:
        for item in items:
            results.append(function(item, *extra))
            bar.update()
    return results


def map_on_cluster(
    function: Callable[..., R],
    items: Sequence[T],
    *extra: Any,
    workers: int,
    address: str | None = None,
    label: str = "",
    purpose: str = "running tasks on a cluster",
    failure_wait: float = FAILURE_WAIT_SECONDS,
) -> list[R]:
    """``function(item, *extra)`` for each item as Ray tasks, at most ``workers`` at once (one CPU each, and a
    placement group of ``workers`` one-CPU bundles on a given cluster or a bigger one), on the cluster at
    ``address`` (None: a local one with ``workers`` CPUs); the results in the items' order. The task's own
    exception when one fails, once the tasks in flight have ended or ``failure_wait`` seconds have passed (an
    interrupt cancels them instead); ClusterError without Ray (``PURPOSE needs Ray``) or a cluster."""
    if workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    with ray_cluster(address, num_cpus=workers, purpose=purpose) as ray:
        shared = [ray.put(value) for value in extra]
        if address is None and ray.cluster_resources().get("CPU", 0.0) <= workers:  # a given cluster may grow
            task = ray.remote(function).options(num_cpus=1, max_retries=RETRIES)
            return _in_order(ray, task, items, shared, 2 * workers, label, failure_wait)
        from ray.util.placement_group import placement_group, remove_placement_group
        from ray.util.scheduling_strategies import PlacementGroupSchedulingStrategy

        group = placement_group([{"CPU": 1}] * workers)
        try:
            ray.get(group.ready())
            task = ray.remote(function).options(
                num_cpus=1, max_retries=RETRIES, scheduling_strategy=PlacementGroupSchedulingStrategy(group)
            )
            return _in_order(ray, task, items, shared, 2 * workers, label, failure_wait)
        finally:
            remove_placement_group(group)


def _in_order(
    ray: Any, task: Any, items: Sequence[T], shared: list[Any], in_flight: int, label: str, failure_wait: float
) -> list[Any]:
    """``task`` on each item with the ``shared`` arguments, ``in_flight`` handed to Ray at a time; the results in
    the items' order. A failure is raised once the tasks in flight have ended, or after ``failure_wait`` seconds."""
    results: list[Any] = [None] * len(items)
    running: dict[Any, int] = {}
    upcoming = iter(enumerate(items))
    with progress(len(items), label) as bar:
        try:
            while True:
                while len(running) < in_flight:
                    index, item = next(upcoming, (-1, None))
                    if index < 0:
                        break
                    running[task.remote(item, *shared)] = index
                if not running:
                    break
                done, _ = ray.wait(list(running), num_returns=1)
                for reference in done:
                    index = running.pop(reference)  # before the result, which may raise
                    results[index] = _result(ray, reference)
                    bar.update()
        except Exception:
            # a task failed: the ones in flight (at most ``in_flight``) end on their own and their results are dropped;
            # cancelling them would race with their end, which aborts Ray 2.60's whole process
            if running:
                ray.wait(list(running), num_returns=len(running), timeout=failure_wait)
            raise
        except BaseException:  # interrupted (Ctrl-C): stop the work in flight rather than wait for it
            _cancel_unfinished(ray, list(running))
            raise
    return results


def _cancel_unfinished(ray: Any, references: list[Any]) -> None:
    """Cancel the tasks of ``references`` that have not ended. Ray 2.60 aborts this process ("Tried to complete
    task that was not pending") when a task is cancelled while its end is being recorded, so a task that has
    ended already is left alone; one that ends between that check and its cancel can still abort it, which is why
    only an interrupted map cancels."""
    if not references:
        return
    _, unfinished = ray.wait(references, num_returns=len(references), timeout=0)
    for reference in unfinished:
        ray.cancel(reference)


def _result(ray: Any, reference: Any) -> Any:
    try:
        return ray.get(reference)
    except ray.exceptions.RayTaskError as error:
        cause = getattr(error, "cause", None)
        if isinstance(cause, Exception):
            raise cause from None
        raise
