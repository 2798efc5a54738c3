"""Edits are transactions: concurrent editors lose nothing, hand edits survive, a killed editor leaves old or new.

The concurrent editors are forked processes sharing one loaded knowledge base (as many `robokudo ontology` commands
would, without paying the start-up eight times); each holds its own editor and takes the file lock like the CLI.
"""

from __future__ import annotations

import multiprocessing
import os
import random
import signal
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from rdflib import Graph

from reasoning.errors import EditRejectedError
from reasoning.knowledge.editing import NEW_USER_FILE, OntologyEditor
from reasoning.knowledge.folded_triples import fold
from reasoning.knowledge.history import EditHistory, history_path
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.user_layer import UserLayerFile
from reasoning.knowledge.vocabulary import OWL, RDF, rk
from robokudo.application.knowledge import load_knowledge_base

FORK = multiprocessing.get_context("fork")

Outcome = tuple[str, str, bool, str]
"""(process, what, succeeded, message)."""


def run_in_processes(kb: KnowledgeBase, jobs: list[Callable[[OntologyEditor], list[Outcome]]]) -> list[Outcome]:
    """Run each job in its own forked process at the same moment; every process reports its outcomes."""
    queue = FORK.Queue()
    start = FORK.Event()

    def worker(job: Callable[[OntologyEditor], list[Outcome]]) -> None:
        start.wait()
        queue.put(job(OntologyEditor(kb, lock_timeout=120)))

    processes = [FORK.Process(target=worker, args=(job,)) for job in jobs]
    for process in processes:
        process.start()
    start.set()
    outcomes = [o for _ in processes for o in queue.get(timeout=300)]
    for process in processes:
        process.join(timeout=60)
        assert process.exitcode == 0
    return outcomes


def attempt(who: str, what: str, edit: Callable[[], object]) -> Outcome:
    try:
        edit()
    except EditRejectedError as error:
        return (who, what, False, str(error))
    return (who, what, True, "")


def declared(user_file: Path) -> set[str]:
    graph = Graph().parse(user_file, format="turtle")
    return {str(s).rsplit("#", 1)[-1] for s in graph.subjects(RDF.type, OWL.Class)}


def assert_hermit_consistent(user_file: Path) -> None:
    report = OntologyEditor(load_knowledge_base(user_file)).check(code=False)
    assert report.ok, report.problems
    assert report.reasoner.startswith("HermiT: consistent")


@pytest.mark.slow
def test_eight_processes_adding_at_once_lose_nothing(user_file: Path) -> None:
    kb = load_knowledge_base(user_file)

    def adder(i: int) -> Callable[[OntologyEditor], list[Outcome]]:
        def job(editor: OntologyEditor) -> list[Outcome]:
            edit = lambda: editor.add_object(f"Thing{i}", ["Milk"], colors=["white"])  # noqa: E731
            return [attempt(f"p{i}", f"Thing{i}", edit)]

        return job

    outcomes = run_in_processes(kb, [adder(i) for i in range(8)])
    assert all(ok for _, _, ok, _ in outcomes), outcomes
    assert declared(user_file) == {f"Thing{i}" for i in range(8)}
    entries = EditHistory(history_path(user_file)).entries()
    assert sorted(e.number for e in entries) == list(range(1, 9))
    assert sorted(e.name for e in entries) == [f"Thing{i}" for i in range(8)]
    assert_hermit_consistent(user_file)


