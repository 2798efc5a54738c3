"""A small piece reaching below its neighbour's lowest heights joins it when the middle of its heights lies above
them (annotators/geometry/support.py, AppendageRules).

With grown patches (``ClutterParameters(grown_patches=True)``) uoc 4's wipes tub lost the lower left of its body:
a piece from 1.2 to 6.5 cm (405 coarse pixels) beside the rest of the tub, whose lowest heights (5 %) began at 2.9
cm because its own lower part was in that piece. An appendage had to lie within its owner's heights, so it stayed
apart. A support under an object lies below it (its middle below the object's lowest heights) and still does not
join; the grid cut the tub at 10 of 36 cell phases, now at 1 (bench/profiles/segscore-analysis.txt).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, segment_frame

pytestmark = pytest.mark.real_data

UOC = "uoc_tabletop_realsense"


def test_the_tubs_lower_part_stays_with_the_tub(uoc_folder: Path) -> None:
    objects = load_labelled_objects(LABELS)[(UOC, 4)]
    labels = segment_frame(UOC, 4, replace(ClutterParameters(), grown_patches=True))
    assert str(object_verdicts(labels, objects)["wipes tub"]) == "whole"
