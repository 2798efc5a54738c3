"""The ``/robokudo/tree_status`` message: every node's status, and each annotator's last run time and run count."""

from __future__ import annotations

import json
import time
from typing import Any

from py_trees.common import Status

from robokudo import Engine, Pipeline
from robokudo.application.server.tree_status import tree_status
from robokudo.core.annotator import Annotator
from robokudo.core.types import Plane
from tests.support import Scripted, annotator_class

PAUSE = 0.02


def _slow(annotator: Annotator) -> None:
    time.sleep(PAUSE)


def _find(entry: dict[str, Any], name: str) -> dict[str, Any]:
    """The node called ``name`` in a tree status entry."""
    pending = [entry]
    while pending:
        node = pending.pop()
        if node["name"] == name:
            return node
        pending.extend(node.get("children", []))
    raise KeyError(name)


def test_each_annotator_reports_its_last_run_time_and_run_count() -> None:
    slow = annotator_class("Slow", work=_slow)()
    quick = annotator_class("Quick", outputs=[Plane])()
    heartbeat = Scripted("heartbeat", [Status.SUCCESS])
    engine = Engine(Pipeline("robot", [heartbeat, slow, quick]), hz=100)
    engine.tick()
    first = tree_status(engine.root, engine.tick_count)
    engine.tick()
    second = json.loads(json.dumps(tree_status(engine.root, engine.tick_count)))  # what a client receives

    assert _find(first["tree"], "Slow")["timing"]["runs"] == 1
    slow_timing = _find(second["tree"], "Slow")["timing"]
    quick_timing = _find(second["tree"], "Quick")["timing"]
    assert slow_timing["runs"] == quick_timing["runs"] == 2
    assert slow_timing["last_ms"] >= PAUSE * 1e3
    assert 0 <= quick_timing["last_ms"] < slow_timing["last_ms"]
    assert "timing" not in second["tree"]  # a composite
    assert "timing" not in _find(second["tree"], "heartbeat")  # a behaviour that is no annotator


def test_an_annotator_that_has_not_run_reports_no_runs() -> None:
    waiting = annotator_class("Waiting")()
    status = tree_status(Pipeline("robot", [waiting]), 0)
    assert _find(status["tree"], "Waiting")["timing"] == {"last_ms": 0.0, "runs": 0}
