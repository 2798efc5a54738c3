"""The hand-labelled uoc guard frames (tests/data/labels/guard_objects.json) and the default way the clutter segmenter
is run on them, shared by the tests and bench/score_guards.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.point_cloud import back_project, pixel_rays
from annotators.cloud.support_choice import find_support_plane
from annotators.readers.frame_io import read_color_depth_pair

REPO_ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"
LABELS = REPO_ROOT / "tests" / "data" / "labels" / "guard_objects.json"


def segment_frame(input_name: str, index: int, parameters: ClutterParameters) -> np.ndarray:
    """HxW int32 segment numbers (0 none) of the clutter segmenter on a colour + depth frame, larger ones first."""
    frame = read_color_depth_pair(SHARED_DATA / input_name, index)
    points = np.ascontiguousarray(back_project(frame.depth, pixel_rays(frame.intrinsics)), dtype=np.float32)
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    fit = find_support_plane(points, mask)
    found = segment_clutter(points, mask, fit.model, fit.inlier_indices, parameters, frame.color)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    for number, s in enumerate(sorted(found, key=lambda s: -int(np.count_nonzero(s.mask))), start=1):
        labels[s.mask & (labels == 0)] = number
    return labels
