"""Editing the user ontology: validated, atomic, byte-identical on rejection, usable at once."""

from __future__ import annotations

from pathlib import Path

import pytest

from reasoning.errors import EditRejectedError
from reasoning.knowledge import hermit
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.sources import USER_ONTOLOGY_ENV, default_user_file


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture()
def editor(user_file: Path) -> OntologyEditor:
    """An editor without HermiT (fast); tests that need the reasoner make their own."""
    return OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)


@pytest.mark.slow
def test_add_oat_milk_checked_by_hermit(user_file: Path) -> None:
    kb = KnowledgeBase.load(user_file)
    result = OntologyEditor(kb).add_object("OatMilk", ["Milk"], colors=["white"], texts=["oat"])
    assert result.checked_by.startswith("HermiT: consistent")
    assert user_file.exists()
    # the same knowledge base sees it at once
    assert kb.resolve("oat milk").name == "OatMilk"
    assert kb.resolve("OAT_MILKS").name == "OatMilk"
    assert kb.is_subclass("OatMilk", "Milk")
    assert "OatMilk" in kb.subclasses("Drink")
    profile = kb.object_profile("OatMilk")
    assert profile.stored_in == "Fridge"
    assert profile.origin("stored_in") == "Milk"
    assert kb.default_location("OatMilk") == "Fridge"
    assert profile.colors == ("White",)
    assert "oat" in profile.texts
    assert kb.variants_differ_by_text("OatMilk")
    assert [r.name for r in kb.regions_of_class(kb.default_location("oat milk") or "")] == ["fridge"]
    # and so does a knowledge base loaded later
    assert KnowledgeBase.load(user_file).object_profile("oat milk").name == "OatMilk"


def test_add_with_all_properties(editor: OntologyEditor) -> None:
    editor.add_object(
        "SpiceJar",
        ["jar"],
        colors=["red", "Black"],
        shape="cylinder",
        size="small",
        material="glass",
        transparent=True,
        stored_in="shelf",
        texts=["Paprika"],
        brand="Spicy",
        label="spice jar",
        synonyms=["spice pot"],
    )
    kb = editor.kb
    profile = kb.object_profile("spice pots")
    assert profile.name == "SpiceJar"
    assert profile.colors == ("Black", "Red")
    assert (profile.shape, profile.size_class, profile.material) == ("Cylinder", "Small", "GlassMaterial")
    assert profile.transparent is True
    assert profile.stored_in == "Shelf"
    assert profile.texts == ("paprika",)
    assert profile.brand == "Spicy"
    assert "ClusterExtractor" not in [s.name for s in kb.providers("ObjectHypothesis", object_class="SpiceJar")]


def test_a_second_process_sees_the_edit_after_reload_if_changed(user_file: Path, editor: OntologyEditor) -> None:
    other = KnowledgeBase.load(user_file)
    assert not other.reload_if_changed()
    editor.add_object("OatMilk", ["Milk"], texts=["oat"])
    assert other.reload_if_changed()
    assert other.resolve("oat milk").name == "OatMilk"


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"name": "OatMilk", "is_a": ["Mlik"]}, "unknown object class 'Mlik'; did you mean 'milk'"),
        ({"name": "OatMilk", "is_a": ["Milk"], "stored_in": "Frdge"}, "unknown region class 'Frdge'"),
        ({"name": "OatMilk", "is_a": ["Milk"], "stored_in": "Milk"}, "unknown region class 'Milk'"),
        ({"name": "OatMilk", "is_a": ["Milk"], "colors": ["whit"]}, "unknown colour 'whit'"),
        ({"name": "OatMilk", "is_a": ["Milk"], "shape": "cube"}, "unknown shape 'cube'"),
        ({"name": "OatMilk", "is_a": ["Milk"], "size": "huge"}, "unknown size class 'huge'"),
        ({"name": "OatMilk", "is_a": ["Red"]}, "unknown object class 'Red'"),
        ({"name": "OatMilk", "is_a": []}, "at least one parent"),
        ({"name": "Milk", "is_a": ["Drink"]}, "Milk clashes with the existing term Milk (defined in objects.ttl)"),
        ({"name": "Fridge", "is_a": ["Drink"]}, "clashes with the existing term Fridge"),
        ({"name": "Wholemilk", "is_a": ["Drink"]}, "clashes with the existing term WholeMilk"),
        ({"name": "Oats", "is_a": ["Food"], "label": "cereal"}, "'cereal' already names the object class CerealBox"),
        ({"name": "Oats", "is_a": ["Food"], "label": "Tables"}, "'Tables' already names the region table"),
        ({"name": "Oats", "is_a": ["Food"], "synonyms": ["orange"]}, "'orange' already names the colour Orange"),
        ({"name": "Beverage", "is_a": ["Food"], "label": "oaty"}, "'Beverage' already names the object class Drink"),
        ({"name": "Oats", "is_a": ["Food"], "synonyms": ["milk"]}, "'milk' already names the object class Milk"),
        (
            {"name": "oat_milk", "is_a": ["Milk"]},
            "not a valid class name: use CamelCase letters and digits, e.g. 'OatMilk'",
        ),
        ({"name": "OatMilk", "is_a": ["Milk"], "texts": ["  "]}, "printed text must not be empty"),
    ],
)
def test_bad_edit_is_rejected_and_leaves_files_byte_identical(
    editor: OntologyEditor, user_file: Path, arguments: dict, message: str
) -> None:
    editor.add_object("Oatly", ["Milk"], texts=["oat"])  # the user file exists and has content
    folder = user_file.parent
    before = snapshot(folder)
    shipped_before = {p: p.read_bytes() for p in editor.kb.sources.files}
    with pytest.raises(EditRejectedError) as caught:
        editor.add_object(arguments.pop("name"), arguments.pop("is_a"), **arguments)
    assert message in str(caught.value)
    assert snapshot(folder) == before
    assert {p: p.read_bytes() for p in editor.kb.sources.files} == shipped_before


