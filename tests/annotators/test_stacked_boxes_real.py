"""Stacked boxes on mOSD scenes stay apart wherever the grid cells start (bench/profiles/seg11-analysis.txt,
twenty-second session).

learn24: a box lies across two boxes, one standing in front of a long box lying diagonally behind. At some cell
phases the top box's side face and the long box's face, 89 degrees apart, met across the depth gap between them with
a bending just short of the concave limit, and a connection between faces that are not parallel voted convex: the
three boxes came out as one or two segments. Between two large faces, a connection across a crease now votes convex
only where it bends outward (annotators/geometry/convexity.py, inward_creases).

learn19: a flat box lies on a larger flat box. Where a grid cell lay across the depth seam along the upper box's
front edge, it held a strip of the upper box's front above the seam and one of the lower box's front below it (the
seam ends before the cell's edge, so both are one surface), and the two strips fitted one plane tilted between them,
which joined the two boxes' faces into one at 16 of 36 cell phases. A cell now gives a patch to each of its
4-connected pieces (grid_patches); so does learn22's cell across its middle box's edge. (At 11 other phases the upper
box's side face still meets the lower box's front convexly: learn19 stays merged there.)
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.annotators.conftest import require_folder
from tests.annotators.guard_frames import mosd_score_with_cells_moved

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize("offset", [(1, 2), (3, 4), (4, 2)])
def test_every_stacked_box_is_found_wherever_the_cells_start(
    shared_data: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / "learn24.pcd"
    score = mosd_score_with_cells_moved(path, offset, monkeypatch)
    assert score.matched == score.objects == 3


@pytest.mark.parametrize(
    ("scene", "offset"), [("learn19", (2, 0)), ("learn19", (3, 5)), ("learn19", (5, 2)), ("learn22", (2, 0))]
)
def test_a_box_lying_on_a_box_stays_apart_wherever_the_cells_start(
    shared_data: Path, scene: str, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    score = mosd_score_with_cells_moved(path, offset, monkeypatch)
    assert score.matched == score.objects
