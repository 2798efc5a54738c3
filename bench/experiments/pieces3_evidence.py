"""Evidence for the two objects that still come out in pieces on the shared uoc frames (pieces3-analysis.txt).

1. The upright drill (frames 0 and 1) beside the soup can standing on the spam can (frames 2 and 3): the pieces
   the grouping and merging leave before any joining step (ClutterSegmenter with the joins switched off), each with
   its 5 % / 95 % heights above the table and the share of its footprint inside the other's convex hull on the
   table - the cues the joining steps read.
2. The clear water bottle (frame 3): per image row of its blue pixels, the share of depth readings more than 3 cm
   behind the row's front surface (5 % depth), and the bottle's pixels that read the table or nothing.

Run from the repository root: ``PYTHONPATH=$PWD python bench/experiments/pieces3_evidence.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
from py_trees.common import Status

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterSegmenter  # noqa: E402
from annotators.cloud.plane import plane_basis  # noqa: E402
from annotators.geometry.support import held_share  # noqa: E402
from annotators.readers.choice import reader_for  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.types import ColorImage, ObjectHypothesis, Plane, PointCloud  # noqa: E402
from trees.tabletop import create_pipeline  # noqa: E402

FOLDER = ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense"
NO_JOINS = {
    name: False
    for name in (
        "complete_occluded", "join_unsupported", "join_appendages", "join_jointly_held", "join_inner_walls",
        "join_rims", "join_slabs", "claim_floors",
    )
}  # fmt: skip
PAIRS = {  # frame: (upper piece's pixel, lower piece's pixel, what they are)
    0: ((345, 140), (360, 200), "drill body+grip / battery"),
    1: ((380, 150), (390, 220), "drill body / grip+battery"),
    2: ((150, 180), (150, 260), "soup can / spam can"),
    3: ((150, 170), (150, 260), "soup can / spam can"),
}
FOOTPRINT_CELL = 0.005  # metres: the raster cell the support rules measure footprints on


def run(frame: int, joins: bool) -> tuple[list[ObjectHypothesis], np.ndarray, np.ndarray, np.ndarray]:
    """The hypotheses of one frame, the organized points, the plane model and the colour image."""
    segmenter = ClutterSegmenter() if joins else ClutterSegmenter(**NO_JOINS)
    root = create_pipeline(reader_for(str(FOLDER), frame), segmenter)
    if Engine(root).tick() is not Status.SUCCESS:
        raise RuntimeError(f"frame {frame}: the tabletop tree failed")
    (plane,) = root.cas.annotations(Plane)
    points = root.cas.view(PointCloud).points
    return root.cas.annotations(ObjectHypothesis), points, np.asarray(plane.model), root.cas.view(ColorImage).image


def label_image(hypotheses: list[ObjectHypothesis]) -> np.ndarray:
    """Each pixel's hypothesis number (1-based), 0 for none."""
    labels = np.zeros(hypotheses[0].mask.shape, dtype=np.int64)
    for number, hypothesis in enumerate(hypotheses, start=1):
        labels[hypothesis.mask] = number
    return labels


def footprint_hull(points: np.ndarray, model: np.ndarray) -> np.ndarray:
    """The convex hull (Kx2, float32) of the points projected onto the plane."""
    uv = (points @ plane_basis(model[:3]).T).astype(np.float32)
    return cv2.convexHull(uv).reshape(-1, 2)


def report_pairs() -> None:
    """Heights and footprint shares of the upper and lower piece of each pair, before any joining step."""
    print("pieces before the joining steps (heights above the table, 5 % / 95 %; footprint inside the other's hull)")
    for frame, (upper, lower, what) in PAIRS.items():
        hypotheses, points, model, _ = run(frame, joins=False)
        labels = label_image(hypotheses)
        heights = points @ model[:3] + model[3]
        first, second = labels[upper[1], upper[0]], labels[lower[1], lower[0]]
        if first == second:
            print(f"  frame {frame} ({what}): one piece already (the heights nest: merged as a handle would be)")
            continue
        rows = []
        for label in (first, second):
            mask = (labels == label) & np.isfinite(heights)
            low, high = np.percentile(heights[mask], [5, 95])
            rows.append((low, high, footprint_hull(points[mask], model)))
        inside_lower = held_share(rows[0][2], rows[1][2], FOOTPRINT_CELL)
        inside_upper = held_share(rows[1][2], rows[0][2], FOOTPRINT_CELL)
        print(
            f"  frame {frame} ({what}): upper {rows[0][0]:.3f}-{rows[0][1]:.3f} m, lower {rows[1][0]:.3f}-"
            f"{rows[1][1]:.3f} m; upper inside lower's hull {inside_lower:.2f}, lower inside upper's {inside_upper:.2f}"
        )


def report_bottle() -> None:
    """How the clear bottle in frame 3 reads in depth, and the hypotheses its pixels fall in."""
    hypotheses, points, model, image = run(3, joins=True)
    labels = label_image(hypotheses)
    heights = points @ model[:3] + model[3]
    valid = np.isfinite(heights)
    rgb = image.astype(np.int64)
    rows, columns = np.mgrid[0 : labels.shape[0], 0 : labels.shape[1]]
    # the bottle: its blue pixels right of the blue mug, above the white bowl
    bottle = (rgb[..., 2] > rgb[..., 0] + 40) & (rgb[..., 2] > rgb[..., 1] + 10)
    bottle &= (columns >= 530) & (columns < 600) & (rows >= 20) & (rows < 225)
    print(
        f"clear bottle, frame 3: {np.count_nonzero(bottle)} pixels, {np.mean(~valid[bottle]):.2f} without depth, "
        f"{np.mean(heights[bottle & valid] < 0.01):.2f} of the rest on the table (< 1 cm)"
    )
    for row in range(30, 220, 20):
        depth = points[row, :, 2][bottle[row] & valid[row]]
        if depth.size < 5:
            continue
        front = np.percentile(depth, 5)
        print(
            f"  row {row}: front {front:.3f} m, {np.mean(depth > front + 0.03):.2f} read > 3 cm behind it "
            f"(median {np.median(depth - front) * 100:.1f} cm)"
        )
    numbers, counts = np.unique(labels[bottle & valid], return_counts=True)
    for number, count in zip(numbers.tolist(), counts.tolist(), strict=True):
        if number and count >= 100:
            mask = bottle & valid & (labels == number)
            print(
                f"  hypothesis {number}: {count} bottle pixels, depth {np.median(points[..., 2][mask]):.3f} m, "
                f"heights {np.percentile(heights[mask], 5):.3f}-{np.percentile(heights[mask], 95):.3f} m"
            )


if __name__ == "__main__":
    report_pairs()
    report_bottle()
