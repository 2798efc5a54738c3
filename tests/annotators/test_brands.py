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

from annotators.classification.knowledge_classifier import Cues, Profile, decide, ruled_out, score, text_found
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


def test_the_shipped_ontology_knows_the_colours_of_the_ycb_cans_and_the_toffifee_box() -> None:
    profiles = {p["class"]: p for p in class_profiles(KnowledgeBase.load())}
    assert set(profiles["CampbellsTomatoSoup"]["colors"]) == {"red", "white"}  # red above, white below
    assert profiles["CannedSoup"]["colors"] in (None, ())  # a can of no known brand may be any colour
    coffee = profiles["MasterChefCoffee"]
    assert coffee["colors"] == ("blue",) and coffee["shape"] == "cylinder" and coffee["brand"] == "Master Chef"
    assert coffee["kind_texts"] == ("coffee",) and "CoffeePack" in coffee["ancestors"]
    toffifee = profiles["Toffifee"]
    assert set(toffifee["colors"]) == {"brown", "orange"} and toffifee["brand"] == "Toffifee"
    assert "Snack" in toffifee["ancestors"] and "Drink" not in toffifee["ancestors"]


# the blue mug of uoc frame 3 (held out) as the experts saw it: a handle and an open top surely seen
BLUE_MUG = Cues(color=("blue", 0.84), shape=("cylinder", 0.40), size=("medium", 1.0), handle=(True, 1.0),
                open_top=(True, 1.0), height_to_width=0.94, extent=0.126, elongation=1.13)  # fmt: skip


def test_knowing_a_blue_coffee_can_leaves_a_blue_mug_seen_open_as_sure_a_mug() -> None:
    """The Master Chef can is blue, as the mug, but its closed top is ruled out by the open top seen for sure, so it
    is no rival in the mug's lead: knowing it changes nothing for the mug (a rival's colour was why the cans'
    colours were once left out)."""
    shipped = [Profile.from_mapping(p) for p in class_profiles(KnowledgeBase.load())]
    without = [p for p in shipped if p.class_name != "MasterChefCoffee"]
    found = [score(p, BLUE_MUG) for p in shipped]
    can = next(m for m in found if m.profile.class_name == "MasterChefCoffee")
    mug = next(m for m in found if m.profile.class_name == "Mug")
    assert ruled_out(can.profile, BLUE_MUG) and not ruled_out(mug.profile, BLUE_MUG)
    known, unknown = (decide([score(p, BLUE_MUG) for p in ps], cues=BLUE_MUG) for ps in (shipped, without))
    assert known.class_name == unknown.class_name == "Mug" and mug.score == known.best.score
    assert known.confidence == pytest.approx(unknown.confidence) and known.confidence > 0.5


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path / "answers.sqlite"


def answered(capsys: pytest.CaptureFixture, store: Path, scene: Path, query: str, *options: str) -> list[dict]:
    """The objects ``robokudo query QUERY --input SCENE --json OPTIONS`` answers (it must succeed)."""
    code = cli.main(["query", query, "--input", str(scene), "--store", str(store), "--json", *options])
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)["objects"]


def holding(objects: list[dict], pixel: tuple[int, int]) -> list[dict]:
    """The answered objects whose box holds ``pixel``."""
    x, y = pixel
    return [o for o in objects if o["roi"] and o["roi"][0] <= x < o["roi"][2] and o["roi"][1] <= y < o["roi"][3]]


def answer_at(
    capsys: pytest.CaptureFixture, store: Path, scene: Path, query: str, pixel: tuple[int, int], *options: str
) -> dict:
    """The smallest answered object whose box holds ``pixel``."""
    found = holding(answered(capsys, store, scene, query, *options), pixel)
    assert found, f"no answered object holds {pixel}"
    return min(found, key=lambda o: (o["roi"][2] - o["roi"][0]) * (o["roi"][3] - o["roi"][1]))


