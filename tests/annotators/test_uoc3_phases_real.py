"""Objects of uoc frame 3 that came apart or together depending on where the grid cells start (bench/profiles/
seg11-analysis.txt, section 8).

* The drill lies on its side. Its grip and body come out as one piece and its battery as another; the slab join
  puts them together when their lowest heights and tops agree. The teal bowl's rim touches the battery's end
  without a depth seam, and at some cell phases a strip of the rim, 5-7 cm high, took the battery's label by
  growth: its top rose 0.7-1.5 cm above the body's and the drill stayed in two. The slab join now reads the
  heights of the pixels the convexity votes labelled, not of those grown to them.
* The black can stands in the teal bowl. At some phases its side and the bowl's inner wall meet in one connection
  bending inward at 184 1/m (normals 101 degrees apart), while small faces between them agree with both; one vote
  decided nothing, and the small faces joined can and bowl. A single connection bending inward that sharply now
  keeps two large faces apart (ConvexityRules.decisive_bending).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import Verdict, load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame

pytestmark = pytest.mark.real_data

UOC3 = ("uoc_tabletop_realsense", 3)


def verdicts_with_cells_moved(offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch) -> dict[str, Verdict]:
    """The verdict on each labelled object of uoc 3 with the segmenter's crop started ``offset`` (dy, dx) earlier."""
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    return object_verdicts(segment_frame(*UOC3, ClutterParameters()), load_labelled_objects(LABELS)[UOC3])


@pytest.mark.parametrize("offset", [(0, 1), (0, 2), (2, 1)])
def test_the_drill_lying_on_its_side_is_whole_where_the_bowls_rim_touches_its_battery(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    verdicts = verdicts_with_cells_moved(offset, monkeypatch)
    assert str(verdicts["power drill"]) == "whole"
    assert str(verdicts["teal bowl"]) == "whole"


@pytest.mark.parametrize("offset", [(0, 4), (3, 4)])
def test_the_can_standing_in_the_bowl_stays_apart_from_it(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    verdicts = verdicts_with_cells_moved(offset, monkeypatch)
    assert str(verdicts["black can"]) == "whole"
    assert str(verdicts["teal bowl"]) == "whole"
