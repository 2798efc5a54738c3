"""Mugs and cups on real RealSense frames, classified by their form (issue 15, item 6).

A mug is told from a cup, a bowl and a can by its features (a handle, an open top, its height over width), not by the
query's class: the blue mug is ranked Mug by the classifier before any query names a class, the handle-less purple cup
is not made a mug by "find the mug", "find the green mug" answers nothing on a table without one, the white mugs are
seen open and a closed can is not made a cup by "find a cup". A cup may have a handle (rk:Mug) or not
(rk:HandlelessCup), both below rk:Cup, which says nothing about a handle: "find a cup" answers mugs too, named mugs, and
the purple cup, named a cup (that it has no handle is not seen for sure: a mug's may be behind it). Nor does the query
decide what an unsettled form cue may still tell: half a bowl, or a can with a stray handle seen closed though not
surely, is no mug for "find all mugs". The queries run through ``robokudo query`` on the frames in ../shared/data, read
in place. Pixels are read off the colour images (tests/data/labels/real_objects.json labels the same objects).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from annotators.classification.knowledge_classifier import UNKNOWN_CLASS, KnowledgeClassifier, best_match, score
from robokudo.application import cli
from robokudo.application.service import AnsweringService
from robokudo.core.types import Classification, ObjectHypothesis

BLUE_MUG = {1: (222, 230), 3: (490, 130)}
"""The blue mug in frames 1 and 3."""
HANDLE_IN_VIEW = (3,)
"""The frames whose blue mug shows its handle in depth. In frame 1 (as in frame 0) the handle stands straight behind
the body: the colour image shows a nub of it over the far rim (about (215-224, 177-181)) where the depth image reads
the table (1.03 m; the far rim 0.86 m). A handle was seen there only while the segmenter cut the mug's inside off
its outside: the outside alone, tapered, stuck out of the circle fitted at its foot on its right (pixels x 229-250,
y 228-241, heights 8-9 cm). Whether a mug whose handle is hidden is a mug is the classifier's question."""
TOUCHING_MUG = (480, 135)
"""The blue mug in frame 2: its handle touches the drill."""
WHITE_MUG = {0: (300, 255), 1: (325, 275)}
"""The white mug in frames 0 and 1 (white, glossy inside: the depth camera sees its inside smoothed but deep)."""
CANS = {
    1: {"spam can": (75, 320), "soup can": (172, 190)},
    3: {"spam can": (155, 262), "soup can": (150, 170)},
}
"""The closed cans in frames 1 and 3."""
PURPLE_CUP = (468, 280)
"""The purple cup (no handle) in frame 4."""
NOT_MUGS = {
    1: {"teal bowl": (185, 350), "spam can": (75, 320), "cheez-it box": (480, 320), "mustard bottle": (280, 180)},
    3: {"teal bowl": (340, 185), "spam can": (155, 262), "cheez-it box": (260, 70), "mustard bottle": (190, 160)},
    4: {"purple cup": PURPLE_CUP, "cashew can": (425, 175), "duplo brick": (245, 300)},
}


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path / "beliefs.sqlite"


def ask(capsys: pytest.CaptureFixture, store: Path, query: str, folder: Path, frame: int) -> list[dict]:
    """The objects ``robokudo query`` answers on one frame."""
    code = cli.main(["query", query, "--input", str(folder), "--frame", str(frame), "--store", str(store), "--json"])
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)["objects"]


def covering(objects: list[dict], pixel: tuple[int, int]) -> list[dict]:
    x, y = pixel
    return [o for o in objects if o["roi"] and o["roi"][0] <= x < o["roi"][2] and o["roi"][1] <= y < o["roi"][3]]


def hypothesis_at(hypotheses: list[ObjectHypothesis], pixel: tuple[int, int]) -> ObjectHypothesis:
    x, y = pixel
    counts = [int(h.mask[y - 2 : y + 3, x - 2 : x + 3].sum()) for h in hypotheses]
    assert max(counts, default=0) > 0, f"no hypothesis at {pixel}"
    return hypotheses[int(np.argmax(counts))]


@pytest.mark.real_data
@pytest.mark.parametrize("frame", HANDLE_IN_VIEW)
def test_the_blue_mug_is_ranked_mug_by_its_features_and_nothing_else_is_called_a_mug(
    uoc_folder: Path, store: Path, frame: int
) -> None:
    with AnsweringService.open(store, input_path=str(uoc_folder), frame=frame) as service:
        outcome = service.answer("find all objects")  # no class asked: nothing but the features decide
    classifier = next(n for n in outcome.tree.iterate() if isinstance(n, KnowledgeClassifier))
    assert classifier.expected in (None, UNKNOWN_CLASS)  # the root class breaks no tie
    hypotheses = outcome.tree.cas.annotations(ObjectHypothesis)
    mug = classifier.cues(hypothesis_at(hypotheses, BLUE_MUG[frame]))
    assert mug.handle is not None and mug.handle[0], "the mug's handle was not seen"
    assert mug.open_top is not None and mug.open_top[0], "the mug was not seen open"
    matches = {m.profile.class_name: m for m in (score(p, mug) for p in classifier.profiles)}
    assert best_match(list(matches.values())).profile.class_name == "Mug"
    assert matches["Mug"].score > matches["Cup"].score + 0.05  # the handle, not the query, tells it from a cup
    assert matches["Mug"].score > matches["CannedFood"].score + 0.05  # the open top tells it from a can
    for name, pixel in NOT_MUGS[frame].items():
        said = hypothesis_at(hypotheses, pixel).first(Classification)
        assert said is None or said.class_name != "Mug", name


