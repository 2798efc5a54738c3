"""Subsumption, inherited object profiles, default locations and text-distinguished variants."""

from __future__ import annotations

import pytest

from reasoning.knowledge.knowledge_base import KnowledgeBase


def test_subsumption(kb: KnowledgeBase) -> None:
    assert kb.is_subclass("WholeMilk", "Milk")
    assert kb.is_subclass("Milk", "Drink")
    assert kb.is_subclass("WholeMilk", "PhysicalObject")
    assert kb.is_subclass("Milk", "Milk")
    assert not kb.is_subclass("Milk", "Food")
    assert not kb.is_subclass("Drink", "Milk")
    assert kb.is_subclass("whole milk", "drinks")
    assert kb.is_subclass("FridgeInterior", "Fridge")
    assert kb.is_subclass("SemanticColor", "Annotation")


def test_subclasses_and_superclasses(kb: KnowledgeBase) -> None:
    assert set(kb.subclasses("Milk", direct=True)) == {"WholeMilk", "LactoseFreeMilk", "SkimMilk", "ChocolateMilk"}
    assert {"Cup", "Mug", "Bowl", "Bottle", "PaperCup", "WhiteCeramicBowl"} <= set(kb.subclasses("Container"))
    assert kb.superclasses("WholeMilk", direct=True) == ["Milk"]
    assert kb.superclasses("WholeMilk") == ["Drink", "FoodOrDrink", "Milk", "PhysicalObject"]


def test_disjointness(kb: KnowledgeBase) -> None:
    assert kb.are_disjoint("Drink", "Food")
    assert kb.are_disjoint("Milk", "CerealBox")
    assert kb.are_disjoint("Fork", "Cup")
    assert not kb.are_disjoint("Milk", "WholeMilk")


def test_default_location_of_milk_is_the_fridge(kb: KnowledgeBase) -> None:
    assert kb.default_location("Milk") == "Fridge"
    assert kb.default_location("milk") == "Fridge"
    assert kb.default_location("LactoseFreeMilk") == "Fridge"
    assert kb.default_location("CerealBox") == "Cupboard"
    assert kb.default_location("Fork") == "Drawer"
    assert kb.default_location("PhysicalObject") is None


def test_profile_inherits_and_overrides(kb: KnowledgeBase) -> None:
    whole = kb.object_profile("WholeMilk")
    assert whole.colors == ("White",)
    assert whole.shape == "Box"
    assert whole.size_class == "Medium"
    assert whole.material == "Cardboard"
    assert whole.transparent is False
    assert whole.stored_in == "Fridge"
    assert whole.origin("stored_in") == "Milk"
    assert whole.texts == ("whole", "milk")
    chocolate = kb.object_profile("ChocolateMilk")
    assert chocolate.colors == ("Brown",)
    assert chocolate.origin("colors") == "ChocolateMilk"
    assert kb.object_profile("Glass").transparent is True
    assert kb.object_profile("WineGlass").transparent is True
    assert kb.object_profile("Cola").brand == "Fizzy"


def test_profile_of_unknown_class(kb: KnowledgeBase) -> None:
    with pytest.raises(KeyError, match="Unicorn"):
        kb.object_profile("Unicorn")


def test_variants_that_only_text_tells_apart(kb: KnowledgeBase) -> None:
    assert kb.variants_differ_by_text("LactoseFreeMilk")
    assert kb.variants_differ_by_text("WholeMilk")
    assert kb.variants_differ_by_text("CannedSoup")
    assert not kb.variants_differ_by_text("ChocolateMilk")  # brown: its colour tells it apart
    assert not kb.variants_differ_by_text("Milk")
    assert not kb.variants_differ_by_text("OrangeJuice")
