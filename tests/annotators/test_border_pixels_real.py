"""Border pixels on real mOSD scenes (../shared/data/pcl_mosd_tabletop/learn, labelled Kinect frames): the outline
and foot pixels the clutter segmenter's coarse grid and height cut leave unlabelled are given to their object.

learn0 (two stacked cereal boxes) is from the categories the segmenter was tuned on; learn30 (occluded objects) and
learn36 (a bowl, a tub and a tin) are held out. On each, the masks with the step are compared with the masks the
same segmenter gives without it: the overlap F-measure of the masks rises, the pixels added belong to the object
they were given to, the same objects are found, and their point indices (what the 3-D experts measure) stay the
same.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.cloud.clutter import ClutterSegmenter
from annotators.cloud.filters import RangeFilter
from annotators.cloud.support_choice import SupportPlaneSegmenter
from annotators.readers.frame_readers import PcdReader
from reasoning.evaluation.mosd import object_labels
from reasoning.evaluation.segmentation import score_segmentation
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import ObjectHypothesis
from tests.annotators.conftest import require_folder
from trees.segmenters import hypothesis_labels

pytestmark = pytest.mark.real_data

MIN_RISE = 0.005
"""The least rise of the overlap F-measure the border pixels must bring: half a percent (the outline the coarse grid
loses is about 1 % of a mask, the foot below the candidates' lowest height 2 %)."""


def segment(path: Path, claim_borders: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[np.ndarray]]:
    """Segment labels (of the masks), ground-truth object labels, measured pixels and the hypotheses' point indices
    (sorted, largest hypothesis first) of one labelled scene."""
    reader = PcdReader(path)
    segmenter = ClutterSegmenter(claim_borders=claim_borders)
    root = Pipeline("border", [reader, RangeFilter(min_depth=0.2, max_depth=2.5), SupportPlaneSegmenter(), segmenter])
    assert Engine(root).tick() is Status.SUCCESS
    frame = reader.last_frame
    hypotheses = root.cas.annotations(ObjectHypothesis)
    labels = hypothesis_labels(hypotheses, frame.depth.shape)
    indices = [np.sort(h.point_indices) for h in sorted(hypotheses, key=lambda h: -h.point_indices.size)]
    return labels, object_labels(frame.labels), np.isfinite(frame.points[..., 2]), indices


@pytest.mark.parametrize("scene", ["learn0", "learn30", "learn36"])
def test_border_pixels_join_their_object_and_raise_the_mask_f_measure(shared_data: Path, scene: str) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    before, truth, measured, points_before = segment(path, claim_borders=False)
    after, _, _, points_after = segment(path, claim_borders=True)

    # the same objects, each mask only grown
    assert after.max() == before.max()
    assert np.all(after[before > 0] == before[before > 0])
    added = (after > 0) & (before == 0)
    assert np.count_nonzero(added) >= 200

    # the pixels added are the object's: most carry the ground-truth label of the object the segment found
    owner = {int(s): np.bincount(truth[before == s]).argmax() for s in range(1, int(before.max()) + 1)}
    right = sum(np.count_nonzero(added & (after == s) & (truth == o)) for s, o in owner.items())
    assert right >= 0.9 * np.count_nonzero(added), (right, np.count_nonzero(added))

    score_before = score_segmentation(truth, before, measured)
    score_after = score_segmentation(truth, after, measured)
    assert score_after.overlap_f >= score_before.overlap_f + MIN_RISE, (score_before, score_after)
    assert score_after.overlap_recall > score_before.overlap_recall
    assert score_after.matched == score_before.matched == score_after.objects
    # the 3-D experts measure the same points: the border joins the masks only
    assert len(points_after) == len(points_before)
    assert all(np.array_equal(a, b) for a, b in zip(points_after, points_before, strict=True))