@pytest.mark.real_data
@pytest.mark.parametrize("frame", HANDLE_IN_VIEW)
def test_find_the_mug_answers_the_blue_mug_only(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int
) -> None:
    objects = ask(capsys, store, "find the mug", uoc_folder, frame)
    (mug,) = objects
    assert mug["class"]["label"] == "mug"
    assert covering([mug], BLUE_MUG[frame]), mug["roi"]
    for name, pixel in NOT_MUGS[frame].items():
        assert not covering(objects, pixel), name


@pytest.mark.real_data
def test_a_cup_without_a_handle_is_a_cup_and_not_a_mug(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture
) -> None:
    (cup,) = ask(capsys, store, "find a cup", uoc_folder, 4)
    assert cup["class"]["label"] == "cup" and covering([cup], PURPLE_CUP), cup
    assert ask(capsys, store, "find the mug", uoc_folder, 4) == []  # the query's class does not make it a mug


@pytest.mark.real_data
def test_find_all_cups_answers_both_mugs_and_names_the_one_whose_handle_is_hidden_a_cup(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture
) -> None:
    """Frame 0: the white mug shows its handle, the blue one hides it behind its body. Both are cups; the white one is
    named a mug, the blue one a cup - not a cup without a handle, which its hidden handle does not make it."""
    objects = ask(capsys, store, "find all cups", uoc_folder, 0)
    assert [o["class"]["label"] for o in covering(objects, WHITE_MUG[0])] == ["mug"], objects
    assert [o["class"]["label"] for o in covering(objects, (205, 195))] == ["cup"], objects
    assert len(objects) == 2, objects


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [0, 3])
def test_find_the_green_mug_answers_nothing_on_a_table_without_one(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int
) -> None:
    assert ask(capsys, store, "find the green mug", uoc_folder, frame) == []  # a teal bowl, blue and white mugs


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [0, 1])
def test_the_white_mug_is_seen_open(uoc_folder: Path, store: Path, frame: int) -> None:
    with AnsweringService.open(store, input_path=str(uoc_folder), frame=frame) as service:
        outcome = service.answer("find all objects")
    classifier = next(n for n in outcome.tree.iterate() if isinstance(n, KnowledgeClassifier))
    mug = classifier.cues(hypothesis_at(outcome.tree.cas.annotations(ObjectHypothesis), WHITE_MUG[frame]))
    assert mug.open_top is not None and mug.open_top[0] and mug.open_top[1] > 0.5, mug.open_top


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [1, 3])
def test_the_spam_can_is_closed_and_scored_a_can_before_a_cup(uoc_folder: Path, store: Path, frame: int) -> None:
    with AnsweringService.open(store, input_path=str(uoc_folder), frame=frame) as service:
        outcome = service.answer("find a cup")  # the query's class does not lift a cup over the can the cues prefer
    classifier = next(n for n in outcome.tree.iterate() if isinstance(n, KnowledgeClassifier))
    can = hypothesis_at(outcome.tree.cas.annotations(ObjectHypothesis), CANS[frame]["spam can"])
    cues = classifier.cues(can)
    assert cues.open_top is not None and not cues.open_top[0], "the can was seen open"
    matches = {m.profile.class_name: m for m in (score(p, cues) for p in classifier.profiles)}
    assert matches["CannedFood"].score > matches["Cup"].score + 0.05  # its closed top tells it from a cup
    said = can.first(Classification)
    assert said is None or said.class_name != "Cup"


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [1, 3])
def test_find_a_cup_answers_no_can(uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int) -> None:
    objects = ask(capsys, store, "find a cup", uoc_folder, frame)
    assert all(o["class"]["label"] in ("cup", "mug", "cup without a handle") for o in objects), objects
    for name, pixel in CANS[frame].items():
        assert not covering(objects, pixel), name


@pytest.mark.real_data
def test_find_a_cup_answers_the_mug_and_says_it_is_a_mug(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture
) -> None:
    """A mug is a cup (while Mug and Cup were disjoint, "find a cup" left it out); the answer says it is a mug, not a
    cup without a handle."""
    objects = ask(capsys, store, "find a cup", uoc_folder, 2)
    assert [o["class"]["label"] for o in covering(objects, TOUCHING_MUG)] == ["mug"], objects
    assert all(o["class"]["label"] in ("cup", "mug") for o in objects), objects


@pytest.mark.real_data
@pytest.mark.parametrize("frame", [1, 3])
def test_find_all_mugs_answers_the_blue_mug_and_no_bowl_can_or_box(
    uoc_folder: Path, store: Path, capsys: pytest.CaptureFixture, frame: int
) -> None:
    # frame 1: the soup can is cut with a neighbour that sticks out like a handle, its top seen closed though not
    # surely; frame 3: the teal bowl is cut in half by the can in it, and its flaring side may be a handle
    objects = ask(capsys, store, "find all mugs", uoc_folder, frame)
    if frame in HANDLE_IN_VIEW:
        assert covering(objects, BLUE_MUG[frame]), objects
    assert all(o["class"]["label"] == "mug" for o in objects), objects
    for name, pixel in {**NOT_MUGS[frame], **CANS[frame]}.items():
        assert not covering(objects, pixel), name