def test_rejected_first_edit_creates_no_file(editor: OntologyEditor, user_file: Path) -> None:
    with pytest.raises(EditRejectedError):
        editor.add_object("OatMilk", ["Mlik"])
    assert sorted(p.name for p in user_file.parent.iterdir()) == ["user.ttl.lock"]  # no user file, no history


@pytest.mark.slow
def test_class_under_two_disjoint_parents_is_rejected_by_hermit(user_file: Path) -> None:
    kb = KnowledgeBase.load(user_file)
    OntologyEditor(kb, use_reasoner=False).add_object("OatMilk", ["Milk"], texts=["oat"])
    editor = OntologyEditor(kb)
    before = user_file.read_bytes()
    with pytest.raises(EditRejectedError) as caught:
        editor.add_object("MilkMug", ["Milk", "Mug"])
    message = str(caught.value)
    assert "MilkMug can have no instances according to HermiT" in message
    assert "FoodOrDrink and Tableware, which are disjoint" in message
    assert user_file.read_bytes() == before
    with pytest.raises(EditRejectedError, match="HermiT"):
        editor.add_object("FoodDrink", ["Milk", "CerealBox"])
    assert user_file.read_bytes() == before
    assert editor.kb.resolve_all("milk mug") == ()


def test_without_java_the_asserted_check_rejects_disjoint_parents(
    user_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(hermit, "find_java", lambda: None)
    editor = OntologyEditor(KnowledgeBase.load(user_file))
    with pytest.raises(
        EditRejectedError, match="ForkMug can have no instances: it is under Container and Cutlery, which are disjoint"
    ):
        editor.add_object("ForkMug", ["Fork", "Mug"])
    assert not user_file.exists()
    result = editor.add_object("OatMilk", ["Milk"])
    assert result.checked_by == "asserted checks"
    assert any("Java was not found" in w for w in result.warnings)


def test_remove_object(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"], texts=["oat"])
    editor.add_object("BaristaOatMilk", ["OatMilk"], texts=["barista"])
    before = user_file.read_bytes()
    with pytest.raises(EditRejectedError, match="OatMilk is still used by: BaristaOatMilk"):
        editor.remove_object("OatMilk")
    with pytest.raises(EditRejectedError, match=r"defined in .*objects\.ttl.*only classes added by the user"):
        editor.remove_object("Milk")
    with pytest.raises(EditRejectedError, match="not a class of the user file"):
        editor.remove_object("NoSuchThing")
    assert user_file.read_bytes() == before
    editor.remove_object("BaristaOatMilk")
    editor.remove_object("OatMilk")
    assert editor.kb.resolve_all("oat milk") == ()
    assert "OatMilk" not in user_file.read_text(encoding="utf-8")
    assert "Restriction" not in user_file.read_text(encoding="utf-8")


def test_writes_are_atomic_and_leave_no_temporary_files(editor: OntologyEditor, user_file: Path) -> None:
    editor.add_object("OatMilk", ["Milk"])
    editor.add_object("RiceMilk", ["Milk"])
    assert sorted(p.name for p in user_file.parent.iterdir()) == ["user.ttl", "user.ttl.history.jsonl", "user.ttl.lock"]


def test_user_file_location(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(USER_ONTOLOGY_ENV, str(tmp_path / "custom.ttl"))
    assert default_user_file() == tmp_path / "custom.ttl"
    assert KnowledgeBase.load().user_file == tmp_path / "custom.ttl"
    monkeypatch.delenv(USER_ONTOLOGY_ENV)
    assert default_user_file().name == "user.ttl"
    assert "robokudo" in str(default_user_file())


def test_user_edits_survive_a_shipped_file_change(tmp_path: Path, user_file: Path) -> None:
    """The user layer is separate from the shipped files, so replacing those keeps user classes."""
    editor = OntologyEditor(KnowledgeBase.load(user_file), use_reasoner=False)
    editor.add_object("OatMilk", ["Milk"])
    reloaded = KnowledgeBase.load(user_file)
    assert reloaded.defined_in("OatMilk") == user_file
    assert reloaded.defined_in("Milk") is not None and reloaded.defined_in("Milk") != user_file
