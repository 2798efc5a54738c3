"""Two objects that touch, joined through the small faces along their seam.

Where two objects touch, the grouping's patches along the seam come out as small faces, and a small face may agree
with the objects on either side on a single convex vote each. Joined one after another, such weak agreements carried
mOSD learn19's two boxes into one segment at some grid cell phases, learn42's two cylinders at others (both also
seen by a camera rolled a quarter turn), and uoc 2's cheez-it box into the power drill beside it at half of them. A weak
agreement may still attach a few faces to an object (a pot's handle, hanging on its body by single votes), but it no
longer joins two groups that are each an object's surface (ConvexityRules.object_points;
bench/profiles/seam-analysis.txt), and it is made after every other agreement: on uoc 3 a face of the drill, tied to
it by single votes that bend outward as an edge does, first went with the box on a weak vote and took the drill along.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from annotators.readers.frame_readers import PcdReader
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.camera_resampling import rolled
from tests.annotators.conftest import SHARED_DATA, require_folder
from tests.annotators.guard_frames import LABELS, crop_moved, mosd_score_with_cells_moved, segment_frame
from tests.annotators.test_clutter_camera_resolution_real import found

pytestmark = pytest.mark.real_data

LEARN = SHARED_DATA / "pcl_mosd_tabletop" / "learn"


@pytest.mark.parametrize(
    ("scene", "offset"),
    [("learn19", (0, 5)), ("learn19", (3, 3)), ("learn42", (2, 2)), ("learn42", (3, 4))],
)
def test_two_touching_objects_are_found_at_cell_phases_where_seam_faces_joined_them(
    scene: str, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    score = mosd_score_with_cells_moved(require_folder(LEARN) / f"{scene}.pcd", offset, monkeypatch)
    assert (score.matched, score.objects, score.segments) == (2, 2, 2)


@pytest.mark.parametrize("scene", ["learn19", "learn42"])  # two boxes, two cylinders
def test_two_touching_objects_are_found_by_a_camera_rolled_a_quarter_turn(scene: str) -> None:
    frame = PcdReader(require_folder(LEARN) / f"{scene}.pcd").load()
    assert found(rolled(frame, 1)) == (2, 2, 2)


@pytest.mark.parametrize(
    ("frame", "offset"), [(2, (0, 1)), (2, (2, 2)), (2, (4, 5)), (3, (0, 3)), (3, (2, 4)), (3, (0, 5))]
)
def test_the_cheez_it_box_and_the_drill_beside_it_stay_apart(
    uoc_folder: Path, frame: int, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    key = ("uoc_tabletop_realsense", frame)
    verdicts = object_verdicts(segment_frame(*key, ClutterParameters()), load_labelled_objects(LABELS)[key])
    names = ("cheez-it box", "power drill")
    assert {name: str(verdicts[name]) for name in names} == dict.fromkeys(names, "whole")


@pytest.mark.parametrize(("scene", "offset", "objects"), [("learn39", (0, 4), 4), ("learn40", (1, 0), 3)])
def test_a_pots_handle_hanging_on_single_votes_stays_with_its_body(
    scene: str, offset: tuple[int, int], objects: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    score = mosd_score_with_cells_moved(require_folder(LEARN) / f"{scene}.pcd", offset, monkeypatch)
    assert (score.matched, score.objects, score.segments) == (objects, objects, objects)
