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
* uoc 1's white mug: at some phases the inside seen over its rim comes out in two halves beside the outer wall.
  Each half joined one holder, the other half (their shared border the longest), and the whole inside never met the
  outside. The inner-wall join now repeats while anything joins, so the joined inside joins the outside next.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame

pytestmark = pytest.mark.real_data


CASES = [
    # (uoc frame, crop offset (dy, dx), the objects that must be whole)
    pytest.param(3, (0, 1), ("power drill", "teal bowl"), id="drill-beside-bowl-rim-0-1"),
    pytest.param(3, (0, 2), ("power drill", "teal bowl"), id="drill-beside-bowl-rim-0-2"),
    pytest.param(3, (2, 1), ("power drill", "teal bowl"), id="drill-beside-bowl-rim-2-1"),
    pytest.param(3, (0, 4), ("black can", "teal bowl"), id="can-standing-in-bowl-0-4"),
    pytest.param(3, (3, 4), ("black can", "teal bowl"), id="can-standing-in-bowl-3-4"),
    pytest.param(1, (0, 1), ("blue mug", "soup can"), id="mug-and-can-as-tall-0-1"),
    pytest.param(1, (0, 3), ("blue mug", "soup can"), id="mug-and-can-as-tall-0-3"),
    pytest.param(1, (1, 2), ("white mug",), id="mug-inside-in-two-1-2"),
    pytest.param(1, (4, 2), ("white mug",), id="mug-inside-in-two-4-2"),
]


@pytest.mark.parametrize(("frame", "offset", "names"), CASES)
def test_objects_whose_wholeness_hung_on_the_cell_phase_are_whole(
    uoc_folder: Path, frame: int, offset: tuple[int, int], names: tuple[str, ...], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    key = ("uoc_tabletop_realsense", frame)
    verdicts = object_verdicts(segment_frame(*key, ClutterParameters()), load_labelled_objects(LABELS)[key])
    assert {name: str(verdicts[name]) for name in names} == dict.fromkeys(names, "whole")
