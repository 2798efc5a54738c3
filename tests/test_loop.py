"""The Loop decorator (the paper's ↻): runs its child once per tick at most, counts runs, ends only when told."""

from __future__ import annotations

import py_trees
import pytest
from hypothesis import given
from hypothesis import strategies as st
from py_trees.common import Status

from robokudo.core.loop import Loop, frame_pipeline
from robokudo.core.pipeline import Pipeline

FINISHED = (Status.SUCCESS, Status.FAILURE)


class Scripted(py_trees.behaviour.Behaviour):
    """A leaf that returns the next status of its script on every tick (the script must not run out)."""

    def __init__(self, script: list[Status]) -> None:
        super().__init__(name="scripted")
        self.script = list(script)
        self.ticks = 0
        self.starts = 0

    def initialise(self) -> None:
        self.starts += 1

    def update(self) -> Status:
        self.ticks += 1
        return self.script.pop(0)


statuses = st.lists(st.sampled_from([Status.SUCCESS, Status.FAILURE, Status.RUNNING]), min_size=1, max_size=60)


def run(loop: Loop, ticks: int) -> list[Status]:
    seen = []
    for _ in range(ticks):
        loop.tick_once()
        seen.append(loop.status)
        if loop.status is not Status.RUNNING:
            break
    return seen


@given(statuses)
def test_until_stopped_it_never_ends_and_counts_every_finished_run(script: list[Status]) -> None:
    child = Scripted(script)
    loop = Loop("loop", child, runs=None, max_failures=None)
    assert run(loop, len(script)) == [Status.RUNNING] * len(script)
    assert child.ticks == len(script)  # one run step per tick, never two
    assert loop.succeeded == script.count(Status.SUCCESS) and loop.failed == script.count(Status.FAILURE)
    finished = sum(s in FINISHED for s in script)
    assert child.starts == 1 + finished - (script[-1] in FINISHED)  # a new run starts after each finished one


@given(statuses, st.integers(min_value=0, max_value=5))
def test_it_fails_on_the_first_run_beyond_the_allowed_failures_in_a_row(script: list[Status], allowed: int) -> None:
    loop = Loop("loop", Scripted(script), max_failures=allowed)
    seen = run(loop, len(script))
    in_a_row, end = 0, None
    for index, status in enumerate(script):
        in_a_row = in_a_row + 1 if status is Status.FAILURE else (0 if status is Status.SUCCESS else in_a_row)
        if in_a_row > allowed:
            end = index
            break
    if end is None:
        assert seen == [Status.RUNNING] * len(script)
    else:
        assert seen == [Status.RUNNING] * end + [Status.FAILURE]
        assert loop.failures_in_a_row == allowed + 1 and "failed" in loop.feedback_message


@given(statuses, st.integers(min_value=1, max_value=5))
def test_a_bounded_loop_succeeds_on_its_last_successful_run(script: list[Status], runs: int) -> None:
    loop = Loop("loop", Scripted(script), runs=runs, max_failures=None)
    seen = run(loop, len(script))
    successes = [i for i, s in enumerate(script) if s is Status.SUCCESS]
    if len(successes) >= runs:
        assert seen == [Status.RUNNING] * successes[runs - 1] + [Status.SUCCESS]
    else:
        assert seen == [Status.RUNNING] * len(script)


def test_stopping_a_running_loop_stops_its_running_child_and_a_restart_counts_anew() -> None:
    child = Scripted([Status.SUCCESS, Status.RUNNING, Status.SUCCESS])
    loop = Loop("loop", child)
    run(loop, 2)
    assert loop.succeeded == 1 and child.status is Status.RUNNING
    loop.stop(Status.INVALID)
    assert child.status is Status.INVALID and loop.status is Status.INVALID
    loop.tick_once()
    assert loop.succeeded == 1 and loop.completed == 1  # counted afresh after the restart


def test_frame_pipeline_finds_the_pipeline_a_loop_repeats() -> None:
    pipeline = Pipeline("every frame", [Scripted([Status.SUCCESS])])
    assert frame_pipeline(Loop("loop", pipeline)) is pipeline
    assert frame_pipeline(pipeline) is pipeline
    assert frame_pipeline(Scripted([])) is None


@pytest.mark.parametrize("bad", [{"runs": 0}, {"runs": True}, {"max_failures": -1}, {"max_failures": 1.5}])
def test_bad_limits_are_refused(bad: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        Loop("loop", Scripted([]), **bad)  # type: ignore[arg-type]


@given(st.lists(st.booleans(), min_size=1, max_size=40))
def test_a_pipeline_in_a_loop_gets_a_fresh_cas_per_run(successes: list[bool]) -> None:
    script = [Status.SUCCESS if ok else Status.FAILURE for ok in successes]
    pipeline = Pipeline("every frame", [Scripted(script)])
    loop = Loop("loop", pipeline, max_failures=None)
    seen = []
    for _ in script:
        loop.tick_once()
        seen.append(pipeline.cas)  # kept alive, so identities cannot be reused
    assert len({id(cas) for cas in seen}) == len(script)
