"""Guard objects (tests/data/labels/guard_objects.json) that came apart or together depending on where the grid
cells start (bench/profiles/seg11-analysis.txt, section 8).

* The drill lies on its side. Its grip and body come out as one piece and its battery as another; the slab join
  puts them together when their lowest heights and tops agree. The teal bowl's rim touches the battery's end
  without a depth seam, and at some cell phases a strip of the rim, 5-7 cm high, took the battery's label by
  growth: its top rose 0.7-1.5 cm above the body's and the drill stayed in two. The slab join now reads the
  heights of the pixels the convexity votes labelled, not of those grown to them.
* The black can stands in the teal bowl. At some phases its side and the bowl's inner wall meet in one connection
  bending inward at 184 1/m (normals 101 degrees apart), while small faces between them agree with both; one vote
  decided nothing, and the small faces joined can and bowl. A single connection bending inward that sharply now
  keeps two large faces apart (ConvexityRules.decisive_bending).
* uoc 1's blue mug and the soup can beside it are as tall as each other (1-10 cm above the table) and touch without
  a depth jump where the mug's rim meets the can's side; at some phases the slab join took them for pieces of one
  object lying flat. A slab's pieces now each span more on the table than they are high.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import Verdict, load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame

pytestmark = pytest.mark.real_data


def verdicts_with_cells_moved(
    frame: int, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> dict[str, Verdict]:
    """The verdict on each labelled object of a uoc frame with the segmenter's crop started ``offset`` (dy, dx)
    earlier."""
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    key = ("uoc_tabletop_realsense", frame)
    return object_verdicts(segment_frame(*key, ClutterParameters()), load_labelled_objects(LABELS)[key])


@pytest.mark.parametrize("offset", [(0, 1), (0, 2), (2, 1)])
def test_the_drill_lying_on_its_side_is_whole_where_the_bowls_rim_touches_its_battery(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    verdicts = verdicts_with_cells_moved(3, offset, monkeypatch)
    assert str(verdicts["power drill"]) == "whole"
    assert str(verdicts["teal bowl"]) == "whole"


@pytest.mark.parametrize("offset", [(0, 4), (3, 4)])
def test_the_can_standing_in_the_bowl_stays_apart_from_it(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    verdicts = verdicts_with_cells_moved(3, offset, monkeypatch)
    assert str(verdicts["black can"]) == "whole"
    assert str(verdicts["teal bowl"]) == "whole"


@pytest.mark.parametrize("offset", [(0, 1), (0, 3)])
def test_a_mug_and_a_can_as_tall_as_each_other_stay_apart(
    uoc_folder: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    verdicts = verdicts_with_cells_moved(1, offset, monkeypatch)
    assert str(verdicts["blue mug"]) == "whole"
    assert str(verdicts["soup can"]) == "whole"
