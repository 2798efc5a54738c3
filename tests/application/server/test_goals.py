"""The goal manager in-process: a crashing expert inside a served tree aborts only its goal; the next succeeds."""

from __future__ import annotations

import importlib
import queue
from pathlib import Path
from typing import Any

import pytest

from annotators.catalog import AnnotatorCatalog
from robokudo.application.server.goals import Goal, GoalManager
from robokudo.application.server.protocol import GoalStatus
from robokudo.application.service import AnsweringService

WAIT = 60.0

CRASHING_MODULE = '''
"""An expert that crashes on every frame."""

from __future__ import annotations

from typing import ClassVar

from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis, SemanticColor


class TealCrasher(Annotator):
    """Claims to tell teal objects, and raises instead."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (SemanticColor,)
    capability: ClassVar[Capability] = Capability(label="teal crasher", colors=("Teal",), cost_ms=1.0, reliability=0.9)

    def analyse(self) -> None:
        raise RuntimeError("the teal crasher broke")
'''


@pytest.fixture()
def crasher(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> type:
    (tmp_path / "my_teal_crasher.py").write_text(CRASHING_MODULE, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    return importlib.import_module("my_teal_crasher").TealCrasher


def result_of(messages: queue.SimpleQueue[dict[str, Any]]) -> dict[str, Any]:
    while (message := messages.get(timeout=WAIT))["op"] != "action_result":
        pass
    return message


def test_a_crashing_expert_aborts_its_goal_with_the_reason_and_the_next_goal_succeeds(
    tmp_path: Path, crasher: type
) -> None:
    catalog = AnnotatorCatalog.discover(extra=[crasher])
    service = AnsweringService.open(tmp_path / "beliefs.sqlite", catalog=catalog)
    goals = GoalManager(service)
    messages: queue.SimpleQueue[dict[str, Any]] = queue.SimpleQueue()
    owner = object()
    try:
        goals.submit(Goal("teal", "detect { obj: { color: teal } }", owner, messages.put))
        crashed = result_of(messages)
        assert crashed["status"] == GoalStatus.ABORTED
        assert "TealCrasher" in crashed["values"]["reason"] and "broke" in crashed["values"]["reason"]
        goals.submit(Goal("milk", "find milk in fridge", owner, messages.put))
        found = result_of(messages)
        assert found["status"] == GoalStatus.SUCCEEDED and found["values"]["objects"]
    finally:
        goals.close("the test ended")
