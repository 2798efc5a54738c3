"""Occlusion completion: the pieces of an object that a nearer one cuts apart come out as one hypothesis, and two
objects behind one occluder stay two.

Rendered scenes (ground truth per pixel) and two real held-out mOSD scenes (category "occluded", never used to
choose thresholds): a box lying behind a box standing across it, and a can lying behind a box.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from annotators.readers.frame_readers import PcdReader
from reasoning.evaluation.mosd import object_labels
from reasoning.evaluation.segmentation import score_segmentation
from tests.annotators.conftest import require_folder
from tests.annotators.test_clutter import best_ious, render, segment
from trees.segmenters import segmenter

FRONT = ((0.06, 0.06, 0.2), (-0.03, -0.12, 0.0))  # a tall narrow box in front


def test_a_long_box_behind_an_occluder_is_one_segment() -> None:
    points, colors, objects = render([FRONT, ((0.4, 0.08, 0.08), (-0.2, -0.02, 0.0))])
    labels = segment(points, colors)
    assert int(labels.max()) == 2
    assert min(best_ious(objects, labels)) >= 0.8


def test_two_boxes_of_different_height_behind_an_occluder_stay_apart() -> None:
    # aligned, the same depth, 2 cm apart in height: only the cross-section rule tells them apart (two boxes of one
    # height aligned behind an occluder look exactly like one long box, and are joined)
    left, right = ((0.17, 0.08, 0.08), (-0.2, -0.02, 0.0)), ((0.17, 0.08, 0.10), (0.03, -0.02, 0.0))
    points, colors, objects = render([FRONT, left, right])
    labels = segment(points, colors)
    assert int(labels.max()) == 3
    assert min(best_ious(objects, labels)) >= 0.8


@pytest.mark.real_data
@pytest.mark.parametrize("scene", ["learn28", "learn30"])
def test_an_occluded_object_seen_on_both_sides_is_one_hypothesis(shared_data: Path, scene: str) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    found = segmenter("clutter").segment(PcdReader(path))
    score = score_segmentation(object_labels(found.frame.labels), found.labels, np.isfinite(found.frame.points[..., 2]))
    assert (score.objects, score.segments, score.matched) == (2, 2, 2)
