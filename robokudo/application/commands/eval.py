"""``robokudo eval segmentation PATH...``: score a segmenter against labelled frames, per scene, category and overall.

PATH is a labelled organized PCD file (mOSD labels: 1-9 table, object id = label // 10 for labels >= 20) or a
folder of them. For each scene it prints the objects and segments, the objects found at 2-D box IoU >= 0.5
(recall and precision), the overlap and boundary precision / recall / F-measure of the unseen-object-segmentation
literature (Hungarian matching, see :mod:`reasoning.evaluation.segmentation`) and the segmentation time; then the
same per category (mOSD: from the scene number; other files: their folder) and overall. ``--json`` prints one
JSON document instead. ``--workers N`` scores N scenes at a time as Ray tasks, on a local cluster or the one at
``--address`` (the scene files must be readable at the same path there): the same figures as in one process.
Exit status 0, or 2 for a path that is no labelled frame, an unknown segmenter, or ``--workers`` without Ray.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from annotators.readers.frame_io import FrameError
from annotators.readers.frame_readers import PcdReader
from reasoning.evaluation.mosd import object_labels, scene_category
from reasoning.evaluation.segmentation import ScoreSummary, SegmentationScore, score_segmentation, summarize
from robokudo.application.cluster import ClusterError
from robokudo.application.parallel import map_on_cluster, run_in_order
from trees.segmenters import SEGMENTERS, segmenter

HELP = "score a segmentation against labelled frames"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo eval``."""
    kinds = parser.add_subparsers(dest="kind", required=True, metavar="KIND")
    segmentation = kinds.add_parser(
        "segmentation", help="score object segmentation on labelled organized PCD files (mOSD labels)"
    )
    segmentation.add_argument("paths", nargs="+", metavar="PATH", help="labelled .pcd file or folder of them")
    segmentation.add_argument(
        "--segmenter",
        default="clutter",
        choices=sorted(SEGMENTERS),
        help="what segments the frames: " + "; ".join(f"{s.name}: {s.description}" for s in SEGMENTERS.values()),
    )
    segmentation.add_argument("--json", action="store_true", help="print the scores as JSON")
    segmentation.add_argument(
        "--workers",
        type=int,
        default=1,
        metavar="N",
        help="score N scenes at a time as Ray tasks (needs robokudo[ray]; default 1: in this process)",
    )
    segmentation.add_argument(
        "--address",
        metavar="ADDRESS",
        help="the Ray cluster for --workers: ray://HOST:10001 or HOST:6379 (default: a local cluster with N CPUs)",
    )


@dataclass(frozen=True)
class SceneResult:
    """One scored scene."""

    scene: str
    category: str
    score: SegmentationScore
    milliseconds: float


def scene_files(paths: list[str]) -> list[Path]:
    """The PCD files named or found in the named folders (natural order); ValueError for anything else."""
    found: list[Path] = []
    for name in paths:
        path = Path(name)
        if path.is_dir():
            files = sorted(path.glob("*.pcd"), key=_natural)
            if not files:
                raise ValueError(f"{path} holds no .pcd file")
            found.extend(files)
        elif path.is_file() and path.suffix.lower() == ".pcd":
            found.append(path)
        elif not path.exists():
            raise ValueError(f"{path}: no such file or folder")
        else:
            raise ValueError(f"{path} is not a .pcd file or a folder of them")
    return found


def _natural(path: Path) -> list[object]:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path.name)]


def score_scene(path: Path, segmenter_name: str) -> SceneResult:
    """Segment one labelled scene and score it; ValueError when it has no labels."""
    segmented = segmenter(segmenter_name).segment(PcdReader(path))
    frame = segmented.frame
    if frame.labels is None:
        raise ValueError(f"{path} has no label field to score against")
    valid = np.isfinite(frame.points[..., 2]) if frame.points is not None else frame.depth > 0
    score = score_segmentation(object_labels(frame.labels), segmented.labels, valid)
    return SceneResult(path.stem, scene_category(path), score, segmented.seconds * 1000.0)


def run(args: argparse.Namespace) -> int:
    """Score the scenes and print the results; 2 for bad paths or unlabelled files."""
    if args.workers < 1:
        print(f"robokudo eval: --workers must be at least 1, got {args.workers}", file=sys.stderr)
        return 2
    try:
        files = scene_files(args.paths)
        if args.workers == 1 and args.address is None:
            results = run_in_order(score_scene, files, args.segmenter, label="scenes")
        else:
            results = map_on_cluster(
                score_scene,
                files,
                args.segmenter,
                workers=args.workers,
                address=args.address,
                label="scenes",
                purpose=f"--workers {args.workers}" if args.address is None else "--address",
            )
    except (ValueError, FrameError, ClusterError) as error:
        print(f"robokudo eval: {error}", file=sys.stderr)
        return 2
    categories: dict[str, list[SceneResult]] = {}
    for result in results:
        categories.setdefault(result.category, []).append(result)
    overall = summarize(r.score for r in results)
    by_category = {name: summarize(r.score for r in members) for name, members in categories.items()}
    if args.json:
        print(json.dumps(_document(args.segmenter, results, by_category, overall), indent=2))
    else:
        print(_table(args.segmenter, results, by_category, overall))
    return 0


def _document(
    name: str, results: list[SceneResult], by_category: dict[str, ScoreSummary], overall: ScoreSummary
) -> dict[str, object]:
    return {
        "segmenter": name,
        "min_box_iou": 0.5,
        "scenes": [
            {"scene": r.scene, "category": r.category, **r.score.as_dict(), "milliseconds": round(r.milliseconds, 2)}
            for r in results
        ],
        "categories": {category: summary.as_dict() for category, summary in by_category.items()},
        "overall": overall.as_dict(),
    }


HEADER = f"{'':<16}{'objects':>8}{'segments':>9}{'found':>6}{'recall':>8}{'precision':>10}" + (
    f"{'overlap P':>10}{'R':>6}{'F':>6}{'boundary F':>11}"
)


def _row(name: str, score: SegmentationScore | ScoreSummary, extra: str = "") -> str:
    return (
        f"{name:<16}{score.objects:>8}{score.segments:>9}{score.matched:>6}{score.recall:>8.2f}{score.precision:>10.2f}"
        f"{score.overlap_precision:>10.3f}{score.overlap_recall:>6.3f}{score.overlap_f:>6.3f}{score.boundary_f:>11.3f}"
        f"{extra}"
    )


def _table(name: str, results: list[SceneResult], by_category: dict[str, ScoreSummary], overall: ScoreSummary) -> str:
    lines = [f"segmenter: {segmenter(name).description}", "", f"{'scene':<16}{HEADER[16:]}{'category':>11}{'ms':>8}"]
    lines += [_row(r.scene, r.score, f"{r.category:>11}{r.milliseconds:>8.1f}") for r in results]
    lines += ["", f"{'category':<16}{HEADER[16:]}{'scenes':>8}"]
    lines += [_row(category, summary, f"{summary.scenes:>8}") for category, summary in by_category.items()]
    lines += [_row("overall", overall, f"{overall.scenes:>8}")]
    lines += [
        "",
        "found: objects paired one to one with a segment at 2-D box IoU >= 0.5; overlap and boundary P/R/F: "
        "Hungarian-matched pixel overlap (boundaries within 0.3% of the diagonal), averaged over scenes",
    ]
    return "\n".join(lines)