@pytest.mark.slow
def test_eight_processes_removing_and_adding_in_a_loop(user_file: Path) -> None:
    kb = load_knowledge_base(user_file)

    def looper(i: int) -> Callable[[OntologyEditor], list[Outcome]]:
        def job(editor: OntologyEditor) -> list[Outcome]:
            done = []
            done.append(attempt(f"p{i}", f"+Loop{i}", lambda: editor.add_object(f"Loop{i}", ["Cup"])))
            done.append(attempt(f"p{i}", f"-Loop{i}", lambda: editor.remove_object(f"Loop{i}")))
            contest = lambda: editor.add_object("Contested", ["Cup"], synonyms=[f"contest {i}"])  # noqa: E731
            done.append(attempt(f"p{i}", "+Contested", contest))  # all eight want this name; one may have it
            done.append(attempt(f"p{i}", f"+Loop{i}", lambda: editor.add_object(f"Loop{i}", ["Cup"])))
            return done

        return job

    outcomes = run_in_processes(kb, [looper(i) for i in range(8)])
    own = [o for o in outcomes if o[1] != "+Contested"]
    assert all(ok for _, _, ok, _ in own), [o for o in own if not o[2]]
    contested = [o for o in outcomes if o[1] == "+Contested"]
    winners = [who for who, _, ok, _ in contested if ok]
    assert len(winners) == 1
    assert all("Contested clashes with the existing term Contested" in m for _, _, ok, m in contested if not ok)
    assert declared(user_file) == {f"Loop{i}" for i in range(8)} | {"Contested"}
    final = load_knowledge_base(user_file)
    assert final.synonyms("Contested") == (f"contest {winners[0][1:]}",)  # the winner's edit, no loser's
    successes = sum(ok for _, _, ok, _ in outcomes)
    assert len(EditHistory(history_path(user_file)).entries()) == successes
    assert_hermit_consistent(user_file)


def test_a_hand_added_class_and_comment_survive_add_and_remove(user_file: Path) -> None:
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("OatMilk", ["Milk"], colors=["white"])
    hand = (
        "\n# my own note: the jug on the balcony\n"
        'rk:BalconyJug a owl:Class ; rdfs:subClassOf rk:Bottle ; rdfs:label "balcony jug"@en .  # keep me\n'
    )
    user_file.write_text(user_file.read_text(encoding="utf-8") + hand, encoding="utf-8")
    editor.add_object("RiceMilk", ["Milk"])
    assert hand in user_file.read_text(encoding="utf-8")
    assert editor.kb.is_subclass("BalconyJug", "Bottle")  # the hand edit was read, not overwritten
    editor.remove_object("OatMilk")
    editor.remove_object("RiceMilk")
    assert user_file.read_text(encoding="utf-8") == NEW_USER_FILE + hand  # the CLI's blocks went, nothing else
    editor.remove_object("BalconyJug")  # a hand-written class can be removed too; its comment stays
    assert "# my own note: the jug on the balcony" in user_file.read_text(encoding="utf-8")
    assert "BalconyJug" not in user_file.read_text(encoding="utf-8")


