"""The object experts on real 640x480 frames: ms per run (and per hypothesis) of each new annotator.

On frame 000003 of ../shared/data/uoc_tabletop_realsense the tabletop tree makes the hypotheses once; then each
expert runs repeatedly on that CAS inside a Pipeline (so the numbers include the framework's share): normals,
shape, size, colour histogram, knowledge classifier, OCR (one pass per frame; bench_text.py compares it with
per-hypothesis crops), the ONNX detector with a tiny generated model (pre-processing, inference and decoding,
not a real network's cost) and the colour-only region segmenter.
The region filter needs a camera pose, which the recorded frames lack, so it runs on the built-in kitchen's
640x480 "table" view with the semantic map's table box.
"""

from __future__ import annotations

import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from py_trees.common import Status  # noqa: E402

from annotators import kitchen_scene  # noqa: E402
from annotators.classification.knowledge_classifier import KnowledgeClassifier  # noqa: E402
from annotators.cloud.filters import RegionFilter  # noqa: E402
from annotators.cloud.normals import NormalEstimator  # noqa: E402
from annotators.cloud.point_cloud import PointCloudGenerator  # noqa: E402
from annotators.cloud.shape import ShapeAnnotator  # noqa: E402
from annotators.cloud.size import SizeAnnotator  # noqa: E402
from annotators.image.histogram import ColorHistogramAnnotator  # noqa: E402
from annotators.image.image_regions import ImageRegionSegmenter  # noqa: E402
from annotators.image.onnx_detector import OnnxDetector  # noqa: E402
from annotators.readers.choice import reader_for  # noqa: E402
from annotators.readers.frame_readers import KitchenSceneReader  # noqa: E402
from annotators.text.reader import TextReader  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline  # noqa: E402
from robokudo.core.stats import RunStats  # noqa: E402
from robokudo.core.types import ANNOTATION_TYPES, VIEW_TYPES, ColorImage, ObjectHypothesis, Text  # noqa: E402
from trees.tabletop import create_pipeline  # noqa: E402

DATA = (ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense").resolve()
FRAME = 3
RUNS = 30
OCR_RUNS = 3
PROFILES = (
    {"class": "CrackerBox", "colors": ("red", "orange"), "shape": "box", "size": "medium", "texts": ("cheez",)},
    {"class": "Bowl", "shape": "sphere", "size": "medium"},
    {"class": "Mug", "shape": "cylinder", "size": "small"},
    {"class": "MustardBottle", "colors": ("yellow",), "shape": "cylinder", "size": "medium", "texts": ("mustard",)},
)


class Replay(Annotator):
    """Writes the views and annotations of a finished CAS again (hypotheses shared, not copied)."""

    outputs = VIEW_TYPES + ANNOTATION_TYPES

    def __init__(self, items: list) -> None:
        super().__init__(name="replay")
        self.items = items

    def analyse(self) -> None:
        for item in self.items:
            self.write(item)


def cas_items(root: Pipeline) -> list:
    """Every view and scene-level annotation of a pipeline's CAS."""
    items = [v for v in (root.cas.view(t) for t in VIEW_TYPES) if v is not None]
    for annotation_type in ANNOTATION_TYPES:
        items += root.cas.annotations(annotation_type)
    return items


def time_expert(items: list, make: Callable[[], Annotator], runs: int) -> tuple[float, Annotator]:
    """Median ms of the expert's own runs (its RunStats) over ``runs`` pipeline runs on the same CAS content."""
    expert = make()
    pipeline = Pipeline("bench", [Replay(items), expert])
    for run in range(runs + 1):
        if run == 1:
            expert.stats = RunStats()  # the first run builds caches and models; not counted
        pipeline.tick_once()
        while expert.status is Status.RUNNING:
            time.sleep(0.001)
            pipeline.tick_once()
        if expert.status is not Status.SUCCESS:
            raise RuntimeError(f"{expert.name} failed: {expert.feedback_message}")
    return expert.stats.median_seconds * 1e3, expert


def main() -> None:
    if not DATA.is_dir():
        print(f"bench_experts: no data at {DATA}; skipped")
        return
    root = create_pipeline(reader_for(str(DATA), FRAME))
    Engine(root).tick()
    hypotheses = root.cas.annotations(ObjectHypothesis)
    base = cas_items(root)
    normals_pipeline = Pipeline("normals", [Replay(base), NormalEstimator()])
    normals_pipeline.tick_once()
    normals_items = cas_items(normals_pipeline)

    rows: list[tuple[str, float, str]] = []
    count = len(hypotheses)

    def add(label: str, ms: float, note: str = "") -> None:
        rows.append((label, ms, note))

    ms, _ = time_expert(base, NormalEstimator, RUNS)
    add("NormalEstimator", ms, "whole frame")
    ms, _ = time_expert(normals_items, ShapeAnnotator, RUNS)
    add("ShapeAnnotator", ms, f"{ms / count:.2f} ms per hypothesis")
    ms, _ = time_expert(base, SizeAnnotator, RUNS)
    add("SizeAnnotator", ms, f"{ms / count:.2f} ms per hypothesis")
    ms, _ = time_expert(base, ColorHistogramAnnotator, RUNS)
    add("ColorHistogramAnnotator", ms, f"{ms / count:.2f} ms per hypothesis")

    described = Pipeline(
        "described", [Replay(normals_items), ShapeAnnotator(), SizeAnnotator(), ColorHistogramAnnotator()]
    )
    described.tick_once()
    ms, _ = time_expert(cas_items(described), lambda: KnowledgeClassifier(PROFILES), RUNS)
    add("KnowledgeClassifier", ms, f"{len(PROFILES)} profiles, {ms / count:.3f} ms per hypothesis")

    ms, _ = time_expert(base, TextReader, OCR_RUNS)
    read = sum(1 for h in hypotheses if h.find(Text))
    add("TextReader (OCR)", ms, f"one pass over the frame ({count} hypotheses, {read} with text)")

    with tempfile.TemporaryDirectory() as folder:
        from tests.annotators.onnx_models import one_box_model

        model = one_box_model(Path(folder) / "tiny.onnx")
        ms, _ = time_expert(base, lambda: OnnxDetector(str(model), overlap_threshold=0.0), RUNS)
        add("OnnxDetector (tiny model)", ms, "letterbox to 64x64, run, decode, NMS, match")

    ms, _ = time_expert([item for item in base if isinstance(item, ColorImage)], ImageRegionSegmenter, RUNS)
    add("ImageRegionSegmenter", ms, "colour only, whole frame")

    kitchen = Pipeline("kitchen", [KitchenSceneReader(view="table"), PointCloudGenerator()])
    kitchen.tick_once()
    table = next(r for r in kitchen_scene.kitchen_regions() if r.name == "table")
    ms, _ = time_expert(
        cas_items(kitchen), lambda: RegionFilter("table", table.pose.reshape(-1).tolist(), table.size), RUNS
    )
    add("RegionFilter", ms, "kitchen 'table' view (needs a camera pose)")

    print(f"object experts on {DATA.name}/{FRAME:06d} (640x480), {count} hypotheses, median ms per run")
    width = max(len(label) for label, _, _ in rows)
    print(f"{'annotator':{width}s} {'ms':>8s}  note")
    print("-" * (width + 40))
    for label, ms, note in rows:
        print(f"{label:{width}s} {ms:8.2f}  {note}")


if __name__ == "__main__":
    main()
