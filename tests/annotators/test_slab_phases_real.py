"""The drill lying on its side in uoc frame 3 is one object wherever the grid cells start (bench/profiles/
seg11-analysis.txt, section 8).

Its grip and body come out as one piece and its battery as another; the slab join puts them together when their
lowest heights and tops agree. The teal bowl's rim touches the battery's end without a depth seam, and at some
cell phases a strip of the rim, 5-7 cm high, took the battery's label by growth: its top rose 0.7-1.5 cm above
the body's and the drill stayed in two. The slab join now reads the heights of the pixels the convexity votes
labelled, not of those grown to them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame

pytestmark = pytest.mark.real_data

UOC3 = ("uoc_tabletop_realsense", 3)


@pytest.mark.parametrize("offset", [(0, 1), (0, 2), (2, 1)])
def test_the_drill_lying_on_its_side_is_whole_where_the_bowls_rim_touches_its_battery(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    objects = load_labelled_objects(LABELS)[UOC3]
    verdicts = object_verdicts(segment_frame(*UOC3, ClutterParameters()), objects)
    assert str(verdicts["power drill"]) == "whole"
    assert str(verdicts["teal bowl"]) == "whole"
