"""Every edit is recorded; undo reverts the last N edits and gives back what the file meant before them."""

from __future__ import annotations

from pathlib import Path

import pytest
from rdflib import Graph
from rdflib.compare import isomorphic

from reasoning.errors import EditRejectedError
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase


@pytest.fixture()
def editor(user_file: Path) -> OntologyEditor:
    """An editor without HermiT (fast); the reasoner tests make their own."""
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("Oatly", ["Milk"], texts=["oat"])  # the file exists and has content
    return editor


def meaning(user_file: Path) -> Graph:
    return Graph().parse(user_file, format="turtle")


def test_undo_after_add_restores_the_previous_meaning(editor: OntologyEditor, user_file: Path) -> None:
    before = meaning(user_file)
    editor.add_object("OatMilk", ["Milk"], colors=["white"], stored_in="fridge", synonyms=["oat drink"])
    result = editor.undo()
    assert [e.summary for e in result.undone] == ["add-object OatMilk"]
    assert isomorphic(meaning(user_file), before)
    assert editor.kb.resolve_all("oat milk") == ()


def test_undo_after_remove_restores_the_previous_meaning(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"], colors=["white"], transparent=False, brand="Oaty", synonyms=["oat drink"])
    before = meaning(user_file)
    editor.remove_object("OatMilk")
    editor.undo()
    assert isomorphic(meaning(user_file), before)
    profile = editor.kb.object_profile("oat drink")
    assert (profile.name, profile.colors, profile.brand) == ("OatMilk", ("White",), "Oaty")


def test_undo_after_a_synonym_change_restores_the_previous_meaning(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"], synonyms=["oat drink", "oaty"])
    editor.change_synonyms("Milk", add=["moo juice"])  # a synonym for a shipped class lives in the user layer
    assert editor.kb.resolve("moo juice").name == "Milk"
    before = meaning(user_file)
    editor.change_synonyms("OatMilk", add=["oat beverage"], remove=["oaty"])
    assert editor.kb.synonyms("OatMilk") == ("oat beverage", "oat drink")
    editor.undo()
    assert isomorphic(meaning(user_file), before)
    assert editor.kb.synonyms("OatMilk") == ("oat drink", "oaty")


def test_undo_n_reverts_the_last_n_edits_once_each(editor: OntologyEditor, user_file: Path) -> None:
    start = meaning(user_file)
    editor.add_object("OatMilk", ["Milk"])
    middle = meaning(user_file)
    editor.add_object("RiceMilk", ["Milk"])
    editor.remove_object("OatMilk")
    result = editor.undo(2)  # the removal and RiceMilk
    assert [e.summary for e in result.undone] == ["remove-object OatMilk", "add-object RiceMilk"]
    assert isomorphic(meaning(user_file), middle)
    editor.undo()  # an undo is not undone: the next older edit is
    assert isomorphic(meaning(user_file), start)
    log = editor.log()
    assert [e.summary for e in log] == [
        "add-object Oatly",
        "add-object OatMilk",
        "add-object RiceMilk",
        "remove-object OatMilk",
        "undo of 4, 3",
        "undo of 2",
    ]
    assert [e.number for e in log] == [1, 2, 3, 4, 5, 6]
    assert all(e.time.endswith("Z") and e.user for e in log)
    assert log[1].added and not log[1].removed and log[3].removed and not log[3].added
    with pytest.raises(EditRejectedError, match=r"only 1 edit\(s\) can be undone"):
        editor.undo(2)


def test_undo_keeps_hand_edits_made_since(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"])
    hand = "\n# mine\nrk:Flask a owl:Class ; rdfs:subClassOf rk:Bottle .\n"
    user_file.write_text(user_file.read_text(encoding="utf-8") + hand, encoding="utf-8")
    editor.undo()
    text = user_file.read_text(encoding="utf-8")
    assert hand in text and "OatMilk" not in text


def test_undo_that_would_break_a_class_is_rejected(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"])
    hand = "rk:BaristaOat a owl:Class ; rdfs:subClassOf rk:OatMilk .\n"
    user_file.write_text(user_file.read_text(encoding="utf-8") + hand, encoding="utf-8")
    before = user_file.read_bytes()
    with pytest.raises(EditRejectedError, match=r"OatMilk is still used by: BaristaOat \(rdfs:subClassOf\)"):
        editor.undo()
    assert user_file.read_bytes() == before


def test_shipped_synonyms_cannot_be_removed_and_clashes_are_refused(editor: OntologyEditor, user_file: Path) -> None:
    before = user_file.read_bytes()
    with pytest.raises(EditRejectedError, match=r"'milk carton' of Milk comes from .*objects\.ttl"):
        editor.change_synonyms("Milk", remove=["milk carton"])
    with pytest.raises(EditRejectedError, match="'cereal' already names the object class CerealBox"):
        editor.change_synonyms("Milk", add=["cereal"])
    with pytest.raises(EditRejectedError, match="Milk has no synonym 'moo'"):
        editor.change_synonyms("Milk", remove=["moo"])
    assert user_file.read_bytes() == before


@pytest.mark.slow
def test_reasoner_edits_after_the_first_are_checked_incrementally_and_undo_reuses_it(user_file: Path) -> None:
    editor = OntologyEditor(KnowledgeBase.load(user_file))
    assert editor.add_object("OatMilk", ["Milk"]).checked_by.startswith("HermiT: consistent")
    second = editor.add_object("RiceMilk", ["Milk"], stored_in="fridge")
    assert second.checked_by.startswith("incremental check of RiceMilk against the stored HermiT classification")
    with pytest.raises(EditRejectedError, match="MilkMug can have no instances: it is under FoodOrDrink and Tableware"):
        editor.add_object("MilkMug", ["Milk", "Mug"])
    editor.remove_object("RiceMilk")
    redone = editor.undo()  # RiceMilk comes back: an addition, checked incrementally
    assert redone.checked_by.startswith("incremental check of RiceMilk")
