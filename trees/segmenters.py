"""Segmenters by name, each run on a recorded frame as the tabletop tree runs it, for scoring against labels.

* ``clutter``: the tabletop front (reader, range filter, support plane) and the ClutterSegmenter (convexity);
* ``clutter-grown``: the same with patches grown from the flattest pixels instead of grid cells, which gives the
  same segments wherever the candidates' box starts (``ClutterParameters.grown_patches``; not the default, see
  bench/profiles/segscore-analysis.txt);
* ``clusters``: the same front and the ClusterExtractor (depth jumps, hue edges, footprint merging);
* ``open3d``: the untuned Open3D recipe (plane RANSAC + DBSCAN at 2 cm) on the frame's points.

Each gives a :class:`SegmentedFrame`: the segment labels on the frame's grid, the frame (with its ground-truth
labels when the file has them) and the time the segmentation took, reading excluded.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from py_trees.common import Status

from annotators.cloud.clusters import ClusterExtractor
from annotators.cloud.clutter import ClutterSegmenter
from annotators.cloud.filters import RangeFilter
from annotators.cloud.open3d_baseline import plane_dbscan_labels
from annotators.cloud.support_choice import SupportPlaneSegmenter
from annotators.readers.frame_io import Frame
from annotators.readers.frame_readers import FileFrameReader
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import ObjectHypothesis


@dataclass(frozen=True, eq=False)
class SegmentedFrame:
    """A frame and its segments: ``labels`` HxW int32 (0 = none), ``seconds`` the segmentation's run time."""

    frame: Frame
    labels: np.ndarray
    seconds: float


@dataclass(frozen=True)
class Segmenter:
    """A named way to segment a frame read by ``reader``."""

    name: str
    description: str
    segment: Callable[[FileFrameReader], SegmentedFrame]


def hypothesis_labels(hypotheses: list[ObjectHypothesis], shape: tuple[int, int]) -> np.ndarray:
    """HxW int32 labels 1..n of the hypotheses' masks, larger hypotheses first where masks overlap."""
    labels = np.zeros(shape, dtype=np.int32)
    ordered = sorted(hypotheses, key=lambda h: -int(np.count_nonzero(h.mask)))
    for number, hypothesis in enumerate(ordered, start=1):
        labels[hypothesis.mask & (labels == 0)] = number
    return labels


def with_front(make: Callable[[], Annotator]) -> Callable[[FileFrameReader], SegmentedFrame]:
    """Run reader, range filter (0.2-2.5 m), support plane and the segmenter ``make()`` once on the frame."""

    def segment(reader: FileFrameReader) -> SegmentedFrame:
        frame = reader.load()
        steps = [RangeFilter(min_depth=0.2, max_depth=2.5), SupportPlaneSegmenter(), make()]
        root = Pipeline("segmentation", [reader, *steps])
        status = Engine(root).tick()
        seconds = sum(step.stats.total_seconds for step in steps)
        hypotheses = root.cas.annotations(ObjectHypothesis) if status is Status.SUCCESS else []
        return SegmentedFrame(frame, hypothesis_labels(hypotheses, frame.depth.shape), seconds)

    return segment


def _open3d(reader: FileFrameReader) -> SegmentedFrame:
    frame = reader.load()
    start = time.perf_counter()
    labels = plane_dbscan_labels(frame.points)
    return SegmentedFrame(frame, labels, time.perf_counter() - start)


SEGMENTERS: Mapping[str, Segmenter] = MappingProxyType(
    {
        "clutter": Segmenter(
            "clutter", "ClutterSegmenter: convexly connected surfaces (new)", with_front(ClutterSegmenter)
        ),
        "clutter-grown": Segmenter(
            "clutter-grown",
            "ClutterSegmenter with patches grown from the flattest pixels: no cell phase (alternative)",
            with_front(lambda: ClutterSegmenter(grown_patches=True)),
        ),
        "clusters": Segmenter(
            "clusters", "ClusterExtractor: cuts and footprint merging (old)", with_front(ClusterExtractor)
        ),
        "open3d": Segmenter("open3d", "untuned Open3D plane RANSAC + DBSCAN at 2 cm (baseline)", _open3d),
    }
)
"""Every segmenter ``robokudo eval segmentation --segmenter NAME`` can score, by name."""


def segmenter(name: str) -> Segmenter:
    """The segmenter called ``name``; KeyError listing the known ones."""
    if name not in SEGMENTERS:
        raise KeyError(f"no segmenter named {name!r}; known: {', '.join(SEGMENTERS)}")
    return SEGMENTERS[name]
