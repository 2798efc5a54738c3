"""Cost of the border-pixel step of the clutter segmenter (outline and foot pixels given to their objects).

On real 640x480 frames (uoc frame 3, RealSense; mOSD learn0 and learn36, Kinect), after the tabletop front
(reader, range filter, support plane):

1. the step alone (:func:`annotators.geometry.border_pixels.claim_border_pixels` plus :func:`plane_noise`) on the
   whole frame - the segmenter runs it on the objects' bounding box only, so this is an upper bound
   (goal: <= 1.5 ms);
2. :func:`segment_clutter` with and without the step, rounds alternating so machine noise hits both alike.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterParameters, segment_clutter  # noqa: E402
from annotators.cloud.filters import RangeFilter  # noqa: E402
from annotators.cloud.plane import SupportPlaneSegmenter, plane_distances  # noqa: E402
from annotators.cloud.point_cloud import PointCloudGenerator  # noqa: E402
from annotators.geometry.border_pixels import claim_border_pixels, plane_noise  # noqa: E402
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


def median_ms(run: object, runs: int = RUNS) -> float:
    """Median wall time (ms) of ``runs`` calls of ``run``."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        run()  # type: ignore[operator]
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


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

    def step() -> np.ndarray:
        floor = plane_noise(points, model, inliers)
        return claim_border_pixels(labels, points, candidates, plane=model, floor=floor, rules=rules)

    claimed = int(np.count_nonzero(step() > 0) - np.count_nonzero(labels))
    step_ms = median_ms(step)
    with_step, without_step = [], []
    for _ in range(5):
        with_step.append(median_ms(lambda: segment_clutter(points, mask, model, inliers, None, cloud.colors), 3))
        without_step.append(median_ms(lambda: segment_clutter(points, mask, model, inliers, without, cloud.colors), 3))
    on, off = statistics.median(with_step), statistics.median(without_step)
    print(
        f"{name:<14} {mask.shape[1]}x{mask.shape[0]}: {len(segments)} objects, {claimed} pixels claimed; "
        f"step {step_ms:.2f} ms (whole frame); segment_clutter {on:.1f} ms with / {off:.1f} ms without = {on / off:.2f}"
    )
    return step_ms


def main() -> None:
    readers = frames()
    if not readers:
        print(f"bench_border_pixels: no frames under {DATA}; nothing measured")
        return
    worst = max(measure(name, *front(reader)) for name, reader in readers.items())
    verdict = "met" if worst <= STEP_GOAL_MS else "NOT met"
    print(
        f"goal: border step <= {STEP_GOAL_MS} ms on a 640x480 frame: {verdict} (worst {worst:.2f} ms; machine shared)"
    )


if __name__ == "__main__":
    main()
