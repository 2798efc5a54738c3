"""The hand-labelled uoc guard frames (tests/data/labels/guard_objects.json) and the default way the clutter segmenter
is run on them and on labelled mOSD scenes, shared by the tests and bench/score_guards.py."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.point_cloud import back_project, pixel_rays
from annotators.cloud.support_choice import PlaneFit, find_support_plane
from annotators.geometry.grid_segmentation import bounding_box
from annotators.readers.frame_io import read_color_depth_pair
from annotators.readers.pcd_io import read_pcd
from reasoning.evaluation.mosd import object_labels
from reasoning.evaluation.segmentation import SegmentationScore, score_segmentation

REPO_ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"
LABELS = REPO_ROOT / "tests" / "data" / "labels" / "guard_objects.json"


def segment_frame(input_name: str, index: int, parameters: ClutterParameters) -> np.ndarray:
    """HxW int32 segment numbers (0 none) of the clutter segmenter on a colour + depth frame, larger ones first."""
    return segment_points(*frame_points(input_name, index), parameters)


def frame_points(input_name: str, index: int) -> tuple[np.ndarray, np.ndarray]:
    """The organized points (float32 HxWx3) and colours of a colour + depth frame of the shared data."""
    frame = read_color_depth_pair(SHARED_DATA / input_name, index)
    points = np.ascontiguousarray(back_project(frame.depth, pixel_rays(frame.intrinsics)), dtype=np.float32)
    return points, frame.color


def segment_mosd_scene(path: Path, parameters: ClutterParameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segment numbers of :func:`segment_frame` on a labelled mOSD scene, its ground-truth object labels and its
    valid (measured) pixels."""
    frame = read_pcd(path)
    points = np.ascontiguousarray(frame.points, dtype=np.float32)
    return segment_points(points, frame.color, parameters), object_labels(frame.labels), np.isfinite(points[..., 2])


def support_plane(points: np.ndarray) -> tuple[np.ndarray, PlaneFit]:
    """The points within the range filter's 0.2-2.5 m (HxW bool) and the supporting plane found among them."""
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    return mask, find_support_plane(points, mask)


def segment_points(points: np.ndarray, colors: np.ndarray, parameters: ClutterParameters) -> np.ndarray:
    """Segment numbers of the clutter segmenter on an organized cloud, larger segments first."""
    mask, fit = support_plane(points)
    found = segment_clutter(points, mask, fit.model, fit.inlier_indices, parameters, colors)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    for number, s in enumerate(sorted(found, key=lambda s: -int(np.count_nonzero(s.mask))), start=1):
        labels[s.mask & (labels == 0)] = number
    return labels


def crop_moved(dy: int, dx: int) -> Callable[[np.ndarray, int], tuple[int, int, int, int]]:
    """A stand-in for the segmenter's ``bounding_box`` whose candidates' box (margin 2) starts ``dy`` rows and ``dx``
    columns (coarse pixels) earlier: the grid cells' phase moves with the crop, grown patches do not."""

    def box(mask: np.ndarray, margin: int = 0) -> tuple[int, int, int, int]:
        x0, y0, x1, y1 = bounding_box(mask, margin)
        if margin == 2:
            x0, y0 = max(0, x0 - dx), max(0, y0 - dy)
        return x0, y0, x1, y1

    return box


def mosd_score_with_cells_moved(
    path: Path, offset: tuple[int, int], monkeypatch: pytest.MonkeyPatch
) -> SegmentationScore:
    """The default segmenter's score on a labelled mOSD scene with its grid cells started ``offset`` (dy, dx) coarse
    pixels earlier (:func:`crop_moved`)."""
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(*offset))
    labels, truth, valid = segment_mosd_scene(path, ClutterParameters())
    return score_segmentation(truth, labels, valid)
