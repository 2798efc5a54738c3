"""The objects the clutter segmenter finds on the TUM desk should not depend on candidates far away from them.

The segmenter cuts the candidates into cells of ``cell`` x ``cell`` coarse pixels counted from the corner of the
candidates' bounding box, so a candidate appearing or vanishing anywhere above the objects moves every cell
boundary below it. On the TUM desk the blue mug and the saucer with the spoon beside it touch, and where they part
depends on that phase: with the top rows of the board cut off (a metre to their left) the mug's segment changes
(bench/profiles/range4-analysis.txt; range3's cause C, saucers lost once far points are read, is this). Kept as a
strict expected failure until the split no longer depends on where the cells start.
"""

from __future__ import annotations

import numpy as np
import pytest

from annotators.cloud.clusters import Segment
from annotators.cloud.clutter import ClutterParameters, segment_clutter
from annotators.cloud.filters import RangeFilter
from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.cloud.support_choice import SupportPlaneSegmenter
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import Plane, PointCloud
from tests.annotators.conftest import SHARED_DATA, require_folder
from trees.tabletop import create_reader

pytestmark = pytest.mark.real_data

MUG = (543, 215)
"""A pixel (column, row) on the blue mug of the TUM frame."""


@pytest.fixture(scope="module")
def desk() -> tuple[PointCloud, Plane]:
    """The TUM frame as the tabletop tree crops it (0.2-2.5 m) and its support plane."""
    folder = require_folder(SHARED_DATA / "tum_rgbd_sample_open3d")
    steps = [create_reader(str(folder), 0), PointCloudGenerator(), RangeFilter(0.2, 2.5), SupportPlaneSegmenter()]
    root = Pipeline("front", steps)
    Engine(root).tick()
    return root.cas.view(PointCloud), max(root.cas.annotations(Plane), key=lambda p: p.inlier_indices.size)


def segments(
    cloud: PointCloud, plane: Plane, mask: np.ndarray, parameters: ClutterParameters | None = None
) -> list[Segment]:
    """The clutter segments of the masked cloud on the plane."""
    model, inliers = np.asarray(plane.model), np.asarray(plane.inlier_indices)
    return segment_clutter(cloud.points, mask, model, inliers, parameters or ClutterParameters(), cloud.colors)


def mug_pixels(found: list[Segment], width: int) -> set[int]:
    """The flat pixel indices of the segment holding the mug pixel."""
    flat = MUG[1] * width + MUG[0]
    held = [segment for segment in found if flat in set(segment.indices.tolist())]
    assert len(held) == 1, [segment.roi for segment in found]
    return set(held[0].indices.tolist())


GRID = pytest.param(
    ClutterParameters(),
    marks=pytest.mark.xfail(strict=True, reason="cells counted from the candidates' corner (range4-analysis.txt)"),
    id="grid cells",
)
GROWN = pytest.param(ClutterParameters(grown_patches=True), id="grown patches")


@pytest.mark.parametrize("parameters", [GRID, GROWN])
def test_the_mug_does_not_change_when_the_board_top_is_cut_off(
    desk: tuple[PointCloud, Plane], parameters: ClutterParameters
) -> None:
    cloud, plane = desk
    width = cloud.points.shape[1]
    found = segments(cloud, plane, cloud.mask, parameters)
    whole = mug_pixels(found, width)
    top = min(int(segment.indices.min()) // width for segment in found)  # the board's top row
    assert top < MUG[1] - 60, top  # far above the mug
    differing = []
    for cut in range(2, 14, 2):  # one to six coarse rows: every phase of a 6-row cell
        mask = cloud.mask.copy()
        mask[: top + cut] = False
        if mug_pixels(segments(cloud, plane, mask, parameters), width) != whole:
            differing.append(cut)
    assert not differing, f"the mug's pixels change when the top {differing} rows of the candidates are cut off"
