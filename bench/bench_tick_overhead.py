"""Tick overhead per node: robokudo's node classes vs bare py_trees nodes that do nothing, in one run.

Both trees have the same shape (a root Sequence of N leaves); the robokudo tree is a Pipeline whose leaves
are Annotators with declared ports doing nothing, the bare tree a py_trees Sequence of py_trees
``Success`` behaviours. A ThresholdParallel vs py_trees Parallel pair is measured the same way.
Rounds alternate between the two so machine noise hits both alike, and time is the process's CPU time: on a
shared machine wall time also counts the moments other processes held the core.
"""

from __future__ import annotations

import statistics
import time

import py_trees

from robokudo import Annotator, Pipeline, ThresholdParallel
from robokudo.core.types import Plane

LEAVES = 50
ROUNDS = 15
TICKS_PER_ROUND = 400
GOAL_RATIO = 1.1  # issue 19: ours at most 1.1x bare py_trees per node tick


class Idle(Annotator):
    """An annotator that declares a port and does nothing."""

    inputs = ()
    outputs = (Plane,)

    def analyse(self) -> None:
        """Nothing to do."""


def ours_sequence() -> py_trees.behaviour.Behaviour:
    return Pipeline("ours", [Idle(f"idle{i}") for i in range(LEAVES)])


def bare_sequence() -> py_trees.behaviour.Behaviour:
    return py_trees.composites.Sequence(
        "bare", memory=True, children=[py_trees.behaviours.Success(f"s{i}") for i in range(LEAVES)]
    )


def ours_parallel() -> py_trees.behaviour.Behaviour:
    return Pipeline("ours", [ThresholdParallel("p", [Idle(f"idle{i}") for i in range(LEAVES)])])


def bare_parallel() -> py_trees.behaviour.Behaviour:
    policy = py_trees.common.ParallelPolicy.SuccessOnAll(synchronise=False)
    return py_trees.composites.Parallel(
        "p", policy=policy, children=[py_trees.behaviours.Success(f"s{i}") for i in range(LEAVES)]
    )


def seconds_per_node_tick(root: py_trees.behaviour.Behaviour) -> float:
    start = time.process_time()
    for _ in range(TICKS_PER_ROUND):
        root.tick_once()
    return (time.process_time() - start) / (TICKS_PER_ROUND * LEAVES)


def compare(label: str, ours: py_trees.behaviour.Behaviour, bare: py_trees.behaviour.Behaviour) -> bool:
    """Print the medians and their ratio; True when the ratio meets the goal."""
    ours_samples, bare_samples = [], []
    for _ in range(ROUNDS):
        ours_samples.append(seconds_per_node_tick(ours))
        bare_samples.append(seconds_per_node_tick(bare))
    ours_median, bare_median = statistics.median(ours_samples), statistics.median(bare_samples)
    ratio = ours_median / bare_median
    met = ratio <= GOAL_RATIO
    print(
        f"{label:28s} ours {ours_median * 1e6:7.2f} µs/node   bare py_trees {bare_median * 1e6:7.2f} µs/node   "
        f"ratio {ratio:5.2f}  {'met' if met else 'NOT met'}"
    )
    return met


def main() -> None:
    print(f"tick overhead, {LEAVES} leaves, median of {ROUNDS} alternating rounds x {TICKS_PER_ROUND} ticks")
    print(f"goal: ratio <= {GOAL_RATIO} (ours / bare py_trees)")
    results = [
        compare("Sequence of leaves", ours_sequence(), bare_sequence()),
        compare("Parallel of leaves", ours_parallel(), bare_parallel()),
    ]
    print(f"goal {'met' if all(results) else 'NOT met'}")


if __name__ == "__main__":
    main()