def test_a_hand_edit_made_during_validation_is_not_overwritten(
    user_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A text editor that does not take the lock saves while an edit is being validated: the edit is redone on the
    new content instead of replacing it."""
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("OatMilk", ["Milk"])
    validate = editor._validate
    saved = []

    def validate_while_someone_saves(*args: object, **kwargs: object) -> object:
        if not saved:
            text = user_file.read_text(encoding="utf-8")
            user_file.write_text(text + "rk:SavedMeanwhile a owl:Class ; rdfs:subClassOf rk:Cup .\n", "utf-8")
            saved.append(True)
        return validate(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(editor, "_validate", validate_while_someone_saves)
    editor.add_object("RiceMilk", ["Milk"])
    assert {"OatMilk", "SavedMeanwhile", "RiceMilk"} <= declared(user_file)


def test_an_edit_waits_for_the_lock_and_gives_up_with_a_clear_error(user_file: Path) -> None:
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False, lock_timeout=0.2)
    holder = FORK.Event()
    release = FORK.Event()

    def hold() -> None:
        with UserLayerFile(user_file).locked():
            holder.set()
            release.wait(10)

    process = FORK.Process(target=hold)
    process.start()
    try:
        assert holder.wait(10)
        with pytest.raises(EditRejectedError, match=r"another edit has held .*user\.ttl\.lock for 0\.2 s"):
            editor.add_object("OatMilk", ["Milk"])
    finally:
        release.set()
        process.join(10)
    assert not user_file.exists()
    editor.add_object("OatMilk", ["Milk"])
    assert "OatMilk" in declared(user_file)


def _edit_once(editor: OntologyEditor, name: str) -> None:
    editor.add_object(name, ["Milk"], colors=["white"], synonyms=[f"{name} drink"])
    os._exit(0)


def edit_in_a_process(editor: OntologyEditor, name: str) -> multiprocessing.process.BaseProcess:
    process = FORK.Process(target=_edit_once, args=(editor, name))
    process.start()
    return process


def test_kill_9_at_random_points_leaves_the_old_or_the_new_file(user_file: Path) -> None:
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("First", ["Milk"])
    started = time.perf_counter()
    edit_in_a_process(editor, "Second").join(30)
    duration = time.perf_counter() - started  # what an editing process takes, start-up included
    assert "Second" in declared(user_file)
    rng = random.Random(20)
    outcomes = {"old": 0, "new": 0}
    for i in range(20):
        editor.kb.reload_if_changed()  # the forked editor starts from the file as it is, like the measured one
        old = user_file.read_bytes()
        old_triples = fold(Graph().parse(data=old, format="turtle"))
        process = edit_in_a_process(editor, f"Killed{i}")
        time.sleep(rng.uniform(0.0, duration * 1.2))
        os.kill(process.pid, signal.SIGKILL)  # type: ignore[arg-type]
        process.join(10)
        now = user_file.read_bytes()
        if now == old:
            outcomes["old"] += 1
            continue
        assert now.startswith(old)  # an edit appends its block: the new version is the old one plus it
        triples = fold(Graph().parse(data=now, format="turtle"))
        assert old_triples < triples
        assert {t[0] for t in triples - old_triples} == {rk(f"Killed{i}")}
        outcomes["new"] += 1
    editor.add_object("AfterTheKills", ["Milk"])  # the lock was released by every killed process
    assert "AfterTheKills" in declared(user_file)
    leftovers = [p.name for p in user_file.parent.iterdir() if p.name.endswith(".tmp")]
    assert leftovers == []
    print(f"killed editors left the old file {outcomes['old']} times and the new one {outcomes['new']} times")


def test_a_user_file_written_by_the_earlier_editor_is_edited_in_place(user_file: Path) -> None:
    """Before edits kept text, the editor rewrote the whole file with rdflib under a header saying comments are
    lost; such a file is edited like any other and its header says what is true now."""
    user_file.parent.mkdir(parents=True)
    old_body = (
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "@prefix rk: <http://robokudo.org/ontology#> .\n\n"
        '<http://robokudo.org/ontology/user> a owl:Ontology ;\n    rdfs:label "RoboKudo user ontology"@en .\n\n'
        'rk:OatMilk a owl:Class ;\n    rdfs:label "oat milk"@en ;\n'
        '    rdfs:subClassOf [ a owl:Restriction ;\n            owl:hasValue "oat" ;\n'
        "            owl:onProperty rk:printedText ],\n        rk:Milk .\n"
    )
    old_header = (
        "# RoboKudo user ontology: object classes and regions added by the user, layered over the shipped\n"
        "# ontology. Written by `robokudo ontology` (comments in this file are not kept).\n\n"
    )
    user_file.write_text(old_header + old_body, encoding="utf-8")
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("RiceMilk", ["Milk"])
    editor.remove_object("OatMilk")
    text = user_file.read_text(encoding="utf-8")
    assert "comments in this file are not kept" not in text
    assert text.startswith(NEW_USER_FILE.split("@prefix")[0])
    assert declared(user_file) == {"RiceMilk"}
    assert editor.kb.resolve("rice milk").name == "RiceMilk"
