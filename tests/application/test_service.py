"""The answering service: one knowledge base, planner, store and engine for many queries; kinds -> modes."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from queries import KINDS, parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.service import EXECUTION_MODES, TASK_SLOT, AnsweringService, ExecutionMode


@pytest.fixture
def service(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[AnsweringService]:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    with AnsweringService.open(tmp_path / "beliefs.sqlite") as opened:
        yield opened


def test_three_queries_share_one_engine_and_one_knowledge_base_load(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    loads: list[KnowledgeBase] = []
    original_init = KnowledgeBase.__init__

    def counting_init(self: KnowledgeBase, *args: object, **kwargs: object) -> None:
        loads.append(self)
        original_init(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(KnowledgeBase, "__init__", counting_init)
    with AnsweringService.open(tmp_path / "beliefs.sqlite") as service:
        engine = service.engine
        milk = service.answer("find milk in fridge").answer
        ticks_after_first = engine.tick_count
        cup = service.answer("find the red cup").answer
        # (not the bowl: from the table camera it is a blue sphere, a bowl as much as a fruit, so it is stored as an
        # unknown object and a later query for bowls does not relabel it)
        box = service.answer("detect { obj: { type: CerealBox, color: yellow } }").answer
        assert service.engine is engine and engine.tick_count > ticks_after_first
    assert len(loads) == 1
    assert len(milk.objects) == 1 and "milk" in (milk.objects[0].class_label or "")
    assert milk.objects[0].region == "fridge"
    assert [o.class_label for o in cup.objects] == ["cup"] and cup.objects[0].attributes["color"].value == "red"
    assert [o.class_label for o in box.objects] == ["cereal box"]
    assert len({milk.objects[0].id, cup.objects[0].id, box.objects[0].id}) == 3


def test_every_query_kind_has_one_execution_mode() -> None:
    assert set(EXECUTION_MODES) == set(KINDS) - {"stop"}
    assert EXECUTION_MODES["track"] is ExecutionMode.CONTINUOUS
    assert {EXECUTION_MODES[k] for k in ("detect", "inspect", "scan")} == {ExecutionMode.ONCE}


def test_a_track_query_answers_every_run_until_cancelled(service: AnsweringService) -> None:
    with pytest.raises(ValueError, match="runs continuously"):
        service.answer("track the red cup")
    handle = service.start("track the red cup")
    first = handle.next_answer(timeout=60)
    second = handle.next_answer(timeout=60)
    assert first is not None and second is not None, handle.reason
    assert [o.class_label for o in first.objects] == ["cup"]
    assert second.objects[0].id == first.objects[0].id  # the same cup, seen again
    assert not handle.done
    handle.cancel()
    assert handle.done and handle.reason == "cancelled"
    slot = service.engine.tasks.slot(TASK_SLOT)
    assert slot.subtree is not None and slot.subtree.name == "idle"  # the slot idles; the engine keeps ticking
    ticks = service.engine.tick_count
    deadline = time.monotonic() + 10
    while service.engine.tick_count < ticks + 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert service.engine.tick_count >= ticks + 3
    assert all(late.objects for late in handle.answers())  # answers() ends once the task ended
    # the engine answers one-shot queries again after the continuous task
    assert [o.class_label for o in service.answer("find the red cup").answer.objects] == ["cup"]


def test_a_one_shot_query_replaces_a_running_continuous_task(service: AnsweringService) -> None:
    handle = service.start("track the red cup")
    assert handle.next_answer(timeout=60) is not None, handle.reason
    assert service.answer("find milk in fridge").answer.objects
    assert handle.done and "replaced" in handle.reason


def test_kinds_that_do_not_fit_the_call_are_refused(service: AnsweringService) -> None:
    with pytest.raises(ValueError, match="ends with one answer"):
        service.start("find the red cup")
    with pytest.raises(ValueError, match="plans no perception tree"):
        service.mode_of(parse_query("stop { task: 1 }"))


def test_the_trees_of_one_service_share_the_loaded_ocr_model(service: AnsweringService) -> None:
    readers = []
    for _ in range(2):
        tree = service.answer("find milk in fridge").tree
        readers += [node for node in tree.iterate() if node.name == "TextReader"]
    assert len(readers) == 2 and readers[0] is not readers[1]
    assert readers[0].engine() is readers[1].engine()  # the second tree did not load the OCR models again


def test_a_static_camera_watching_the_cup_does_not_make_it_certain(service: AnsweringService) -> None:
    # the kitchen camera does not move and the cup stays put: every run sees the same view of it again, one piece
    # of evidence however often it is repeated (before repeated views were told apart, ten runs made it 0.999)
    handle = service.start("track the red cup")
    answers = [handle.next_answer(timeout=60) for _ in range(10)]
    handle.cancel()
    assert all(a is not None for a in answers), handle.reason
    first, last = answers[0].objects[0], answers[-1].objects[0]  # type: ignore[union-attr]
    assert last.id == first.id
    belief = service.store.get(last.id)
    assert belief is not None and belief.observations >= 10
    color = last.attributes["color"]
    assert color.value == "red" and color.confidence == pytest.approx(first.attributes["color"].confidence)
    assert color.confidence < 0.99 and last.confidence < 0.99
