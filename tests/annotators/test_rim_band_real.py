"""The top of a bowl's outer wall, cut off from the rest, rejoins the bowl's inside up to the rim
(annotators/geometry/grid_segmentation.py, RIM_BAND).

On mOSD learn35 grown patches (``ClutterParameters(grown_patches=True)``) cut the white bowl's outer wall below 5 cm
from its top. The top piece reaches the rim at 8.9 cm, above the inside's 95 % height (few points lie on the rim),
and spans more than half the inside's heights, so it was not in the rim band and its heights did not nest: the bowl
came out as two objects. A piece starting in the upper half of another's heights now counts as in the band too.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.support_choice import find_support_plane
from annotators.readers.pcd_io import read_pcd
from reasoning.evaluation.mosd import object_labels
from reasoning.evaluation.segmentation import score_segmentation
from tests.annotators.conftest import require_folder

pytestmark = pytest.mark.real_data


def segment_labels(path: Path, parameters: ClutterParameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The clutter segments of a labelled mOSD scene (larger first), its ground-truth objects and valid pixels."""
    frame = read_pcd(path)
    points = np.ascontiguousarray(frame.points, dtype=np.float32)
    valid = np.isfinite(points[..., 2])
    mask = range_mask(points, valid, 0.2, 2.5)
    fit = find_support_plane(points, mask)
    found = segment_clutter(points, mask, fit.model, fit.inlier_indices, parameters, frame.color)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    for number, s in enumerate(sorted(found, key=lambda s: -int(np.count_nonzero(s.mask))), start=1):
        labels[s.mask & (labels == 0)] = number
    return labels, object_labels(frame.labels), valid


@pytest.mark.parametrize("grown", [False, True], ids=["grid", "grown patches"])
def test_the_white_bowl_is_one_object_with_the_top_of_its_outer_wall(shared_data: Path, grown: bool) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / "learn35.pcd"
    labels, truth, valid = segment_labels(path, replace(ClutterParameters(), grown_patches=grown))
    score = score_segmentation(truth, labels, valid)
    assert (score.recall, score.precision) == (1.0, 1.0)
