"""ThreadedAnnotator responsiveness, interruption and timeout; the engine's subtree swap; rendering."""

from __future__ import annotations

import shutil
import subprocess
import time

import py_trees
import pytest
from py_trees.common import Status

from robokudo import DataFlowError, Engine, Pipeline, StructureError, TaskSlot, ThresholdParallel
from robokudo.core.render import dot_tree, stats_table, unicode_tree
from robokudo.core.types import ObjectHypothesis, Plane
from tests.support import GatedWork, Scripted, annotator_class


def test_threaded_annotator_keeps_other_branches_ticking() -> None:
    worker = GatedWork()
    heartbeat = Scripted("heartbeat", [Status.RUNNING])
    parallel = ThresholdParallel("side by side", [worker, heartbeat], n_success=0, n_failure=1)
    pipeline = Pipeline("p", [parallel])
    for _ in range(20):
        pipeline.tick_once()
    assert worker.status is Status.RUNNING
    assert heartbeat.updates == 20  # the tick loop never waited for the worker
    worker.release.set()
    assert worker.finished.wait(2)
    pipeline.tick_once()
    assert worker.status is Status.SUCCESS
    assert len(pipeline.cas.annotations(Plane)) == 1


def test_interrupted_threaded_annotator_stops_and_discards_its_writes() -> None:
    worker = GatedWork()
    pipeline = Pipeline("p", [worker])
    pipeline.tick_once()
    assert worker.started.wait(2)
    pipeline.stop(Status.INVALID)
    assert worker.finished.wait(2)  # the worker saw the cancel flag and ended
    assert not worker.is_working() or worker.finished.is_set()
    assert pipeline.cas.annotations(Plane) == []


def test_threaded_annotator_times_out_with_a_reason() -> None:
    worker = GatedWork(timeout=0.05)
    pipeline = Pipeline("p", [worker])
    pipeline.tick_once()
    assert worker.started.wait(2)
    time.sleep(0.1)
    pipeline.tick_once()
    assert worker.status is Status.FAILURE
    assert worker.feedback_message.startswith("timed out")
    assert worker.finished.wait(2)  # the worker saw the cancel flag and ended
    assert pipeline.cas.annotations(Plane) == []


def _root_with_slot() -> tuple[Pipeline, TaskSlot, Scripted]:
    slot = TaskSlot("task")
    heartbeat = Scripted("reader", [Status.SUCCESS])
    root = Pipeline("robot", [heartbeat, slot])
    return root, slot, heartbeat


def test_subtree_swap_while_the_engine_runs_stops_the_old_subtree() -> None:
    root, slot, heartbeat = _root_with_slot()
    engine = Engine(root, hz=200)
    first = GatedWork("first-task")
    engine.start()
    try:
        engine.tasks.insert("task", first)
        assert first.started.wait(2)
        ticks_before = engine.tick_count
        second = annotator_class("SecondTask", outputs=[ObjectHypothesis])()
        previous = engine.tasks.replace("task", second)
        assert previous is first
        assert first.finished.wait(2)  # the swapped-out worker was cancelled
        assert first.status is Status.INVALID
        assert slot.subtree is second
        deadline = engine.tick_count + 5
        while engine.tick_count < deadline:
            pass
        assert second.stats.count > 0  # the new subtree runs without restarting the engine
        assert engine.tick_count > ticks_before
    finally:
        engine.stop()
    assert heartbeat.updates > 0


def test_bad_subtree_is_rejected_before_the_swap() -> None:
    root, slot, _ = _root_with_slot()
    engine = Engine(root)
    needs_plane = annotator_class("NeedsPlane", inputs=[Plane])()
    with pytest.raises(DataFlowError, match="NeedsPlane reads Plane"):
        engine.tasks.replace("task", needs_plane)
    assert slot.subtree is None
    with pytest.raises(StructureError, match="repeated: robot"):
        engine.tasks.replace("task", Pipeline("robot"))


def test_empty_slot_is_idle_and_engine_collects_stats() -> None:
    root, _, _ = _root_with_slot()
    engine = Engine(root, hz=1000)
    engine.tasks.insert("task", annotator_class("Work", outputs=[Plane])())
    assert engine.run(ticks=3) is Status.SUCCESS
    assert engine.annotator_stats()["Work"].count == 3
    assert "Work" in stats_table(root)
    engine.tasks.remove("task")
    assert engine.tick() is Status.SUCCESS


def test_unicode_and_dot_rendering_show_structure_and_reasons() -> None:
    work = annotator_class("Segmenter", outputs=[ObjectHypothesis])()
    work.reason = "the query needs object hypotheses"
    fallback = py_trees.composites.Selector("choose", memory=False, children=[work])
    root = Pipeline("p", [fallback])
    text = unicode_tree(root)
    assert "Pipeline p" in text and "Fallback choose" in text
    assert "└── Segmenter  # the query needs object hypotheses" in text
    dot = dot_tree(root)
    assert 'tooltip="the query needs object hypotheses"' in dot
    if shutil.which("dot"):
        svg = subprocess.run(["dot", "-Tsvg"], input=dot, capture_output=True, text=True, check=True).stdout
        assert "<svg" in svg