@pytest.mark.real_data
@pytest.mark.parametrize("frame, box", [(0, (500, 250)), (1, (480, 320))], ids=["frame0-fit", "frame1-held-out"])
def test_find_the_cracker_box_answers_the_cheez_it_box(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, box: tuple[int, int]
) -> None:
    """OCR reads "CHEEZ-IT" on the box; the ontology knows Cheez-It is a brand of crackers, so the answer is the
    box, named as the product, with a confident class."""
    objects = answered(capsys, store, uoc_folder, "find the cracker box", "--frame", str(frame))
    (found,) = holding(objects, box)
    assert found["class"]["label"] == "Cheez-It crackers", found
    assert found["attributes"][Classification.attribute]["confidence"] > 0.5, found
    assert len(objects) == 1, [o["class"]["label"] for o in objects]  # the drill, the bowls, the cans are not it


@pytest.mark.real_data
@pytest.mark.parametrize("frame, box", [(0, (500, 250)), (1, (480, 320))], ids=["frame0-fit", "frame1-held-out"])
def test_find_all_objects_reads_text_and_names_the_cheez_it_box_by_its_brand(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, box: tuple[int, int]
) -> None:
    """A query naming no class reads the text (the ontology knows products only their brand tells apart), so the
    box that reads "CHEEZ-IT" is named as the product; asked not to read text, it is only "food or drink" (or
    another class above the cracker box): its look alone does not tell."""
    answers = {}
    for query in ("find all objects", "detect { obj: { type: object, text: false } }"):
        own_store = store.with_name(f"answers{len(answers)}.sqlite")  # the text read once is not fused into the other
        answers[query] = answer_at(capsys, own_store, uoc_folder, query, box, "--frame", str(frame))
    read, unread = answers.values()
    assert read["class"]["label"] == "Cheez-It crackers", read
    assert "CHEEZ" in read["attributes"]["text"]["value"], read
    assert read["attributes"][Classification.attribute]["confidence"] > 0.5, read
    assert unread["class"]["label"] in {"food or drink", "food", "snack", "crackers"}, unread
    assert "text" not in unread["attributes"], unread


@pytest.mark.real_data
@pytest.mark.parametrize("frame, can", [(0, (540, 365)), (1, (172, 190))], ids=["frame0-fit", "frame1-held-out"])
def test_find_all_soup_cans_answers_the_campbells_can_by_its_colours(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, can: tuple[int, int]
) -> None:
    """No text is read on the soup can, so only its look speaks: a small, closed, white (and red) cylinder. With
    its colours known the Campbell's can fits best (before, a white salt or yogurt pot of the same form did), so
    the query's class may break the tie: the can is answered as a Campbell's soup, hedged (its brand went unread)."""
    (found,) = holding(answered(capsys, store, uoc_folder, "find all soup cans", "--frame", str(frame)), can)
    stated = found["attributes"][Classification.attribute]
    assert stated["value"] == "CampbellsTomatoSoup", found
    assert stated["confidence"] < 0.5, found  # a guess: the brand that would tell went unread


@pytest.fixture
def toffifee_scene(shared_data: Path) -> Path:
    scene = shared_data / "pcl_mosd_tabletop" / "learn" / "learn5.pcd"
    if not scene.is_file():
        pytest.skip(f"needs {scene}")
    return scene


TOFFIFEE = (394, 258)


@pytest.mark.real_data
def test_the_toffifee_box_is_no_drink(toffifee_scene: Path, store: Path, capsys: pytest.CaptureFixture) -> None:
    """mOSD learn scene 5 (held out): a brown, medium, tall box. Drinks (a coffee pack) were the only brown boxes
    the ontology knew, so unread it was called a drink; the ontology now knows sweets and the Toffifee box, so
    unread it is food or drink (it could be either), and with its brand read it is the Toffifee box. (This scene
    is in the calibration's check split; it was looked at to find why it was a drink, nothing was tuned on it.)"""
    unread = answer_at(capsys, store, toffifee_scene, "detect { obj: { type: object, text: false } }", TOFFIFEE)
    assert unread["class"]["label"] in {"food or drink", "food", "snack", "sweets", "Toffifee"}, unread
    # asked with its text, the text is read on the whole frame ("Toffifee" runs up the box's face)
    read = answer_at(capsys, store, toffifee_scene, 'detect { obj: { type: Toffifee, text: "toffifee" } }', TOFFIFEE)
    assert read["class"]["label"] == "Toffifee", read
    assert read["attributes"][Classification.attribute]["confidence"] > 0.5, read
