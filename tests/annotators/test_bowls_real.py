"""Open containers on real RealSense frames (uoc_tabletop_realsense, read in place from ../shared/data): the white
bowl is one hypothesis of its own at its hand-labelled pixel (tests/data/labels/real_objects.json), which lies on
the bowl's floor - a few millimetres above the table, below the segmenter's lowest candidate height - and covers
its walls too; in frame 0 the teal bowl likewise, and the bits of the white bowl's floor that the depth noise
lifts above the candidate height are no hypotheses of their own."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.readers.choice import reader_for
from robokudo.core.engine import Engine
from robokudo.core.types import ObjectHypothesis
from tests.annotators.test_segmentation_real import UOC_OBJECTS, hypothesis_at
from trees.tabletop import create_pipeline

pytestmark = pytest.mark.real_data

LABELS = Path(__file__).resolve().parents[1] / "data" / "labels" / "real_objects.json"

WALLS = {  # a pixel on the far inner wall of the white bowl, above its floor
    0: (420, 335),
    1: (300, 390),
    2: (470, 225),
    3: (470, 235),
}


def labelled_pixels(frame: int) -> dict[str, tuple[int, int]]:
    """The hand-labelled pixel of each object of a uoc frame."""
    frames = json.loads(LABELS.read_text())["frames"]
    (entry,) = [f for f in frames if f["input"] == "uoc_tabletop_realsense" and f["frame"] == frame]
    return {o["name"]: tuple(o["pixel"]) for o in entry["objects"]}


@pytest.mark.parametrize("frame", [0, 1, 2, 3])
def test_the_white_bowl_is_one_hypothesis_with_its_floor(uoc_folder: Path, frame: int) -> None:
    root = create_pipeline(reader_for(str(uoc_folder), frame))
    assert Engine(root).tick() is Status.SUCCESS, [(c.name, c.feedback_message) for c in root.children]
    hypotheses = root.cas.annotations(ObjectHypothesis)
    labelled = labelled_pixels(frame)
    floor = hypothesis_at(hypotheses, *labelled["white bowl"])
    wall = hypothesis_at(hypotheses, *WALLS[frame])
    assert floor and floor == wall, f"the bowl's floor is in hypothesis {floor}, its wall in {wall}"
    others = {hypothesis_at(hypotheses, x, y) for name, (x, y) in UOC_OBJECTS[frame].items() if name != "white bowl"}
    others |= {hypothesis_at(hypotheses, x, y) for name, (x, y) in labelled.items() if name != "white bowl"}
    assert floor not in others, "the white bowl shares its hypothesis with another object"


def test_the_bowls_floors_in_frame_0_are_no_pieces_of_their_own(uoc_folder: Path) -> None:
    root = create_pipeline(reader_for(str(uoc_folder), 0))
    assert Engine(root).tick() is Status.SUCCESS, [(c.name, c.feedback_message) for c in root.children]
    hypotheses = root.cas.annotations(ObjectHypothesis)
    labelled = labelled_pixels(0)
    for name in ("white bowl", "teal bowl"):
        bowl = hypothesis_at(hypotheses, *labelled[name])
        assert bowl, f"no hypothesis at the {name}'s labelled pixel"
        # the hypotheses lying mostly within the bowl's image box are the bowl itself
        x0, y0, x1, y1 = hypotheses[bowl - 1].roi
        inside = [
            k
            for k, h in enumerate(hypotheses, start=1)
            if np.count_nonzero(h.mask[y0:y1, x0:x1]) > 0.5 * np.count_nonzero(h.mask)
        ]
        assert inside == [bowl], f"the {name} is in hypotheses {inside}"
