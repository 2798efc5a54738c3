"""``robokudo eval segmentation`` on shared labelled mOSD scenes, against figures derived in the test itself.

learn0 holds two boxes standing apart (every object should be found); learn17 a box lying on another (two
touching objects that must be separated). The expected figures are worked out here from the label field and the
segments by plain counting - objects from the labels, each object paired with the segment covering most of it,
boxes and overlaps counted pixel by pixel - not taken from the command.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from annotators.readers.frame_readers import PcdReader
from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder
from trees.segmenters import SEGMENTERS

pytestmark = pytest.mark.real_data


@pytest.fixture(scope="module")
def learn() -> Path:
    return require_folder(SHARED_DATA / "pcl_mosd_tabletop" / "learn")


def evaluate(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    capsys.readouterr()
    status = cli.main(["eval", "segmentation", *argv])
    out, err = capsys.readouterr()
    return status, out, err


def box(mask: np.ndarray) -> tuple[int, int, int, int]:
    rows, cols = np.nonzero(mask)
    return cols.min(), rows.min(), cols.max() + 1, rows.max() + 1


def box_iou(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> float:
    width = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    height = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    shared = width * height
    area = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - shared
    return shared / area


def expected_figures(path: Path) -> dict[str, float]:
    """The scene's figures counted by hand: objects, segments, and (each object with its best segment, which is
    a different one for every object here) the boxes' IoU and the overlap precision / recall / F."""
    segmented = SEGMENTERS["clutter"].segment(PcdReader(path))
    labels, segments = segmented.frame.labels.astype(int), segmented.labels
    valid = np.isfinite(segmented.frame.points[..., 2])
    objects = sorted({label // 10 for label in np.unique(labels) if label >= 20})
    segment_ids = [s for s in np.unique(segments[valid]) if s > 0]
    shared_total, found, best = 0, 0, []
    for object_id in objects:
        truth = valid & (labels >= 20) & (labels // 10 == object_id)
        overlaps = [np.count_nonzero(truth & (segments == s)) for s in segment_ids]
        segment = segment_ids[int(np.argmax(overlaps))]
        best.append(segment)
        shared_total += max(overlaps)
        found += box_iou(box(truth), box(valid & (segments == segment))) >= 0.5
    assert len(set(best)) == len(best), "two objects share their best segment: the counting above would not hold"
    precision = shared_total / np.count_nonzero(valid & (segments > 0))
    recall = shared_total / np.count_nonzero(valid & (labels >= 20))
    return {
        "objects": len(objects),
        "segments": len(segment_ids),
        "matched": found,
        "overlap_precision": precision,
        "overlap_recall": recall,
        "overlap_f": 2 * precision * recall / (precision + recall),
    }


@pytest.mark.parametrize("scene", ["learn0", "learn17"])
def test_every_object_is_found_also_where_two_boxes_touch(
    capsys: pytest.CaptureFixture[str], learn: Path, scene: str
) -> None:
    path = learn / f"{scene}.pcd"
    status, out, _ = evaluate(capsys, str(path), "--json")
    assert status == 0
    (result,) = json.loads(out)["scenes"]
    expected = expected_figures(path)
    # two boxes, two segments, both found at box IoU >= 0.5
    assert (expected["objects"], expected["segments"], expected["matched"]) == (2, 2, 2)
    assert {key: result[key] for key in ("objects", "segments", "matched")} == {
        "objects": 2,
        "segments": 2,
        "matched": 2,
    }
    assert (result["recall"], result["precision"]) == (1.0, 1.0)
    for key in ("overlap_precision", "overlap_recall", "overlap_f"):
        assert result[key] == pytest.approx(expected[key]), key
    assert result["category"] == {"learn0": "boxes", "learn17": "stacked"}[scene]


def test_the_table_has_scenes_categories_and_overall(capsys: pytest.CaptureFixture[str], learn: Path) -> None:
    status, out, _ = evaluate(capsys, str(learn / "learn0.pcd"), str(learn / "learn17.pcd"))
    assert status == 0
    lines = out.splitlines()
    assert any(line.startswith("learn0 ") and line.rstrip().split()[-2] == "boxes" for line in lines)
    overall = next(line for line in lines if line.startswith("overall")).split()
    assert overall[1:6] == ["4", "4", "4", "1.00", "1.00"]  # objects, segments, found, recall, precision


def test_the_old_segmenter_grown_patches_and_open3d_can_be_scored_too(
    capsys: pytest.CaptureFixture[str], learn: Path
) -> None:
    for name in ("clusters", "clutter-grown", "open3d"):
        status, out, _ = evaluate(capsys, str(learn / "learn0.pcd"), "--segmenter", name, "--json")
        assert status == 0
        document = json.loads(out)
        assert document["segmenter"] == name and document["overall"]["objects"] == 2


def test_paths_that_are_not_labelled_scenes_are_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    status, out, err = evaluate(capsys, str(tmp_path))
    assert (status, out) == (2, "") and "no .pcd file" in err
    unlabelled = require_folder(SHARED_DATA / "pcl_tabletop_pcd") / "table_scene_mug_stereo_textured.pcd"
    status, out, err = evaluate(capsys, str(unlabelled))
    assert (status, out) == (2, "") and "no label field" in err


def test_a_missing_path_is_called_missing(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    status, out, err = evaluate(capsys, str(tmp_path / "learn99.pcd"))
    assert (status, out) == (2, "") and "learn99.pcd: no such file or folder" in err
    (tmp_path / "notes.txt").write_text("not a cloud")
    status, out, err = evaluate(capsys, str(tmp_path / "notes.txt"))
    assert (status, out) == (2, "") and "is not a .pcd file or a folder of them" in err
