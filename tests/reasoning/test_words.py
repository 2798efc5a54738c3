"""Resolving words to terms: labels, synonyms, names, plurals, case, spaces and underscores."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reasoning.errors import UnknownTermError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import Resolved
from reasoning.knowledge.words import typo_distance


@pytest.mark.parametrize(
    ("word", "kind", "name"),
    [
        ("milk", "class", "Milk"),
        ("Milk", "class", "Milk"),
        ("MILK", "class", "Milk"),
        ("milk carton", "class", "Milk"),
        ("cereal_box", "class", "CerealBox"),
        ("cereal boxes", "class", "CerealBox"),
        ("Cereal Box", "class", "CerealBox"),
        ("CerealBox", "class", "CerealBox"),
        ("cereal", "class", "CerealBox"),
        ("lactose free milk", "class", "LactoseFreeMilk"),
        ("lactose_free_milk", "class", "LactoseFreeMilk"),
        ("lactose-free milk", "class", "LactoseFreeMilk"),
        ("skimmed milk", "class", "SkimMilk"),
        ("cups", "class", "Cup"),
        ("knives", "class", "Knife"),
        ("glasses", "class", "Glass"),
        ("cherry tomatoes", None, None),
        ("tomatoes", "class", "Tomato"),
        ("yoghurt", "class", "Yogurt"),
        ("beverages", "class", "Drink"),
        ("sweets", "class", "Sweets"),
        ("sweet", "class", "Sweets"),  # a label said only in the plural, from a phrase's singular
        ("potato chip", "class", "PotatoChips"),
        ("refrigerator", "region_class", "Fridge"),
        ("Fridge", "region_class", "Fridge"),
        ("fridge", "region", "fridge"),
        ("table", "region", "table"),
        ("cupboards", "region_class", "Cupboard"),
        ("red", "color", "Red"),
        ("gray", "color", "Grey"),
        ("cylinders", "shape", "Cylinder"),
        ("big", "size", "Large"),
    ],
)
def test_resolve(kb: KnowledgeBase, word: str, kind: str | None, name: str | None) -> None:
    if name is None:
        with pytest.raises(UnknownTermError):
            kb.resolve(word)
    else:
        assert kb.resolve(word) == Resolved(kind, name)  # type: ignore[arg-type]


def test_kinds_restrict_the_search(kb: KnowledgeBase) -> None:
    assert kb.resolve("glass") == Resolved("class", "Glass")
    assert kb.resolve("glass", kinds={"material"}) == Resolved("material", "GlassMaterial")
    assert kb.resolve("fridge", kinds={"region_class"}) == Resolved("region_class", "Fridge")
    with pytest.raises(UnknownTermError):
        kb.resolve("milk", kinds={"color"})


def test_resolve_all_lists_every_reading(kb: KnowledgeBase) -> None:
    readings = kb.resolve_all("fridge")
    assert Resolved("region", "fridge") in readings
    assert Resolved("region_class", "Fridge") in readings


def test_unknown_word_suggests_close_matches(kb: KnowledgeBase) -> None:
    with pytest.raises(UnknownTermError) as caught:
        kb.resolve("mlik")
    assert "milk" in caught.value.suggestions
    assert "did you mean" in str(caught.value)


def plural(word: str) -> str:
    """A regular English plural of the last word."""
    if word.endswith(("s", "x", "ch", "sh")):
        return word + "es"
    if word.endswith("y") and word[-2:-1] not in "aeiou":
        return word[:-1] + "ies"
    return word + "s"


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_every_label_and_synonym_resolves_however_it_is_written(kb: KnowledgeBase, data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(kb.names_of_kind("class")))
    word = data.draw(st.sampled_from([kb.label(name), *kb.synonyms(name)]))
    style = data.draw(st.sampled_from(["upper", "title", "underscores", "plural", "plain"]))
    variant = {
        "upper": word.upper(),
        "title": word.title(),
        "underscores": word.replace(" ", "_"),
        "plural": plural(word),
        "plain": word,
    }[style]
    assert kb.resolve(variant, kinds={"class"}).name == name
    assert kb.resolve(name).name == name


@pytest.mark.parametrize(("typed", "meant"), [("mlik", "milk"), ("botle", "bottle"), ("mgu", "mug"), ("cupp", "cup")])
def test_a_typing_slip_is_answered_with_the_word_meant(kb: KnowledgeBase, typed: str, meant: str) -> None:
    with pytest.raises(UnknownTermError) as caught:
        kb.resolve(typed, kinds={"class"})
    assert meant in caught.value.suggestions


@pytest.mark.parametrize("word", ["chair", "magazine", "lamp"])
def test_a_class_not_modelled_gets_advice_not_a_far_fetched_guess(kb: KnowledgeBase, word: str) -> None:
    """The trial on the TUM desk: "find the chair" got "did you mean 'dairy', 'chips'?" (spelling alike, meaning
    not); a word no slip away from any class gets what to ask instead."""
    with pytest.raises(UnknownTermError) as caught:
        kb.resolve(word, kinds={"class"})
    assert caught.value.suggestions == ()
    assert "'find all objects'" in str(caught.value)


slips = st.text(alphabet="abcdefgh", min_size=1, max_size=8)


@given(slips, slips)
def test_typo_distance_is_symmetric_and_zero_only_for_the_same_word(a: str, b: str) -> None:
    assert typo_distance(a, b) == typo_distance(b, a)
    assert (typo_distance(a, b) == 0) == (a == b)


@given(slips, st.integers(min_value=0, max_value=7), st.sampled_from(["wrong", "missing", "extra", "swapped"]))
def test_one_slip_is_one(word: str, at: int, slip: str) -> None:
    at %= len(word)
    if slip == "wrong":
        typed = word[:at] + ("z" if word[at] != "z" else "y") + word[at + 1 :]
    elif slip == "missing":
        typed = word[:at] + word[at + 1 :]
    elif slip == "extra":
        typed = word[:at] + "z" + word[at:]
    else:
        if at + 1 >= len(word) or word[at] == word[at + 1]:
            return
        typed = word[:at] + word[at + 1] + word[at] + word[at + 2 :]
    assert typo_distance(typed, word) == 1
