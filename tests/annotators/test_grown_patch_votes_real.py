"""With grown patches (ClutterParameters(grown_patches=True)) two faces too small to be trusted join on fewer votes
than large faces need only where one is the other's best neighbour (bench/profiles/seg10-analysis.txt).

On uoc frame 2 grown patches cut the Cheez-It box and the drill beside it into a chain of small faces (6-60 points)
that each joined every neighbour on one convex vote, so the box, the drill, the mug, the bowl and the can
in it became one segment; on uoc frame 1 the tall can joined the blue mug the same way.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.point_cloud import back_project, pixel_rays
from annotators.cloud.support_choice import find_support_plane
from annotators.readers.frame_io import read_color_depth_pair

pytestmark = pytest.mark.real_data

APART = {
    2: {"Cheez-It box": (260, 60), "drill": (367, 126), "blue mug": (505, 125)},
    1: {"tall can": (167, 185), "blue mug": (222, 225)},
}
"""Per uoc frame, a pixel (column, row) on each of objects that stand apart."""


def labels(folder: Path, index: int) -> np.ndarray:
    """HxW segment numbers (0 = none) of uoc frame ``index`` segmented with grown patches."""
    frame = read_color_depth_pair(folder, index)
    points = np.ascontiguousarray(back_project(frame.depth, pixel_rays(frame.intrinsics)), dtype=np.float32)
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    fit = find_support_plane(points, mask)
    found = segment_clutter(
        points, mask, fit.model, fit.inlier_indices, ClutterParameters(grown_patches=True), frame.color
    )
    out = np.zeros(points.shape[:2], dtype=np.int32)
    for number, segment in enumerate(found, start=1):
        out[segment.mask & (out == 0)] = number
    return out


@pytest.mark.parametrize("index", sorted(APART))
def test_objects_standing_apart_are_not_chained_into_one_segment(uoc_folder: Path, index: int) -> None:
    found = labels(uoc_folder, index)
    held = {name: int(found[row, col]) for name, (col, row) in APART[index].items()}
    assert all(held.values()), held  # each pixel lies on some segment
    assert len(set(held.values())) == len(held), held


def test_the_drill_stays_one_segment(uoc_folder: Path) -> None:
    found = labels(uoc_folder, 2)
    body, battery = found[126, 367], found[175, 392]  # (row, column) on the drill's body and on its battery
    assert body > 0 and body == battery, (body, battery)
