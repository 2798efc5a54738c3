"""With grown patches (ClutterParameters(grown_patches=True)) two faces too small to be trusted join on fewer votes
than large faces need only where one is the other's best neighbour (bench/profiles/seg10-analysis.txt).

On uoc frame 2 grown patches cut the Cheez-It box and the drill beside it into a chain of small faces (6-60 points)
that each joined every neighbour on one convex vote, so the box, the drill, the mug, the bowl and the can
in it became one segment; on uoc frame 1 the tall can joined the blue mug the same way.

On uoc frame 3 the drill's chuck (93 cm away) ends 6 cm behind the blue mug's handle (87 cm), and the stereo depth
ramp between them is a patch of its own, 73 degrees off its line of sight, that bent gently inward into the chuck
and voted convex: the chuck joined the handle, and the mug with it. A grazing patch's inward bend casts no convex
vote (``ClutterParameters.grazing_degrees``; annotators/geometry/convexity.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters
from tests.annotators.guard_frames import segment_frame

pytestmark = pytest.mark.real_data

APART = {
    2: {"Cheez-It box": (260, 60), "drill": (367, 126), "blue mug": (505, 125)},
    1: {"tall can": (167, 185), "blue mug": (222, 225)},
}
"""Per uoc frame, a pixel (column, row) on each of objects that stand apart."""


def labels(index: int) -> np.ndarray:
    """HxW segment numbers (0 = none) of uoc frame ``index`` segmented with grown patches."""
    return segment_frame("uoc_tabletop_realsense", index, ClutterParameters(grown_patches=True))


@pytest.mark.parametrize("index", sorted(APART))
def test_objects_standing_apart_are_not_chained_into_one_segment(uoc_folder: Path, index: int) -> None:
    found = labels(index)
    held = {name: int(found[row, col]) for name, (col, row) in APART[index].items()}
    assert all(held.values()), held  # each pixel lies on some segment
    assert len(set(held.values())) == len(held), held


def test_the_drill_stays_one_segment(uoc_folder: Path) -> None:
    found = labels(2)
    body, battery = found[126, 367], found[175, 392]  # (row, column) on the drill's body and on its battery
    assert body > 0 and body == battery, (body, battery)


def test_the_drill_chuck_is_not_joined_to_the_mug_handle_over_the_depth_ramp(uoc_folder: Path) -> None:
    found = labels(3)
    body, chuck, handle, mug = found[115, 370], found[115, 420], found[117, 441], found[117, 490]
    assert mug > 0 and handle == mug, (handle, mug)  # the mug stays whole with its handle
    assert chuck > 0 and chuck != mug, (chuck, mug)
    assert chuck == body, (chuck, body)
