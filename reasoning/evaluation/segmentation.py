"""Scores of an object segmentation against a ground-truth labelling of the same pixels.

Both labellings are HxW integer images, 0 for "no object" and one positive label per object (ground truth) or per
segment (prediction). Three families of figures, all computed by :func:`score_segmentation`:

* **Objects at box IoU >= 0.5**: each object's and each segment's 2-D bounding box; objects and segments are
  paired one to one (Hungarian, the most pairs at IoU >= ``min_iou``, ties broken by IoU). Recall is the share of
  objects paired, precision the share of segments paired.
* **Overlap P/R/F** as in the unseen-object-segmentation literature (OSD/OCID: Richtsfeld et al. 2012, Xie et al.
  2019, Xiang et al. 2020): objects and segments are paired one to one by the Hungarian method on their pairwise
  F-measure ``2 |c ∩ g| / (|c| + |g|)``; precision is the sum of the paired intersections over all segment
  pixels, recall the same sum over all object pixels, F their harmonic mean. ``objects_f75`` counts the objects
  whose paired segment reaches F >= 0.75 (the papers' "%75").
* **Boundary P/R/F**, the same on 1-pixel outlines (a pixel whose 4-neighbour carries another label): a segment's
  outline pixel counts when an object outline lies within ``ceil(0.003 * image diagonal)`` pixels, and vice versa;
  pairs are matched by the Hungarian method on the boundary F-measure.

:func:`summarize` adds scenes up: object counts are summed (micro recall / precision), overlap and boundary
P/R/F are averaged over scenes, as the papers report them.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage
from scipy.optimize import linear_sum_assignment

MIN_BOX_IOU = 0.5
"""Box IoU at which a segment counts as finding an object."""

F_THRESHOLD = 0.75
"""Overlap F-measure at which an object counts as well segmented (the papers' "%75")."""

BOUNDARY_TOLERANCE = 0.003
"""Share of the image diagonal within which outline pixels match (the DAVIS / OSD boundary convention)."""


@dataclass(frozen=True)
class SegmentationScore:
    """The figures of one scene (see the module docstring); counts are integers, shares 0..1."""

    objects: int
    segments: int
    matched: int
    objects_f75: int
    overlap_precision: float
    overlap_recall: float
    overlap_f: float
    boundary_precision: float
    boundary_recall: float
    boundary_f: float

    @property
    def recall(self) -> float:
        """Share of the objects found at box IoU >= 0.5 (1 for a scene without objects)."""
        return self.matched / self.objects if self.objects else 1.0

    @property
    def precision(self) -> float:
        """Share of the segments that found an object (1 when there is no segment: nothing was claimed)."""
        return self.matched / self.segments if self.segments else 1.0

    def as_dict(self) -> dict[str, float | int]:
        """The figures as plain data, with recall and precision."""
        return {**asdict(self), "recall": self.recall, "precision": self.precision}


@dataclass(frozen=True)
class ScoreSummary(SegmentationScore):
    """Several scenes together: summed counts (so recall and precision are over all objects and segments) and
    per-scene means of the overlap and boundary figures."""

    scenes: int = 0


def _harmonic(precision: float, recall: float) -> float:
    return 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0


def _share(hits: float, total: float, other_total: float) -> float:
    """``hits / total``; without outline pixels 1 when the other labelling has none either (both fill the
    image), else 0."""
    if total:
        return hits / total
    return 1.0 if not other_total else 0.0


def _dense(labels: np.ndarray) -> tuple[np.ndarray, int]:
    """Labels renumbered 1..n in increasing order (0 stays 0), and n."""
    values, inverse = np.unique(labels, return_inverse=True)
    inverse = inverse.reshape(labels.shape)
    if values[0] == 0:
        return inverse.astype(np.int64), values.size - 1
    return inverse.astype(np.int64) + 1, values.size


def _boxes(labels: np.ndarray, count: int) -> np.ndarray:
    """``count`` x 4 boxes ``(x0, y0, x1, y1)``, x1/y1 exclusive, of labels 1..count."""
    boxes = np.zeros((count, 4), dtype=np.float64)
    for index, found in enumerate(ndimage.find_objects(labels, max_label=count)):
        if found is not None:
            rows, cols = found
            boxes[index] = (cols.start, rows.start, cols.stop, rows.stop)
    return boxes


def box_ious(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The IoU of every pair of boxes (Nx4 by Mx4, ``(x0, y0, x1, y1)`` with x1/y1 exclusive) as an NxM array."""
    first, second = np.asarray(first, dtype=np.float64), np.asarray(second, dtype=np.float64)
    x0 = np.maximum(first[:, None, 0], second[None, :, 0])
    y0 = np.maximum(first[:, None, 1], second[None, :, 1])
    x1 = np.minimum(first[:, None, 2], second[None, :, 2])
    y1 = np.minimum(first[:, None, 3], second[None, :, 3])
    shared = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
    area_first = (first[:, 2] - first[:, 0]) * (first[:, 3] - first[:, 1])
    area_second = (second[:, 2] - second[:, 0]) * (second[:, 3] - second[:, 1])
    union = area_first[:, None] + area_second[None, :] - shared
    return np.divide(shared, union, out=np.zeros_like(shared), where=union > 0)


def count_box_matches(ious: np.ndarray, min_iou: float = MIN_BOX_IOU) -> int:
    """The most one-to-one pairs of an NxM IoU matrix with IoU >= ``min_iou``."""
    if ious.size == 0:
        return 0
    good = ious >= min_iou
    weight = np.where(good, min(ious.shape) + 1 + ious, 0.0)
    rows, cols = linear_sum_assignment(weight, maximize=True)
    return int(np.count_nonzero(good[rows, cols]))


def _matched_sums(pair_f: np.ndarray, terms_first: np.ndarray, terms_second: np.ndarray) -> tuple[float, float, list]:
    """Hungarian pairs maximising ``pair_f`` and the sums of the two term matrices over the pairs with F > 0."""
    if pair_f.size == 0:
        return 0.0, 0.0, []
    rows, cols = linear_sum_assignment(pair_f, maximize=True)
    keep = pair_f[rows, cols] > 0
    rows, cols = rows[keep], cols[keep]
    return (
        float(terms_first[rows, cols].sum()),
        float(terms_second[rows, cols].sum()),
        list(zip(rows, cols, strict=True)),
    )


def outlines(labels: np.ndarray) -> np.ndarray:
    """HxW bool: pixels of a positive label with a 4-neighbour of another label (inside the image)."""
    edge = np.zeros(labels.shape, dtype=bool)
    horizontal = labels[:, 1:] != labels[:, :-1]
    vertical = labels[1:, :] != labels[:-1, :]
    edge[:, 1:] |= horizontal
    edge[:, :-1] |= horizontal
    edge[1:, :] |= vertical
    edge[:-1, :] |= vertical
    return edge & (labels > 0)


def _disk(radius: int) -> np.ndarray:
    span = np.arange(-radius, radius + 1)
    return span[:, None] ** 2 + span[None, :] ** 2 <= radius * radius


def _near_counts(
    source: np.ndarray,
    source_edges: np.ndarray,
    count: int,
    target: np.ndarray,
    target_edges: np.ndarray,
    target_count: int,
    radius: int,
) -> np.ndarray:
    """``count`` x ``target_count``: outline pixels of each target label within ``radius`` of each source outline."""
    near = np.zeros((count, target_count), dtype=np.float64)
    disk = _disk(radius)
    rows, cols = source.shape
    for index, found in enumerate(ndimage.find_objects(source, max_label=count)):
        if found is None:
            continue
        r0, r1 = max(found[0].start - radius, 0), min(found[0].stop + radius, rows)
        c0, c1 = max(found[1].start - radius, 0), min(found[1].stop + radius, cols)
        own = source_edges[r0:r1, c0:c1] & (source[r0:r1, c0:c1] == index + 1)
        reach = ndimage.binary_dilation(own, structure=disk)
        hit = target[r0:r1, c0:c1][reach & target_edges[r0:r1, c0:c1]]
        near[index] = np.bincount(hit, minlength=target_count + 1)[1:]
    return near


def score_segmentation(
    truth: np.ndarray, predicted: np.ndarray, valid: np.ndarray | None = None, min_iou: float = MIN_BOX_IOU
) -> SegmentationScore:
    """Score the segment labels ``predicted`` against the object labels ``truth`` (HxW, 0 = none).

    ``valid`` (HxW bool) limits both to the pixels that carry a measurement; labels need not be consecutive.
    """
    truth = np.asarray(truth)
    predicted = np.asarray(predicted)
    if truth.shape != predicted.shape or truth.ndim != 2:
        raise ValueError(f"truth {truth.shape} and prediction {predicted.shape} must be HxW images of one size")
    if valid is not None:
        truth = np.where(valid, truth, 0)
        predicted = np.where(valid, predicted, 0)
    truth, objects = _dense(truth)
    predicted, segments = _dense(predicted)

    joint = np.bincount((truth * (segments + 1) + predicted).reshape(-1), minlength=(objects + 1) * (segments + 1))
    joint = joint.reshape(objects + 1, segments + 1).astype(np.float64)
    shared = joint[1:, 1:]
    object_sizes, segment_sizes = joint[1:, :].sum(axis=1), joint[:, 1:].sum(axis=0)
    matched = count_box_matches(box_ious(_boxes(truth, objects), _boxes(predicted, segments)), min_iou)

    with np.errstate(invalid="ignore", divide="ignore"):
        pair_f = np.nan_to_num(2 * shared / (object_sizes[:, None] + segment_sizes[None, :]))
    paired, _, pairs = _matched_sums(pair_f, shared, shared)
    precision = paired / segment_sizes.sum() if segments else 0.0
    recall = paired / object_sizes.sum() if objects else 0.0
    f75 = sum(1 for row, col in pairs if pair_f[row, col] >= F_THRESHOLD)

    radius = math.ceil(BOUNDARY_TOLERANCE * math.hypot(*truth.shape))
    truth_edges, predicted_edges = outlines(truth), outlines(predicted)
    truth_outline = np.bincount(truth[truth_edges], minlength=objects + 1)[1:].astype(np.float64)
    predicted_outline = np.bincount(predicted[predicted_edges], minlength=segments + 1)[1:].astype(np.float64)
    segment_hits = _near_counts(truth, truth_edges, objects, predicted, predicted_edges, segments, radius)
    object_hits = _near_counts(predicted, predicted_edges, segments, truth, truth_edges, objects, radius).T
    with np.errstate(invalid="ignore", divide="ignore"):
        pair_precision = np.nan_to_num(segment_hits / predicted_outline[None, :])
        pair_recall = np.nan_to_num(object_hits / truth_outline[:, None])
        boundary_f = np.nan_to_num(2 * pair_precision * pair_recall / (pair_precision + pair_recall))
    hits_precision, hits_recall, _ = _matched_sums(boundary_f, segment_hits, object_hits)
    b_precision = _share(hits_precision, predicted_outline.sum(), truth_outline.sum())
    b_recall = _share(hits_recall, truth_outline.sum(), predicted_outline.sum())
    return SegmentationScore(
        objects=objects,
        segments=segments,
        matched=matched,
        objects_f75=f75,
        overlap_precision=precision,
        overlap_recall=recall,
        overlap_f=_harmonic(precision, recall),
        boundary_precision=b_precision,
        boundary_recall=b_recall,
        boundary_f=_harmonic(b_precision, b_recall),
    )


def summarize(scores: Iterable[SegmentationScore]) -> ScoreSummary:
    """Scenes together: counts summed, overlap and boundary P/R/F averaged over the scenes (0 scenes: zeros)."""
    scores = list(scores)
    count = len(scores)

    def mean(name: str) -> float:
        return sum(getattr(s, name) for s in scores) / count if count else 0.0

    return ScoreSummary(
        scenes=count,
        objects=sum(s.objects for s in scores),
        segments=sum(s.segments for s in scores),
        matched=sum(s.matched for s in scores),
        objects_f75=sum(s.objects_f75 for s in scores),
        overlap_precision=mean("overlap_precision"),
        overlap_recall=mean("overlap_recall"),
        overlap_f=mean("overlap_f"),
        boundary_precision=mean("boundary_precision"),
        boundary_recall=mean("boundary_recall"),
        boundary_f=mean("boundary_f"),
    )
