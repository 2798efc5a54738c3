"""Evidence for seg8 (bench/profiles/seg8-analysis.txt): how much the clutter segmenter depends on the cell phase.

segment_clutter cuts the candidates' surfaces into ``cell`` x ``cell`` coarse-pixel patches counted from the corner
of the candidates' bounding box. This script moves where the cells start and segments again:

1. ``tum``: the blue mug and the saucer beside it on the TUM desk (tabletop tree crop, 0.2-2.5 m) for each of the
   ``cell`` x ``cell`` phases (cells counted from the crop's corner less ``(dy, dx)`` coarse pixels): the segments
   right of column 480 and below row 150, as (roi, points).
2. ``mosd``: the 45 labelled mOSD learn scenes scored per category (recall / precision at box IoU >= 0.5, overlap F,
   as bench/bench_segmentation.py scores them) for each phase; phase (0, 0) is today's segmenter.
3. ``counts``: the number of segments on every real guard input of bench/check_clutter_labels.py (uoc 0-4, the
   pcl_grabber frames) and the rendered 15-object scene, per phase: how often today's count comes out.
4. ``surface``: the same scores when each surface (connected candidates without a depth seam) gets cells of its
   own, counted from its own first row and column less ``margin`` (0 .. cell - 1): a rule in which far candidates
   cannot move an object's cells.
5. ``cluster``: the same scores when each group of surfaces lying within a distance of one another (multiples of the
   grouping's reach) gets cells of its own.

Run from the repository root:
``PYTHONPATH=$PWD python bench/experiments/seg8_phases.py [tum|mosd|counts|surface|cluster]``.
"""

from __future__ import annotations

import argparse
import collections
import sys
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import annotators.cloud.clutter as clutter  # noqa: E402
from annotators.geometry.convexity import dense_labels  # noqa: E402

CELL = clutter.ClutterParameters().cell
FACTORS = (0.0, 0.5, 1.0, 2.0, 4.0, 8.0)
"""The cluster distances tried, in multiples of the grouping's reach (``max(2 cell, grow_distance / stride)``)."""
Patches = Callable[[np.ndarray, int], np.ndarray]


