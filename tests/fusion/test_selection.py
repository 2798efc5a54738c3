"""Selections among the objects that answer a query (``the leftmost cup``, ``the top box``, ``the biggest bowl``):
from memory through the store, and measured from a viewpoint (camera pose, support plane)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from queries import parse_query
from queries.selection import SELECTIONS, SelectionRequest
from reasoning.beliefs.answer import answer_from_memory
from reasoning.beliefs.filters import belief_filter
from reasoning.beliefs.selection import Viewpoint, select
from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief


def cup(x: float, y: float = 0.0, z: float = 1.0, *, sure: float = 0.9, size: float = 0.08) -> FrameObject:
    return FrameObject(
        position=np.array([x, y, z]),
        frame="camera",
        dimensions=np.array([size, size, size]),
        evidence=[Evidence("class", "Cup", sure, "Classifier")],
        sources={"Seg"},
        confidence=0.9,
    )


def stored(path: Path, *objects: FrameObject) -> None:
    with BeliefStore(path, tracker=BeliefTracker()) as store:
        store.integrate(list(objects), 1.0)


def remembered(path: Path, text: str) -> tuple[list[int], dict | None, str]:
    """The ids answered from memory, the answer's selection (JSON) and its summary."""
    with BeliefStore(path) as store:
        answer = answer_from_memory(store, belief_filter(parse_query(text)), text)
    document = answer.to_dict()
    return [o.id for o in answer.objects], document.get("selection"), answer.summary()


def test_the_leftmost_rightmost_and_closest_cup_from_memory(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(path, cup(0.0, z=0.8), cup(-0.3, z=1.2), cup(0.3, z=1.0))  # ids 1, 2, 3
    assert remembered(path, "find the leftmost cup")[0] == [2]
    assert remembered(path, "find the cup on the right")[0] == [3]
    assert remembered(path, "find the closest cup")[0] == [1]
    assert remembered(path, "find the farthest cup")[0] == [2]
    assert remembered(path, "find the second cup from the left")[0] == [1]
    assert remembered(path, "find the two leftmost cups")[0] == [2, 1]
    assert remembered(path, "find the cups on the left")[0] == [2, 1, 3]  # plural: every cup, left to right
    _, selection, summary = remembered(path, "find the leftmost cup")
    assert selection is not None and selection["by"] == "leftmost" and selection["measure"] == "camera_x"
    assert selection["values"] == [{"id": 2, "value": -0.3}] and selection["tie_with"] is None
    assert "selected leftmost, least camera x" in summary


def test_the_biggest_and_smallest_by_volume(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(path, cup(0.0, size=0.08), cup(0.4, size=0.12), cup(-0.4, size=0.05))
    assert remembered(path, "find the biggest cup")[0] == [2]
    assert remembered(path, "find the smallest cup")[0] == [3]
    assert remembered(path, "find the second biggest cup")[0] == [1]


def test_a_single_cup_is_the_leftmost_and_no_cup_answers_nothing(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(path, cup(0.2))
    ids, selection, summary = remembered(path, "find the leftmost cup")
    assert ids == [1] and selection is not None and selection["tie_with"] is None
    ids, _, summary = remembered(path, "find the leftmost bowl")
    assert ids == [] and summary == "no matching object"
    ids, _, summary = remembered(path, "find the second leftmost cup")
    assert ids == [] and summary.startswith("no matching object")


def test_a_tie_is_said_and_decided_by_what_is_likeliest_asked(tmp_path: Path) -> None:
    """Two cups 4 mm apart in x (under the centimetre a centroid moves between frames): either is the leftmost; the
    one more likely a cup is answered, and the answer says it ties with the other."""
    path = tmp_path / "beliefs.sqlite"
    stored(path, cup(0.004, sure=0.95), cup(0.0, y=0.3, sure=0.6), cup(0.5))
    ids, selection, summary = remembered(path, "find the leftmost cup")
    assert selection is not None
    assert ids == [2] and selection["tie_with"] == 1
    assert "a tie with #1" in summary
    ids, selection, _ = remembered(path, "find the rightmost cup")
    assert ids == [3] and selection is not None and selection["tie_with"] is None


def belief(identifier: int, position: tuple[float, float, float], frame: str = "world") -> ObjectBelief:
    return ObjectBelief(id=identifier, frame=frame, position=np.array(position, dtype=np.float64))


def test_left_is_the_cameras_left_and_top_is_above_the_support_plane() -> None:
    """A camera in the world looking along world +x (image right = world -y): the leftmost object is left in the
    image, not at the least world x; the top one is the highest above the support plane, not the one highest in the
    image."""
    # camera at (0, 0, 1) looking along world +x, image right = world -y, image down = world -z
    cam_to_world = np.array(
        [[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]], dtype=np.float64
    )
    viewpoint = Viewpoint(cam_to_world=cam_to_world)
    beliefs = [belief(1, (1.0, 0.3, 0.5)), belief(2, (2.0, -0.2, 0.5)), belief(3, (0.5, 0.0, 0.8))]
    (left,), note = select(beliefs, SelectionRequest(SELECTIONS["leftmost"]), viewpoint, 1)
    assert left.id == 1 and note.basis == "camera frame"
    (near,), _ = select(beliefs, SelectionRequest(SELECTIONS["closest"]), viewpoint, 1)
    assert near.id == 3
    (top,), note = select(beliefs, SelectionRequest(SELECTIONS["top"]), Viewpoint(), 1)
    assert top.id == 3 and note.basis == "world z"
    chosen, note = select(beliefs, SelectionRequest(SELECTIONS["leftmost"]), Viewpoint())
    assert chosen == [] and note.unmeasured == (1, 2, 3)  # left of whom? no camera pose: nothing is measured
    # a camera tilted down at a table: the plane decides, not image up
    normal = np.array([0.0, -np.sin(0.8), -np.cos(0.8)])
    plane = np.array([*normal, 0.9])
    low_far = belief(4, (0.0, -0.05, 1.3), frame="camera")  # higher in the image
    high_near = belief(5, (0.0, 0.0, 0.9), frame="camera")
    (top,), note = select([low_far, high_near], SelectionRequest(SELECTIONS["top"]), Viewpoint(plane=plane), 1)
    assert top.id == 5 and note.basis == "above the support plane"
    (top,), note = select([low_far, high_near], SelectionRequest(SELECTIONS["top"]), Viewpoint(), 1)
    assert top.id == 4 and note.basis.startswith("up in the image")


def test_the_selection_is_in_the_answers_json(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    stored(path, cup(0.0), cup(0.5, size=0.2))
    with BeliefStore(path) as store:
        answer = answer_from_memory(store, belief_filter(parse_query("find the biggest cup")), "find the biggest cup")
    document = json.loads(answer.to_json())
    assert [o["id"] for o in document["objects"]] == [2]
    assert document["selection"]["by"] == "biggest" and document["selection"]["unit"] == "m^3"
    plain = answer_from_memory(BeliefStore(path), belief_filter(parse_query("find the cups")))
    assert "selection" not in plain.to_dict()
