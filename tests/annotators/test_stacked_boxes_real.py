"""Stacked boxes on a mOSD scene stay three objects wherever the grid cells start (bench/profiles/seg11-analysis.txt,
twenty-second session).

learn24: a box lies across two boxes, one standing in front of a long box lying diagonally behind. At some cell
phases the top box's side face and the long box's face, 89 degrees apart, met across the depth gap between them with
a bending just short of the concave limit, and a connection between faces that are not parallel voted convex: the
three boxes came out as one or two segments. Between two large faces, a connection across a crease now votes convex
only where it bends outward (annotators/geometry/convexity.py, inward_creases).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.segmentation import score_segmentation
from tests.annotators.conftest import require_folder
from tests.annotators.guard_frames import crop_moved, segment_mosd_scene

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize("offset", [(1, 2), (3, 4), (4, 2)])
def test_every_stacked_box_is_found_wherever_the_cells_start(
    shared_data: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / "learn24.pcd"
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    labels, truth, valid = segment_mosd_scene(path, ClutterParameters())
    score = score_segmentation(truth, labels, valid)
    assert score.matched == score.objects == 3
