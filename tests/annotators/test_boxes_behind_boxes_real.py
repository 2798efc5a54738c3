"""A box standing in front of another stays apart from it wherever the grid cells start (bench/profiles/
seg11-analysis.txt, section 7).

learn14: a muesli box stands in front of a white box, 10 cm nearer. Labels are grown from the trusted patches by
distance in the image alone, so at some cell phases a few pixels of the white box's lower edge, seen past the muesli
box's outline, took the muesli box's label. They stretched its footprint over the white box's, just past the
footprint rule's share, and the two boxes joined. At other phases a few pixels of the muesli box took the white
box's label, the other way round (learn14 at (4, 2); learn0 at (2, 0): the box behind's label on the front box's
top). Such strays no longer count toward a join by footprint (ConvexObjects.spilled, merge_parts); learn15's boxes
had joined the same way.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.annotators.conftest import require_folder
from tests.annotators.guard_frames import mosd_score_with_cells_moved

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize(
    ("scene", "offset"),
    [("learn14", (1, 1)), ("learn14", (3, 3)), ("learn14", (4, 2)), ("learn15", (2, 3)), ("learn0", (2, 0))],
)
def test_a_box_in_front_of_a_box_stays_apart_wherever_the_cells_start(
    shared_data: Path, scene: str, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    score = mosd_score_with_cells_moved(path, offset, monkeypatch)
    assert score.matched == score.objects == score.segments
