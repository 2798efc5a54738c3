"""The seed's Fig. 2 tabletop tree on a real 640x480 RealSense frame: ms per frame, per annotator and in total.

Three measurements in one run, on frame 000003 of ../shared/data/uoc_tabletop_realsense:

* tree: the Engine ticks ``trees.tabletop`` (reader, cloud, range filter, plane, objects, colour || pose);
  per-annotator times come from each node's RunStats, the total from the engine's tick stats;
* bare: the same functions the annotators call (back-projection, range mask, RANSAC plane, cluster extraction,
  colour naming, oriented boxes) called directly in a loop, without tree or CAS;
* reference: a common Open3D recipe for the same job (5 mm voxel grid, ``segment_plane``, DBSCAN above the plane),
  to put the numbers in context;
* segmentation recall on the labelled mOSD scenes (../shared/data/pcl_mosd_tabletop): the share of ground-truth
  objects matched by a hypothesis with point IoU >= 0.5;
* with ``--reference REV`` (a git revision, e.g. the commit before a change): this checkout's tree and the tree of
  REV (exported with ``git archive``) ticked side by side, each in its own worker process
  (:mod:`bench.tick_tree`), rounds alternating; ms, Hz and the ratio (goal: >= 30 Hz), each annotator's ms side by
  side with the per-expert budgets (:data:`EXPERT_GOALS_MS`), and the clutter segmentation alone on the rendered
  15-object scene of :mod:`bench.bench_segmentation` (goal: <= 40 ms).

Tree and bare rounds alternate so machine noise hits both alike. The reader decodes the PNGs once and then
serves the cached frame (as it does on repeated ticks of the same frame); decoding is reported separately.
"""

from __future__ import annotations

import argparse
import io
import json
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import open3d as o3d

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterParameters, segment_clutter  # noqa: E402
from annotators.cloud.filters import range_mask  # noqa: E402
from annotators.cloud.point_cloud import back_project, pixel_rays  # noqa: E402
from annotators.cloud.pose import PoseAnnotator, hypothesis_points  # noqa: E402
from annotators.cloud.support_choice import find_support_plane  # noqa: E402
from annotators.geometry.boxes import object_box  # noqa: E402
from annotators.image.color import SemanticColorAnnotator, name_color  # noqa: E402
from annotators.image.pixel_expert import hypothesis_pixels  # noqa: E402
from annotators.readers.frame_io import read_color_depth_pair  # noqa: E402
from annotators.readers.frame_readers import PcdReader  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.stats import RunStats  # noqa: E402
from robokudo.core.types import ObjectHypothesis, PointCloud  # noqa: E402
from trees.tabletop import create_pipeline, create_tree  # noqa: E402

