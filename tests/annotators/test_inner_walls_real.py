"""An open container's inside seen over its rim joins its outside even where the inside is the larger part in view
or ends high up, hidden by the front rim (annotators/geometry/inner_walls.py).

With grown patches (``ClutterParameters(grown_patches=True)``), uoc 1's white mug came out as its inside (with rim
and handle, 3189 px) and its outer front wall (1986 px), and uoc 4's purple cup lost its far inner wall, whose lowest
point is 5.7 cm up; both insides were refused as candidates because join_unsupported's rule for a piece resting on
another (smaller than its holder, reaching down into it) was applied to them. Scored against the hand labels of
tests/data/labels/guard_objects.json.

With the grid cells one phase over (the crop started 4 coarse columns earlier), uoc 1's white mug came out as its
inside with the rim (3154 px) and its outer wall: the rim's normals, pointing away from the mug's axis, pulled the
median of the wall's distances to the axis along the normals under half its distance to it, so the inside had no
axis. Now most of the wall's points must face the axis (80 % do).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame

pytestmark = pytest.mark.real_data

UOC = "uoc_tabletop_realsense"


@pytest.mark.parametrize(("index", "name"), [(1, "white mug"), (4, "purple cup")])
def test_the_inside_seen_over_the_rim_joins_the_outside(uoc_folder: Path, index: int, name: str) -> None:
    objects = load_labelled_objects(LABELS)[(UOC, index)]
    labels = segment_frame(UOC, index, replace(ClutterParameters(), grown_patches=True))
    assert str(object_verdicts(labels, objects)[name]) == "whole"


def test_an_inside_holding_its_rim_joins_the_outside_at_another_cell_phase(
    uoc_folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(1, 4))
    objects = load_labelled_objects(LABELS)[(UOC, 1)]
    labels = segment_frame(UOC, 1, ClutterParameters())
    assert str(object_verdicts(labels, objects)["white mug"]) == "whole"
