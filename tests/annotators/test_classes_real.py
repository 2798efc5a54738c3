"""Known objects on real frames are named by their class, or by the class above it when the cues cannot tell the
leaves apart, and objects no profile describes stay unknown (issue 15, item 6).

What a user sees from ``robokudo query "find all objects"``, and, for the uoc frames, from the same query without
text reading (``detect { obj: { type: object, text: false } }``; "find all objects" reads text, and the Cheez-It box
is then named by its brand, see test_brands.py): unread, the Cheez-It box ties with milk, juice and coffee cartons
and with a bag of chips (all red or white medium boxes, all named by their printed text), and so is "food or drink";
the dark blue mug, whose handle faces away, ties with a cup and a glass and is "a container"; the spam can, whose
text is not read, is at least "food". The cookie tin (a wide, round, orange patterned tin) used to look most like a
carrot or a banana; those are long and narrow (``rk:minElongation``) and it is round, so it stays an unknown object;
so do the drill, the laptop and the cardboard box.

Pixels and splits are those of tests/data/labels/real_objects.json: uoc frames 0 and 2 and mOSD learn scene 35 are
in the fit split (what the rule was checked on while it was made); uoc frames 1 and 3, the milk carton scene and
mOSD learn scene 40 are in the check split and are held out here.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reasoning.beliefs.store import BeliefStore
from robokudo.application import cli
from robokudo.core.types import Classification

pytestmark = pytest.mark.real_data


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path / "answers.sqlite"


CUES_ONLY = "detect { obj: { type: object, text: false } }"
"""Every object, classified by what the experts see without reading text."""


def classes_at(
    capsys: pytest.CaptureFixture, store: Path, source: Path, frame: int, pixels: dict, query: str = "find all objects"
) -> dict[str, set]:
    """The class labels ``robokudo query QUERY`` gives the objects whose image box holds each pixel."""
    code = cli.main(["query", query, "--input", str(source), "--frame", str(frame), "--store", str(store), "--json"])
    out = capsys.readouterr().out
    assert code == 0, out
    objects = json.loads(out)["objects"]
    found = {}
    for name, (x, y) in pixels.items():
        holding = [o for o in objects if o["roi"] and o["roi"][0] <= x < o["roi"][2] and o["roi"][1] <= y < o["roi"][3]]
        # the smallest box holding the pixel is the object's own (a bigger one may reach over it)
        own = min(holding, key=lambda o: (o["roi"][2] - o["roi"][0]) * (o["roi"][3] - o["roi"][1]), default=None)
        assert own is not None, f"the {name} was not seen"
        found[name] = own["class"]["label"]
    return found


UNKNOWN = "unknown object"
BOX_OF_FOOD_OR_DRINK = {"food or drink", "food", "snack", "crackers"}
CONTAINER = {"container", "mug", "cup"}
FOOD = {"food", "canned food", "food or drink"}


@pytest.mark.parametrize(
    "frame, pixels",
    [
        (0, {"cheez-it box": (500, 250), "blue mug": (205, 195), "spam can": (75, 310), "drill": (345, 140)}),  # fit
        # held out; the teal bowl at its left wall: at the label pixel (340, 185) the drill's box, smaller than the
        # whole bowl's, reaches over the bowl's back rim
        (3, {"cheez-it box": (260, 70), "teal bowl": (265, 200), "drill": (395, 180)}),
    ],
)
def test_find_all_objects_names_the_class_above_leaves_it_cannot_tell_apart(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, pixels: dict
) -> None:
    found = classes_at(capsys, store, uoc_folder, frame, pixels, CUES_ONLY)
    assert found["cheez-it box"] in BOX_OF_FOOD_OR_DRINK, found
    # the drill in one piece is a power drill; a piece of it is no class the experts can name (frame 0's: see
    # test_a_drill_standing_on_its_battery_is_a_power_drill_by_its_waist)
    assert found["drill"] in {UNKNOWN, "power drill"}, found
    if frame == 0:
        assert found["blue mug"] in CONTAINER, found
        assert found["spam can"] in FOOD, found
    else:
        assert found["teal bowl"] in {"container", "bowl"}, found


@pytest.mark.parametrize("frame, drill", [(0, (345, 140)), (1, (380, 150))])  # fit, held out
def test_a_drill_standing_on_its_battery_is_a_power_drill_by_its_waist(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int, drill: tuple[int, int]
) -> None:
    """Its grip is narrower than its body above and its battery below (the form expert's waist), which no box, can,
    mug or bowl is. Frame 1's drill, held out, was "unknown object" before the waist cue: it led the next class by
    0.08, too little for the calibration (bench/bench_calibration.py --details).

    Frame 0's drill was a power drill while its segment held a strip of the table beside it, which the form expert
    took for a handle (waist-analysis.txt). Since the convexity grouping makes weak agreements last
    (seam-analysis.txt) the strip is gone, no handle is seen, and PowerDrill leads the orange cracker box by 0.06:
    too little to assert. It must never be named as anything else."""
    allowed = {"power drill"} if frame == 1 else {UNKNOWN, "power drill"}
    assert classes_at(capsys, store, uoc_folder, frame, {"drill": drill}, CUES_ONLY)["drill"] in allowed


def test_the_milk_carton_is_food_or_drink_held_out(
    shared_data: Path, store: Path, capsys: pytest.CaptureFixture
) -> None:
    scene = shared_data / "pcl_tabletop_pcd" / "milk_cartoon_all_small_clorox.pcd"
    if not scene.is_file():
        pytest.skip(f"needs {scene}")
    found = classes_at(capsys, store, scene, 0, {"milk carton": (280, 150)})
    assert found["milk carton"] in {"food or drink", "drink", "milk"}, found


@pytest.mark.parametrize("scene, tin", [("learn35.pcd", (300, 389)), ("learn40.pcd", (165, 353))])  # fit, held out
def test_a_round_cookie_tin_is_no_carrot_nor_banana(
    shared_data: Path, store: Path, capsys: pytest.CaptureFixture, scene: str, tin: tuple[int, int]
) -> None:
    source = shared_data / "pcl_mosd_tabletop" / "learn" / scene
    if not source.is_file():
        pytest.skip(f"needs {source}")
    assert classes_at(capsys, store, source, 0, {"cookie tin": tin})["cookie tin"] == UNKNOWN


def answered_at(capsys: pytest.CaptureFixture, store: Path, source: Path, frame: int, query: str, pixel: tuple) -> dict:
    """The answer object of ``robokudo query QUERY --json`` whose image box holds ``pixel`` (the smallest one)."""
    code = cli.main(["query", query, "--input", str(source), "--frame", str(frame), "--store", str(store), "--json"])
    out = capsys.readouterr().out
    objects = json.loads(out)["objects"] if code == 0 else []
    x, y = pixel
    holding = [o for o in objects if o["roi"] and o["roi"][0] <= x < o["roi"][2] and o["roi"][1] <= y < o["roi"][3]]
    assert holding, f"{query!r} on frame {frame} answered nothing at {pixel}: {out}"
    return min(holding, key=lambda o: (o["roi"][2] - o["roi"][0]) * (o["roi"][3] - o["roi"][1]))


def class_confidence(answered: dict) -> float:
    """The probability the answer gives that the object's class is right."""
    return answered["attributes"][Classification.attribute]["confidence"]


# the mustard bottle: frames 0 and 2 are in the fit split, 1 and 3 held out (labels/real_objects.json)
MUSTARD = [(0, (285, 100)), (1, (280, 180)), (2, (190, 150)), (3, (190, 160))]


@pytest.mark.parametrize("frame, pixel", [MUSTARD[0], MUSTARD[3]], ids=["frame0-fit", "frame3-held-out"])
def test_find_all_bottles_answers_the_mustard_bottle(
    capsys: pytest.CaptureFixture, store: Path, frame: int, pixel: tuple
) -> None:
    """A mustard is packaged in a bottle (rk:packagedIn), so "find all bottles" asks for it. Its label went unread
    and it ties with a lemon soda (a can), so the answer is hedged: a low class probability, marked "?". The
    probability shown is that it answers to "bottle" (``class.answers``): above that of the mustard itself, whose
    label went unread, as likely as the tie with the soda allows."""
    found = answered_at(capsys, store, Path("../shared/data/uoc_tabletop_realsense"), frame, "find all bottles", pixel)
    assert found["class"]["label"] in {"bottle", "plastic bottle", "mustard"}, found
    assert class_confidence(found) < 0.5, found
    stated = {a["value"]: a["confidence"] for a in found["attributes"][Classification.attribute]["alternatives"]}
    assert stated.get("Mustard", 0.0) < found["class"]["answers"] < 0.5, found


def test_that_the_mustard_answers_to_container_is_shown_but_not_kept_in_its_belief(
    capsys: pytest.CaptureFixture, store: Path
) -> None:
    """How likely the mustard answers "find all containers" is a figure of that answer (AnswersTo), not something the
    object is: the belief store keeps only what the mustard was classified as (a bottle, the query's class deciding
    between the bottle classes it ties with), so a later query on the same store does not count "container" as a
    class of it; the answer still shows the figure."""
    frame, pixel = MUSTARD[0]
    source = Path("../shared/data/uoc_tabletop_realsense")
    found = answered_at(capsys, store, source, frame, "find all containers", pixel)
    stated = {a["value"]: a["confidence"] for a in found["attributes"][Classification.attribute]["alternatives"]}
    assert max(stated.values()) < found["class"]["answers"] < 0.5, found
    assert "Container" not in stated, stated
    with BeliefStore(store) as beliefs:
        kept = beliefs.get(found["id"])
        assert kept is not None and "Container" not in kept.attributes[Classification.attribute].values, kept
    again = answered_at(capsys, store, source, frame, "find all containers", pixel)  # a second look, the same store
    assert again["id"] == found["id"] and again["class"]["answers"] > max(stated.values()), again
    with BeliefStore(store) as beliefs:
        assert "Container" not in beliefs.get(found["id"]).attributes[Classification.attribute].values


@pytest.mark.parametrize("frame, pixel", [MUSTARD[2], MUSTARD[1]], ids=["frame2-fit", "frame1-held-out"])
def test_find_the_mustard_answers_the_yellow_bottle_hedged(
    capsys: pytest.CaptureFixture, store: Path, frame: int, pixel: tuple
) -> None:
    found = answered_at(capsys, store, Path("../shared/data/uoc_tabletop_realsense"), frame, "find the mustard", pixel)
    assert found["class"]["label"] == "mustard" and class_confidence(found) < 0.5, found