DATA = (ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense").resolve()
FRAME = 3
ROUNDS = 10
TICKS_PER_ROUND = 10
REFERENCE_RUNS = 5
COLOR_PIXELS = SemanticColorAnnotator().max_pixels  # the bare loop uses the annotators' own settings
POSE_POINTS = PoseAnnotator().max_points
MOSD = (ROOT.parent / "shared" / "data" / "pcl_mosd_tabletop" / "learn").resolve()
MOSD_SCENES = ("learn0", "learn35")
MIN_IOU = 0.5

STAGES = (
    "PointCloudGenerator",
    "RangeFilter",
    "SupportPlaneSegmenter",
    "ClutterSegmenter",
    "SemanticColorAnnotator",
    "PoseAnnotator",
)


def bare_frame(frame, rays, timings: dict[str, list[float]]) -> int:
    """One frame through the annotators' functions without tree or CAS; returns the number of clusters."""

    def timed(stage: str, work: Callable[[], object]) -> object:
        start = time.perf_counter()
        result = work()
        timings[stage].append(time.perf_counter() - start)
        return result

    points = timed("PointCloudGenerator", lambda: back_project(frame.depth, rays))
    valid = np.isfinite(points[..., 2])
    mask = timed("RangeFilter", lambda: range_mask(points, valid, 0.2, 2.5))
    fit = timed("SupportPlaneSegmenter", lambda: find_support_plane(points, mask))
    segments = timed(
        "ClutterSegmenter",
        lambda: segment_clutter(points, mask, fit.model, fit.inlier_indices, ClutterParameters(), frame.color),
    )
    hypotheses = [ObjectHypothesis(point_indices=s.indices, mask=s.mask, roi=s.roi) for s in segments]
    cloud = PointCloud(points=points, mask=mask, colors=frame.color)
    timed(
        "SemanticColorAnnotator",
        lambda: [name_color(hypothesis_pixels(frame.color, h, COLOR_PIXELS)) for h in hypotheses],
    )
    timed("PoseAnnotator", lambda: [object_box(hypothesis_points(cloud, h, POSE_POINTS), None) for h in hypotheses])
    return len(segments)


def reference_open3d(frame) -> float:
    """Seconds for voxel grid + RANSAC plane + DBSCAN of the points above it, with Open3D."""
    k = frame.intrinsics
    start = time.perf_counter()
    depth = o3d.geometry.Image(frame.depth)
    intrinsic = o3d.camera.PinholeCameraIntrinsic(k.width, k.height, k.fx, k.fy, k.cx, k.cy)
    cloud = o3d.geometry.PointCloud.create_from_depth_image(depth, intrinsic, depth_scale=1.0, depth_trunc=2.5)
    cloud = cloud.voxel_down_sample(0.005)
    model, inliers = cloud.segment_plane(0.01, 3, 200)
    rest = cloud.select_by_index(inliers, invert=True)
    heights = np.asarray(rest.points) @ np.asarray(model[:3]) + model[3]
    above = rest.select_by_index(np.flatnonzero(np.abs(heights) > 0.01).tolist())
    np.asarray(above.cluster_dbscan(eps=0.015, min_points=10))
    return time.perf_counter() - start


def mosd_recall(scene: str) -> tuple[int, int, list[float], float]:
    """Objects matched (IoU >= MIN_IOU), objects, each object's best IoU and the tree's ms on a labelled mOSD scene."""
    reader = PcdReader(MOSD / f"{scene}.pcd")
    root = create_pipeline(reader)
    engine = Engine(root, hz=1000.0)
    engine.tick()
    times = []
    for _ in range(5):
        start = time.perf_counter()
        engine.tick()
        times.append(time.perf_counter() - start)
    frame = reader.last_frame
    labels, valid = frame.labels, np.isfinite(frame.points[..., 2])
    hypotheses = root.cas.annotations(ObjectHypothesis)
    ious = []
    for object_id in sorted({int(label) // 10 for label in np.unique(labels) if label >= 20}):
        truth = (labels >= 20) & (labels // 10 == object_id) & valid
        ious.append(
            max((np.count_nonzero(h.mask & truth) / np.count_nonzero(h.mask | truth) for h in hypotheses), default=0)
        )
    return sum(iou >= MIN_IOU for iou in ious), len(ious), ious, statistics.median(times) * 1e3


SEGMENTATION_GOAL_MS = 40.0
"""Goal for the clutter segmentation alone on the rendered 15-object scene (ms)."""


def side_by_side(reference: str, rounds: int = 8, ticks: int = 10, segment_runs: int = 5) -> None:
    """This checkout's tree vs the tree of git revision ``reference`` on the same frame, rounds alternating: whole
    tree and per annotator; then the clutter segmentation alone on the rendered 15-object scene, likewise."""
    from bench.bench_segmentation import fifteen_objects

    with tempfile.TemporaryDirectory() as folder:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", reference], check=True, capture_output=True)
        tree_folder = Path(folder) / "reference"
        tree_folder.mkdir()
        with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
            tar.extractall(tree_folder, filter="data")
        scene = Path(folder) / "fifteen_objects.npz"
        points, colors = fifteen_objects()
        np.savez(scene, points=points, colors=colors)
        checkouts = {"this checkout": str(ROOT), f"reference {reference}": str(tree_folder)}
        workers = {
            name: subprocess.Popen(
                [sys.executable, str(ROOT / "bench" / "tick_tree.py"), path, str(DATA), str(FRAME), str(scene)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
            )
            for name, path in checkouts.items()
        }
        for worker in workers.values():
            if worker.stdout is None or worker.stdout.readline().strip() != "ready":
                raise RuntimeError("a tree worker did not start")

        def ask(worker: subprocess.Popen, line: str) -> dict:
            assert worker.stdin is not None and worker.stdout is not None
            worker.stdin.write(line + "\n")
            worker.stdin.flush()
            return json.loads(worker.stdout.readline())

        wall: dict[str, list[float]] = {name: [] for name in workers}
        cpu: dict[str, list[float]] = {name: [] for name in workers}
        experts: dict[str, dict[str, list[float]]] = {name: {} for name in workers}
        segment_wall: dict[str, list[float]] = {name: [] for name in workers}
        segment_cpu: dict[str, list[float]] = {name: [] for name in workers}
        found: dict[str, int] = {}
        segments: dict[str, int] = {}
        for _ in range(rounds):
            for name, worker in workers.items():
                answer = ask(worker, str(ticks))
                wall[name] += answer["wall"]
                cpu[name] += answer["cpu"]
                for expert, seconds in answer["experts"].items():
                    experts[name].setdefault(expert, []).extend(seconds)
                found[name] = answer["hypotheses"]
            for name, worker in workers.items():
                answer = ask(worker, f"segment {segment_runs}")
                segment_wall[name] += answer["wall"]
                segment_cpu[name] += answer["cpu"]
                segments[name] = answer["segments"]
        for worker in workers.values():
            assert worker.stdin is not None
            worker.stdin.close()
            worker.wait()
    ours_name, theirs_name = "this checkout", f"reference {reference}"
    print(f"\nside by side on {DATA.name}/{FRAME:06d}, {rounds} alternating rounds of {ticks} ticks, median per tick:")
    ms = {name: statistics.median(values) * 1e3 for name, values in wall.items()}
    cpu_ms = {name: statistics.median(values) * 1e3 for name, values in cpu.items()}
    for name in workers:
        print(
            f"  {name:28s} {ms[name]:7.1f} ms = {1e3 / ms[name]:5.1f} Hz  ({cpu_ms[name]:.1f} ms CPU)"
            f"  {found[name]} hypotheses"
        )
    ours, theirs = ms[ours_name], ms[theirs_name]
    ours_cpu, theirs_cpu = cpu_ms[ours_name], cpu_ms[theirs_name]
    print(f"  speed-up over the reference: {theirs / ours:.2f}x wall, {theirs_cpu / ours_cpu:.2f}x CPU")
    print(f"  goal >= 30 Hz: {'met' if 1e3 / ours >= 30 else 'NOT met'} ({1e3 / ours:.1f} Hz on this machine now)")
    print_expert_table(experts[ours_name], experts[theirs_name], reference)
    seg_ms = {name: statistics.median(values) * 1e3 for name, values in segment_wall.items()}
    seg_cpu = {name: statistics.median(values) * 1e3 for name, values in segment_cpu.items()}
    print(
        f"\nclutter segmentation alone on the rendered 15-object scene, {rounds} alternating rounds of {segment_runs}:"
    )
    for name in workers:
        print(f"  {name:28s} {seg_ms[name]:7.1f} ms ({seg_cpu[name]:.1f} ms CPU)  {segments[name]} segments")
    mine = seg_ms[ours_name]
    cpu_ratio = seg_cpu[theirs_name] / seg_cpu[ours_name]
    print(f"  speed-up over the reference: {seg_ms[theirs_name] / mine:.2f}x wall, {cpu_ratio:.2f}x CPU")
    verdict = "met" if mine <= SEGMENTATION_GOAL_MS else "NOT met"
    print(f"  goal <= {SEGMENTATION_GOAL_MS:.0f} ms: {verdict} ({mine:.1f} ms on this machine now)")


EXPERT_GOALS_MS = {"SemanticColorAnnotator": 8.0, "PoseAnnotator": 3.0}
"""Per-expert budgets (ms per frame) within the 30 Hz goal; the experts other than these and the segmentation
(support plane, clutter) share OTHERS_GOAL_MS."""
SEGMENTATION = ("SupportPlaneSegmenter", "ClutterSegmenter")
OTHERS_GOAL_MS = 5.0


def print_expert_table(ours: dict[str, list[float]], theirs: dict[str, list[float]], reference: str) -> None:
    """Median ms per run of every annotator in both trees, side by side, the reference's / ours ratio, and the
    per-expert budgets met or not."""
    print(f"  {'annotator (median ms per run)':30s} {'ours':>8s} {reference[:10]:>10s} {'speed-up':>9s}")
    mine: dict[str, float] = {}
    for node in [*ours, *(node for node in theirs if node not in ours)]:
        mine[node] = statistics.median(ours[node]) * 1e3 if ours.get(node) else float("nan")
        other = statistics.median(theirs[node]) * 1e3 if theirs.get(node) else float("nan")
        print(f"  {node:30s} {mine[node]:8.2f} {other:10.2f} {other / mine[node]:8.2f}x")
    for node, goal in EXPERT_GOALS_MS.items():
        if node in mine:
            verdict = "met" if mine[node] <= goal else "NOT met"
            print(f"  goal {node} <= {goal:.0f} ms: {verdict} ({mine[node]:.1f} ms)")
    others = sum(ms for node, ms in mine.items() if node not in EXPERT_GOALS_MS and node not in SEGMENTATION)
    print(
        f"  goal other experts <= {OTHERS_GOAL_MS:.0f} ms summed: {'met' if others <= OTHERS_GOAL_MS else 'NOT met'}"
        f" ({others:.1f} ms)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--reference", help="git revision whose tree is timed side by side with this checkout's")
    parser.add_argument("--only-side-by-side", action="store_true", help="with --reference: skip the other parts")
    arguments = parser.parse_args()
    if not DATA.is_dir():
        print(f"bench_tabletop: no data at {DATA}; skipped")
        return
    if arguments.reference and arguments.only_side_by_side:
        side_by_side(arguments.reference)
        return
    o3d.utility.random.seed(0)
    start = time.perf_counter()
    frame = read_color_depth_pair(DATA, FRAME)
    decode_ms = (time.perf_counter() - start) * 1e3
    rays = pixel_rays(frame.intrinsics)

    root = create_tree(str(DATA), FRAME)
    engine = Engine(root, hz=1000.0)
    for _ in range(3):  # warm-up: decode, caches, first-call costs
        engine.tick()
        bare_frame(frame, rays, {stage: [] for stage in STAGES})
    nodes = engine.annotator_stats()
    for node in root.iterate():
        if hasattr(node, "stats"):
            node.stats = RunStats()
    engine.tick_stats = RunStats()

    bare: dict[str, list[float]] = {stage: [] for stage in STAGES}
    bare_totals: list[float] = []
    clusters = 0
    for _ in range(ROUNDS):
        for _ in range(TICKS_PER_ROUND):
            engine.tick()
        for _ in range(TICKS_PER_ROUND):
            begin = time.perf_counter()
            clusters = bare_frame(frame, rays, bare)
            bare_totals.append(time.perf_counter() - begin)
    nodes = engine.annotator_stats()
    reference = statistics.median(reference_open3d(frame) for _ in range(REFERENCE_RUNS))

    print(f"tabletop tree on {DATA.name}/{FRAME:06d} (640x480), {ROUNDS * TICKS_PER_ROUND} frames each, median ms")
    print(f"(PNG decode, once per frame file: {decode_ms:.1f} ms; the reader then serves the cached frame)")
    header = f"{'annotator':24s} {'tree ms':>9s} {'bare ms':>9s} {'ratio':>7s}"
    print(header)
    print("-" * len(header))
    reader = next(name for name in nodes if name.endswith("Reader"))
    print(f"{reader:24s} {nodes[reader].median_seconds * 1e3:9.2f} {'-':>9s} {'-':>7s}")
    for stage in STAGES:
        tree_ms = nodes[stage].median_seconds * 1e3
        bare_ms = statistics.median(bare[stage]) * 1e3
        print(f"{stage:24s} {tree_ms:9.2f} {bare_ms:9.2f} {tree_ms / bare_ms:7.2f}")
    tree_total = engine.tick_stats.median_seconds * 1e3
    bare_total = statistics.median(bare_totals) * 1e3
    print("-" * len(header))
    print(f"{'total per frame':24s} {tree_total:9.2f} {bare_total:9.2f} {tree_total / bare_total:7.2f}")
    print(f"{'frames per second':24s} {1e3 / tree_total:9.1f} {1e3 / bare_total:9.1f}")
    print(f"hypotheses per frame: {clusters}; goal: >= 30 Hz, i.e. <= 33.3 ms per frame")
    print(f"reference, Open3D voxel 5 mm + segment_plane + DBSCAN (no colour, no pose): {reference * 1e3:.1f} ms")
    if MOSD.is_dir():
        print(f"\nsegmentation recall on mOSD (object matched when a hypothesis has point IoU >= {MIN_IOU}):")
        for scene in MOSD_SCENES:
            found, total, ious, ms = mosd_recall(scene)
            listed = ", ".join(f"{iou:.2f}" for iou in ious)
            recall = f"recall {found}/{total} = {found / total:.2f}"
            print(f"  {scene:8s} {recall}   IoU per object: {listed}   tree {ms:.1f} ms")
    if arguments.reference:
        side_by_side(arguments.reference)


if __name__ == "__main__":
    main()
