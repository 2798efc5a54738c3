"""Tick-by-tick behaviour-tree semantics: Sequence, Fallback (with and without memory) and ThresholdParallel."""

from __future__ import annotations

import py_trees
import pytest
from py_trees.common import Status

from robokudo.core.parallel import ThresholdParallel
from tests.support import Scripted

S, F, R, INV = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID


def tick(root: py_trees.behaviour.Behaviour) -> Status:
    root.tick_once()
    return root.status


# Each case: composite kind, memory, child scripts, expected (root status, updates per child) after each tick.
COMPOSITE_CASES = [
    ("sequence", False, [[S], [S]], [(S, [1, 1])]),
    ("sequence", False, [[S], [F]], [(F, [1, 1])]),
    ("sequence", False, [[F], [S]], [(F, [1, 0])]),
    # without memory the first child is ticked again while the second runs
    ("sequence", False, [[S], [R, R, S]], [(R, [1, 1]), (R, [2, 2]), (S, [3, 3])]),
    # with memory a finished child is not ticked again while a later one runs
    ("sequence", True, [[S], [R, R, S]], [(R, [1, 1]), (R, [1, 2]), (S, [1, 3])]),
    ("sequence", True, [[R, S], [S]], [(R, [1, 0]), (S, [2, 1])]),
    ("fallback", False, [[F], [S]], [(S, [1, 1])]),
    ("fallback", False, [[S], [S]], [(S, [1, 0])]),
    ("fallback", False, [[F], [F]], [(F, [1, 1])]),
    ("fallback", False, [[F], [R, R, F]], [(R, [1, 1]), (R, [2, 2]), (F, [3, 3])]),
    ("fallback", True, [[F], [R, R, F]], [(R, [1, 1]), (R, [1, 2]), (F, [1, 3])]),
    # a higher-priority child that starts succeeding pre-empts the running lower one (no memory)
    ("fallback", False, [[F, S], [R, R]], [(R, [1, 1]), (S, [2, 1])]),
]


@pytest.mark.parametrize(("kind", "memory", "scripts", "expected"), COMPOSITE_CASES)
def test_sequence_and_fallback_tick_by_tick(kind, memory, scripts, expected) -> None:
    children = [Scripted(f"c{i}", script) for i, script in enumerate(scripts)]
    if kind == "sequence":
        root = py_trees.composites.Sequence("root", memory=memory, children=children)
    else:
        root = py_trees.composites.Selector("root", memory=memory, children=children)
    for step, (status, updates) in enumerate(expected, start=1):
        assert tick(root) is status, f"tick {step}"
        assert [c.updates for c in children] == updates, f"tick {step}"


def test_preempted_running_child_is_terminated_with_invalid() -> None:
    high, low = Scripted("high", [F, S]), Scripted("low", [R, R])
    root = py_trees.composites.Selector("root", memory=False, children=[high, low])
    tick(root)
    assert low.status is R
    tick(root)
    assert low.terminated[-1] is INV
    assert low.status is INV


def test_interrupting_a_running_sequence_stops_its_running_children() -> None:
    first, second = Scripted("first", [S]), Scripted("second", [R])
    sequence = py_trees.composites.Sequence("seq", memory=True, children=[first, second])
    assert tick(sequence) is R
    sequence.stop(INV)
    assert second.terminated == [INV]
    assert second.status is INV and sequence.status is INV


def test_sequence_restarts_from_first_child_after_finishing() -> None:
    first, second = Scripted("first", [S]), Scripted("second", [S])
    sequence = py_trees.composites.Sequence("seq", memory=True, children=[first, second])
    tick(sequence)
    tick(sequence)
    assert (first.updates, second.updates) == (2, 2)
    assert first.initialised == 2


# (n_success, n_failure, child statuses) -> status. SUCCESS when successes > n_success, FAILURE when
# failures > n_failure (failure checked first), FAILURE when all finished without reaching either.
PARALLEL_TABLE = [
    (1, 0, [S, S], S),
    (1, 0, [S, F], F),
    (1, 0, [S, R], R),
    (1, 0, [R, R], R),
    (0, 1, [S, R], S),
    (0, 1, [F, R], R),
    (0, 1, [F, F], F),
    (0, 1, [F, S], S),
    (0, 0, [S, F], F),  # tie: both thresholds crossed on the same tick -> failure wins
    (1, 1, [S, F, R], R),
    (1, 1, [S, F, S], S),
    (1, 1, [F, F, S], F),
    (2, 2, [S, S, F], F),  # all finished, neither threshold crossed: can never succeed
    (0, 2, [R, R, R], R),
    (0, 2, [F, F, R], R),
    (0, 2, [F, F, F], F),
    (2, 0, [S, S, S], S),
]


@pytest.mark.parametrize(("n_success", "n_failure", "statuses", "expected"), PARALLEL_TABLE)
def test_threshold_parallel_decision_table(n_success, n_failure, statuses, expected) -> None:
    parallel = ThresholdParallel("p", n_success=n_success, n_failure=n_failure)
    assert parallel.decide(statuses) is expected
    # the same outcome when the statuses come from real children in one tick
    children = [Scripted(f"c{i}", [s]) for i, s in enumerate(statuses)]
    ticked = ThresholdParallel("p", children=children, n_success=n_success, n_failure=n_failure)
    assert tick(ticked) is expected


def test_parallel_does_not_retick_finished_children_and_stops_running_ones() -> None:
    quick, slow, forever = Scripted("quick", [S]), Scripted("slow", [R, S]), Scripted("forever", [R])
    parallel = ThresholdParallel("p", children=[quick, slow, forever], n_success=1, n_failure=0)
    assert tick(parallel) is R
    assert tick(parallel) is S  # quick and slow succeeded: 2 > 1
    assert quick.updates == 1  # finished children keep their result
    assert forever.terminated[-1] is INV  # still running when the parallel finished: interrupted


def test_parallel_restarts_all_children_on_a_new_run() -> None:
    a, b = Scripted("a", [S]), Scripted("b", [S])
    parallel = ThresholdParallel("p", children=[a, b])
    tick(parallel)
    tick(parallel)
    assert (a.updates, b.updates) == (2, 2)


def test_default_parallel_needs_all_children() -> None:
    parallel = ThresholdParallel("p", children=[Scripted("a", [S]), Scripted("b", [F])])
    assert parallel.n_success == 1
    assert tick(parallel) is F
