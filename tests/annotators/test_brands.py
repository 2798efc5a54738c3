"""Brands and printed texts name classes (issue 15, items 4 and 6): text read on an object that matches a class's
brand (``rk:brand``) or printed text, with one OCR error tolerated per 5 letters and case ignored, is strong evidence
for that class, and a brand read also says what kind of product it is (a Cheez-It box is a box of crackers).

The real-data tests ask through the CLI as a user does; the pixels are those of tests/data/labels/real_objects.json
(uoc frames 0 and 2 are in the calibration's fit split, 1 and 3 held out).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from annotators.classification.knowledge_classifier import Cues, Profile, decide, score, text_found
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import class_profiles
from robokudo.application import cli
from robokudo.core.text_match import phrase_found
from robokudo.core.types import Classification

SNACK = ("Snack", "Food", "FoodOrDrink", "PhysicalObject")
CRACKERS = {"class": "Crackers", "colors": ("orange",), "shape": "box", "size": "medium", "texts": ("crackers",),
            "height_to_width": (1.1, 2.0), "ancestors": ("Crackers", *SNACK)}  # fmt: skip
CHEEZ_IT = {**CRACKERS, "class": "CheezIt", "colors": ("red",), "brand": "Cheez-It", "kind_texts": ("crackers",),
            "ancestors": ("CheezIt", "Crackers", *SNACK)}  # fmt: skip
DRY_FOOD = {"class": "DryFood", "shape": "box", "size": "medium", "ancestors": ("DryFood", "Food", "FoodOrDrink")}
SODA = ("SoftDrink", "Drink", "FoodOrDrink", "PhysicalObject")
COLA = {"class": "Cola", "colors": ("red",), "shape": "cylinder", "size": "medium", "texts": ("cola",),
        "brand": "Fizzy", "ancestors": ("Cola", *SODA)}  # fmt: skip
LEMON = {**COLA, "class": "LemonSoda", "colors": ("yellow",), "texts": ("lemon",), "ancestors": ("LemonSoda", *SODA)}

RED_BOX = Cues(color=("red", 0.55), shape=("box", 0.75), size=("medium", 1.0), height_to_width=1.38)


def test_a_printed_phrase_is_found_with_case_spacing_punctuation_and_ocr_errors_tolerated() -> None:
    assert phrase_found("Cheez-It", "CHEEZIT CHEEZ-IT")
    assert phrase_found("Cheez-It", "cheez it")
    assert phrase_found("Cheez-It", "Baked CHEEL-IT snack")  # one OCR error in 7 letters
    assert not phrase_found("Cheez-It", "CHEEL-LT")  # two errors in 7 letters
    assert phrase_found("lactose free", "MILK LACTOSEFREE")
    assert phrase_found("French's", "FRENCH'S classic")
    assert not phrase_found("tea", "steak")  # a short phrase is a word of its own
    assert not phrase_found("---", "anything")


def test_a_brand_read_names_the_product_and_its_kind() -> None:
    profiles = [Profile.from_mapping(p) for p in (CRACKERS, CHEEZ_IT, DRY_FOOD)]
    cheez_it = profiles[1]
    assert text_found(cheez_it, "CHEEZIT CHEEZ-IT") == 2  # the brand, and with it "crackers"
    assert text_found(cheez_it, "crackers") == 1  # the kind alone does not say the brand
    assert text_found(profiles[0], "CHEEZ-IT") == 0  # crackers of no brand: the brand is not their text
    read = Cues(**{**RED_BOX.__dict__, "text": "CHEEZIT CHEEZ-IT"})
    decision = decide([score(p, read) for p in profiles], expected="Crackers")
    assert decision.class_name == "CheezIt" and decision.confidence > 0.5, decision
    # unread, the red box is no Cheez-It box of its own accord: the brand is what tells it
    assert decide([score(p, RED_BOX) for p in profiles]).class_name != "CheezIt"
    # another brand's text read on the same red box speaks against the Cheez-It box
    other = Cues(**{**RED_BOX.__dict__, "text": "RITZ"})
    assert decide([score(p, other) for p in profiles]).class_name != "CheezIt"


def test_the_variants_of_one_brand_are_told_apart_by_their_own_text() -> None:
    profiles = [Profile.from_mapping(p) for p in (COLA, LEMON)]
    can = Cues(shape=("cylinder", 0.8), size=("medium", 1.0))
    cola, lemon = (score(p, Cues(**{**can.__dict__, "text": "FIZZY cola"})).score for p in profiles)
    assert cola > lemon  # "Fizzy cola" is the cola, not the lemon soda of the same brand
    cola, lemon = (score(p, Cues(**{**can.__dict__, "text": "FIZZY"})).score for p in profiles)
    assert cola == pytest.approx(lemon)  # the brand alone cannot tell its variants apart
    assert (
        cola > score(Profile.from_mapping({**COLA, "brand": "Other"}), Cues(**{**can.__dict__, "text": "FIZZY"})).score
    )


def test_the_shipped_ontology_gives_branded_ycb_products_their_brand_and_kind() -> None:
    profiles = {p["class"]: p for p in class_profiles(KnowledgeBase.load())}
    assert profiles["CheezIt"]["brand"] == "Cheez-It" and profiles["CheezIt"]["kind_texts"] == ("crackers",)
    assert "Crackers" in profiles["CheezIt"]["ancestors"]
    assert profiles["FrenchsMustard"]["kind_texts"] == ("mustard",)
    assert profiles["CampbellsTomatoSoup"]["kind_texts"] == ("soup",)
    assert profiles["DominoSugar"]["kind_texts"] == ("sugar",) and profiles["Pringles"]["kind_texts"] == ("chips",)
    assert profiles["Pringles"]["shape"] == "cylinder"  # a tube, not a bag of chips
    assert profiles["Crackers"]["brand"] is None  # crackers in general have no brand


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path / "answers.sqlite"


@pytest.mark.real_data
@pytest.mark.parametrize("frame, box", [(0, (500, 250)), (1, (480, 320))], ids=["frame0-fit", "frame1-held-out"])
def test_find_the_cracker_box_answers_the_cheez_it_box(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, box: tuple[int, int]
) -> None:
    """OCR reads "CHEEZ-IT" on the box; the ontology knows Cheez-It is a brand of crackers, so the answer is the
    box, named as the product, with a confident class."""
    code = cli.main(
        ["query", "find the cracker box", "--input", str(uoc_folder), "--frame", str(frame), "--store", str(store),
         "--json"]
    )  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0, out
    objects = json.loads(out)["objects"]
    x, y = box
    (found,) = [o for o in objects if o["roi"] and o["roi"][0] <= x < o["roi"][2] and o["roi"][1] <= y < o["roi"][3]]
    assert found["class"]["label"] == "Cheez-It crackers", found
    assert found["attributes"][Classification.attribute]["confidence"] > 0.5, found
    assert len(objects) == 1, [o["class"]["label"] for o in objects]  # the drill, the bowls, the cans are not it
