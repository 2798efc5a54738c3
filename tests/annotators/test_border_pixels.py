"""Border pixels (annotators.geometry.border_pixels): outline and foot pixels join the segment whose surface they
continue, on rendered tabletops (ground truth per pixel) and on a small synthetic wall."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import range_mask
from annotators.cloud.plane import ransac_support_plane
from annotators.geometry.border_pixels import claim_border_pixels
from tests.annotators.test_clutter import SCENES, best_ious, render


def segment_labels(points: np.ndarray, colors: np.ndarray, claim_borders: bool) -> np.ndarray:
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    plane = ransac_support_plane(points, mask)
    parameters = ClutterParameters(claim_borders=claim_borders)
    labels = np.zeros(points.shape[:2], dtype=np.int32)
    for number, found in enumerate(
        segment_clutter(points, mask, plane.model, plane.inlier_indices, parameters, colors), 1
    ):
        labels[found.mask] = number
    return labels


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_box_mask_covers_more_of_its_box_with_its_border(name: str) -> None:
    points, colors, objects = render(SCENES[name])
    before = best_ious(objects, segment_labels(points, colors, claim_borders=False))
    after = best_ious(objects, segment_labels(points, colors, claim_borders=True))
    assert all(a > b for a, b in zip(after, before, strict=True)), (before, after)
    assert np.mean(after) >= np.mean(before) + 0.005, (before, after)


def wall(depths: np.ndarray) -> np.ndarray:
    """An organized HxWx3 cloud of pinhole pixels (f = 525) at the given HxW depths."""
    rows, cols = np.indices(depths.shape, dtype=np.float32)
    x = (cols - depths.shape[1] / 2) / 525.0 * depths
    y = (rows - depths.shape[0] / 2) / 525.0 * depths
    return np.stack([x, y, depths], axis=-1).astype(np.float32)


def test_an_outline_pixel_joins_the_one_segment_on_its_surface_and_no_other() -> None:
    depths = np.full((40, 60), 1.0, dtype=np.float32)
    depths[:, 52:] = 1.3  # a surface behind, across a depth jump
    points = wall(depths)
    labels = np.zeros((40, 60), dtype=np.int32)
    labels[5:35, 10:30] = 1
    labels[5:35, 31:51] = 2  # column 30 lies between the two segments, column 51 beside segment 2
    heights = np.full((40, 60), 0.1, dtype=np.float32)  # all far above the plane: no foot
    candidates = np.ones((40, 60), dtype=bool)
    parameters = ClutterParameters()
    coarse_normals = np.full((20, 30, 3), np.nan, dtype=np.float32)
    plane = np.array([0.0, -1.0, 0.0, 1.0])
    claimed = claim_border_pixels(
        labels, points, heights, candidates, plane=plane, floor=0.0, coarse_normals=coarse_normals,
        rules=parameters.border_rules(),
    )  # fmt: skip
    assert np.all(claimed[labels > 0] == labels[labels > 0])
    assert np.all(claimed[5:35, 9] == 1)  # the outline left of segment 1
    assert np.all(claimed[5:35, 51] == 2)  # right of segment 2, on its surface
    assert np.all(claimed[5:35, 30] == 0)  # touches both segments: stays between them
    assert np.all(claimed[5:35, 52] == 0)  # across the depth jump
    assert np.count_nonzero(claimed) - np.count_nonzero(labels) == 2 * 30 + 4 * 20  # and the rows above and below