def shifted(dy: int, dx: int) -> Patches:
    """The patches of 78b3ec6 (cells counted from the crop's corner) with the cells starting ``dy`` rows and ``dx``
    columns before the crop's corner."""

    def patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
        rows, cols = np.indices(surfaces.shape)
        across, down = (surfaces.shape[1] + dx) // cell + 1, (surfaces.shape[0] + dy) // cell + 1
        keys = surfaces.astype(np.int64) * across * down + ((rows + dy) // cell) * across + (cols + dx) // cell + 1
        return dense_labels(np.where(surfaces > 0, keys, 0))

    return patches


def per_surface(margin: int) -> Patches:
    """Patches with cells counted from each surface's own first row and column less ``margin``."""

    def patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
        return cells_from_first_pixel(surfaces, surfaces, cell, margin)

    return patches


def cells_from_first_pixel(surfaces: np.ndarray, owners: np.ndarray, cell: int, margin: int) -> np.ndarray:
    """Patches: each surface pixel's cell, counted from the first row and column (less ``margin``) of its owner (a
    label image: the surface itself, or the cluster it lies in)."""
    rows, cols = np.nonzero(surfaces)
    owner = owners[rows, cols].astype(np.int64)
    count = int(owner.max(initial=0)) + 1
    first_row, first_col = np.full(count, surfaces.shape[0]), np.full(count, surfaces.shape[1])
    np.minimum.at(first_row, owner, rows)
    np.minimum.at(first_col, owner, cols)
    labels = surfaces[rows, cols].astype(np.int64)
    across = (surfaces.shape[1] + margin) // cell + 1
    down = (surfaces.shape[0] + margin) // cell + 1
    cell_row = (rows - first_row[owner] + margin) // cell
    cell_col = (cols - first_col[owner] + margin) // cell
    keys = np.zeros(surfaces.shape, dtype=np.int64)
    keys[rows, cols] = labels * across * down + cell_row * across + cell_col + 1
    return dense_labels(keys)


def per_cluster(reach: float, margin: int = 2) -> Patches:
    """Patches with cells counted from the first row and column (less ``margin``) of each cluster of surfaces lying
    within ``reach`` coarse pixels of one another (joined by a dilation of ``reach / 2`` on either side)."""

    def patches(surfaces: np.ndarray, cell: int) -> np.ndarray:
        radius = int(np.ceil(reach / 2))
        disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
        near = cv2.dilate((surfaces > 0).astype(np.uint8), disc)
        clusters = cv2.connectedComponents(near, connectivity=8)[1]
        return cells_from_first_pixel(surfaces, clusters, cell, margin)

    return patches


def tum() -> None:
    """The segments near the blue mug for every phase, and how often each outcome occurs."""
    from annotators.cloud.filters import RangeFilter
    from annotators.cloud.point_cloud import PointCloudGenerator
    from annotators.cloud.support_choice import SupportPlaneSegmenter
    from robokudo.core.engine import Engine
    from robokudo.core.pipeline import Pipeline
    from robokudo.core.types import Plane, PointCloud
    from trees.tabletop import create_reader

    folder = ROOT.parent / "shared" / "data" / "tum_rgbd_sample_open3d"
    steps = [create_reader(str(folder), 0), PointCloudGenerator(), RangeFilter(0.2, 2.5), SupportPlaneSegmenter()]
    root = Pipeline("front", steps)
    Engine(root).tick()
    cloud = root.cas.view(PointCloud)
    plane = max(root.cas.annotations(Plane), key=lambda p: p.inlier_indices.size)
    outcomes: collections.Counter = collections.Counter()
    for dy in range(CELL):
        for dx in range(CELL):
            clutter.grid_patches = shifted(dy, dx)
            found = clutter.segment_clutter(
                cloud.points, cloud.mask, np.asarray(plane.model), np.asarray(plane.inlier_indices),
                clutter.ClutterParameters(), cloud.colors,
            )  # fmt: skip
            near = tuple(sorted((s.roi, int(s.indices.size)) for s in found if s.roi[0] > 480 and s.roi[1] > 150))
            print(f"phase ({dy}, {dx}): {near}", flush=True)
            outcomes[near] += 1
    print("outcomes, most frequent first:")
    for near, count in outcomes.most_common():
        print(f"  {count:2d} x {near}")


def counts() -> None:
    """Per real guard input, the segment count of today's phase and how often each count comes out over the phases."""
    import tempfile

    sys.path.insert(0, str(ROOT / "bench"))
    from check_clutter_labels import prepare

    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        names = [
            name for name in prepare(folder) if not name.startswith("learn") and name != "milk_cartoon_all_small_clorox"
        ]
        for name in names:
            data = np.load(folder / f"{name}.npz")
            found: collections.Counter = collections.Counter()
            for dy in range(CELL):
                for dx in range(CELL):
                    clutter.grid_patches = shifted(dy, dx)
                    segments = clutter.segment_clutter(
                        data["points"], data["mask"], data["model"], data["plane"], clutter.ClutterParameters(),
                        data["colors"],
                    )  # fmt: skip
                    found[len(segments)] += 1
                    if (dy, dx) == (0, 0):
                        today = len(segments)
            print(
                f"{name}: today {today} segments; over {CELL * CELL} phases {dict(sorted(found.items()))}", flush=True
            )


def mosd(variants: dict[str, Patches]) -> None:
    """Per variant, the clutter segmenter's mOSD scores per category."""
    import bench.bench_segmentation as bench
    from trees.segmenters import SEGMENTERS

    bench.SEGMENTERS = {"clutter": SEGMENTERS["clutter"]}
    rows = [*bench.TUNED, *bench.HELD_OUT, "all"]
    print(f"{'variant':<14}" + "".join(f"{row:>22}" for row in rows) + "   (R / P / F)")
    for name, patches in variants.items():
        clutter.grid_patches = patches
        found = bench.scores()["clutter"]
        cells = "".join(
            f"{f'{found[r].recall:.2f}/{found[r].precision:.3f}/{found[r].overlap_f:.4f}':>22}" for r in rows
        )
        print(f"{name:<14}{cells}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("part", choices=("tum", "mosd", "counts", "surface", "cluster"))
    part = parser.parse_args().part
    if part == "tum":
        tum()
    elif part == "mosd":
        mosd({f"phase ({dy}, {dx})": shifted(dy, dx) for dy in range(CELL) for dx in range(CELL)})
    elif part == "counts":
        counts()
    elif part == "surface":
        mosd({f"margin {margin}": per_surface(margin) for margin in range(CELL)})
    else:
        reach = max(2.0 * CELL, clutter.ClutterParameters().grow_distance / clutter.ClutterParameters().stride)
        mosd({f"reach {factor:g}x": per_cluster(factor * reach) for factor in FACTORS})


if __name__ == "__main__":
    main()
