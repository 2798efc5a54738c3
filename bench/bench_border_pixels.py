"""Cost of the border-pixel step of the clutter segmenter (outline and foot pixels given to their objects).

On real 640x480 frames (uoc frame 3, RealSense; mOSD learn0 and learn36, Kinect), after the tabletop front
(reader, range filter, support plane):

1. the step alone (:func:`annotators.geometry.border_pixels.claim_border_pixels` plus :func:`plane_noise`) on the
   region the segmenter runs it on (the bounding box of the candidates standing on the plane; goal: <= 1.5 ms) and
   on the whole frame (an upper bound), median wall and CPU time of the process (less swayed by other jobs);
2. :func:`segment_clutter` with and without the step, rounds alternating so machine noise hits both alike.
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clusters import standing_region  # noqa: E402
from annotators.cloud.clutter import ClutterParameters, segment_clutter  # noqa: E402
from annotators.cloud.filters import RangeFilter  # noqa: E402
from annotators.cloud.normals import grid_normals  # noqa: E402
from annotators.cloud.plane import plane_distances  # noqa: E402
from annotators.cloud.point_cloud import PointCloudGenerator  # noqa: E402
from annotators.cloud.support_choice import SupportPlaneSegmenter  # noqa: E402
from annotators.geometry.border_pixels import claim_border_pixels, plane_noise  # noqa: E402
from annotators.geometry.grid_segmentation import bounding_box  # noqa: E402
from annotators.readers.choice import reader_for  # noqa: E402
from annotators.readers.frame_readers import PcdReader  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline  # noqa: E402
from robokudo.core.types import Plane, PointCloud  # noqa: E402

DATA = (ROOT.parent / "shared" / "data").resolve()
RUNS = 30
STEP_GOAL_MS = 1.5
"""Goal for the border step alone on a 640x480 frame (ms)."""


def frames() -> dict[str, Annotator]:
    """The readers of the frames measured, by name (those whose data is present)."""
    found: dict[str, Annotator] = {}
    uoc = DATA / "uoc_tabletop_realsense"
    if uoc.is_dir():
        found["uoc frame 3"] = reader_for(str(uoc), 3)
    for scene in ("learn0", "learn36"):
        path = DATA / "pcl_mosd_tabletop" / "learn" / f"{scene}.pcd"
        if path.is_file():
            found[f"mOSD {scene}"] = PcdReader(path)
    return found


def front(reader: Annotator) -> tuple[PointCloud, Plane]:
    """The cloud and the supporting plane of the reader's frame, as the tabletop tree finds them."""
    cloud = [] if PointCloud in reader.outputs else [PointCloudGenerator()]
    steps = [reader, *cloud, RangeFilter(min_depth=0.2, max_depth=2.5), SupportPlaneSegmenter()]
    root = Pipeline("front", steps)
    Engine(root).tick()
    (plane,) = root.cas.annotations(Plane)
    return root.cas.view(PointCloud), plane


def median_ms(run: Callable[[], object], runs: int = RUNS) -> tuple[float, float]:
    """Median wall and CPU time (ms) of ``runs`` calls of ``run``."""
    wall, cpu = [], []
    for _ in range(runs):
        start, start_cpu = time.perf_counter(), time.process_time()
        run()
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return statistics.median(wall) * 1e3, statistics.median(cpu) * 1e3


def measure(name: str, cloud: PointCloud, plane: Plane) -> float:
    """Print the step's cost and the segmenter's with and without it on one frame; return the step's ms."""
    points, mask, model, inliers = cloud.points, cloud.mask, plane.model, plane.inlier_indices
    without = ClutterParameters(claim_borders=False)
    segments = segment_clutter(points, mask, model, inliers, without, cloud.colors)
    labels = np.zeros(mask.shape, dtype=np.int32)
    for number, segment in enumerate(segments, start=1):
        labels[segment.mask] = number
    heights = plane_distances(points, model)
    with np.errstate(invalid="ignore"):
        candidates = mask & (heights > without.min_height) & (heights < without.max_height)
    rules = without.border_rules()
    # the region segment_clutter hands the step: the candidates' bounding box on the stride grid, at full resolution
    step = max(1, without.stride)
    x0, y0, x1, y1 = bounding_box(standing_region(points, mask, model, inliers, without), margin=2)
    windows = {}
    for window, (top, left, bottom, right) in (("region", (y0, x0, y1, x1)), ("whole frame", (0, 0, None, None))):
        fine = (slice(top * step, bottom and bottom * step), slice(left * step, right and right * step))
        coarse = np.ascontiguousarray(points[::step, ::step][top:bottom, left:right])
        normals = grid_normals(
            coarse, without.normal_step, without.normal_smoothing, rules.jump_absolute, rules.jump_relative
        )
        windows[window] = (labels[fine], np.ascontiguousarray(points[fine]), heights[fine], candidates[fine], normals)
    claimed = 0
    costs = {}
    for window, (window_labels, window_points, window_heights, window_candidates, normals) in windows.items():

        def border_step(
            labels: np.ndarray = window_labels,
            cloud: np.ndarray = window_points,
            above: np.ndarray = window_heights,
            where: np.ndarray = window_candidates,
            normals: np.ndarray = normals,
        ) -> np.ndarray:
            floor = plane_noise(points, model, inliers)  # on the whole frame, as segment_clutter measures it
            return claim_border_pixels(
                labels, cloud, above, where, plane=model, floor=floor, coarse_normals=normals, rules=rules
            )

        claimed = int(np.count_nonzero(border_step() > 0) - np.count_nonzero(window_labels))
        costs[window] = median_ms(border_step)
    with_step, without_step = [], []
    for _ in range(5):
        with_step.append(median_ms(lambda: segment_clutter(points, mask, model, inliers, None, cloud.colors), 3)[1])
        without_step.append(
            median_ms(lambda: segment_clutter(points, mask, model, inliers, without, cloud.colors), 3)[1]
        )
    on, off = statistics.median(with_step), statistics.median(without_step)
    (region_wall, region_cpu), (frame_wall, frame_cpu) = costs["region"], costs["whole frame"]
    shape = windows["region"][0].shape
    print(
        f"{name:<14} {len(segments)} objects, {claimed} pixels claimed; step on its region {shape[1]}x{shape[0]} "
        f"{region_cpu:.2f} ms CPU ({region_wall:.2f} wall), on the whole 640x480 frame {frame_cpu:.2f} ms CPU "
        f"({frame_wall:.2f} wall); segment_clutter CPU {on:.1f} ms with / {off:.1f} ms without = {on / off:.2f}"
    )
    return region_cpu


def main() -> None:
    readers = frames()
    if not readers:
        print(f"bench_border_pixels: no frames under {DATA}; nothing measured")
        return
    worst = max(measure(name, *front(reader)) for name, reader in readers.items())
    verdict = "met" if worst <= STEP_GOAL_MS else "NOT met"
    print(
        f"goal: border step <= {STEP_GOAL_MS} ms CPU on a 640x480 frame (on the region the segmenter gives it): "
        f"{verdict} (worst {worst:.2f} ms; load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"
    )


if __name__ == "__main__":
    main()
