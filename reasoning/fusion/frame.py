"""Per-frame fusion: the hypotheses of several segmenters and the annotations of several experts become objects.

Hypotheses that cover the same points (overlap ``|A∩B| / min(|A|, |B|)`` of their point sets, or of their
masks) are merged into one :class:`FrameObject`; the annotations attached to any of them become
:class:`~reasoning.fusion.rule.Evidence` of that object. Positions are put in the world frame when the camera pose
is known. Pure numpy: no open3d, no knowledge base.

An object whose geometry its own points do not bear out is marked with a ``doubt`` (:func:`geometry_doubt`): too
few points, tiny, flat, implausibly large, or a stated size the bulk of its points contradicts (the segment took
in points of other surfaces). Such an object may confirm a known belief but never creates one. A stated position
outside the bulk of the object's points is an expert's error: the object is put at the bulk's centre
(:func:`placed_on_points`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np

from reasoning.fusion.rule import CLASS_ATTRIBUTE, Evidence
from robokudo.core.geometry import IDENTITY_QUATERNION, quaternion_from_matrix
from robokudo.core.types import (
    ATTRIBUTE_TYPES,
    Annotation,
    AnswersTo,
    ColorHistogram,
    ObjectHypothesis,
    PersonHypothesis,
    Pose,
    Size,
)

A = TypeVar("A", bound=Annotation)
AttachedReader = Callable[[ObjectHypothesis, type[A]], list[A]]
"""How annotations attached to a hypothesis are read (an annotator passes its port-checked ``attached``)."""

WORLD_FRAME = "world"
"""The name of the fixed frame positions are expressed in when the camera pose is known."""

MIN_POINTS = 30
"""An object with fewer valid 3-D points than this has too little support to become a belief."""

MIN_EXTENT = 0.01
"""An object whose largest extent (metres) is below this is too tiny to be told from noise."""

FLAT_EXTENT = 0.005
"""An object thinner than this (metres, its smallest extent: about a depth sensor's noise) is a patch of a surface,
not something standing out of it."""

MAX_EXTENT = 2.0
"""An object whose largest extent (metres) is above this is no object a robot handles but a merge of surfaces."""

MAX_FOOTPRINT = 0.5
"""An object whose middle extent (metres) is above this is furniture-sized in two directions (a table top, a patch
of floor or wall): long thin things (a broom) pass, broad ones are no object a robot handles."""

MAX_PERSON_EXTENT = 2.5
"""A person's largest extent (metres) above this is a merge of surfaces: the tallest people with an arm raised."""

MAX_PERSON_SPAN = 2.2
"""A person's middle extent (metres) above this is a merge of surfaces: about the widest arm span. A person is
broader than any object a robot handles (arms out, waving), so :data:`MAX_FOOTPRINT` is not theirs."""

ROBUST_PERCENTILES = (2.0, 98.0)
"""The bulk of an object's points: the percentiles its robust box spans on every axis."""

BULK_TOLERANCE = 1.25
"""How far a stated size may exceed the diagonal of the bulk's box, and (as a share of that diagonal beyond it)
how far a stated position may lie outside the box: a box fitted to the points never exceeds them, so only points
the bulk does not have (another surface, stray depth) push it further; the tolerance covers the trimmed
percentiles."""

DEFAULT_MIN_OVERLAP = 0.6
"""Two hypotheses whose point sets overlap at least this much (of the smaller one) are one object."""

FUSED_TYPES: tuple[type[Annotation], ...] = tuple(
    dict.fromkeys((Pose, Size, ColorHistogram, *ATTRIBUTE_TYPES, AnswersTo))
)
"""The annotation types fusion reads from a hypothesis: pose, extents, appearance, every stated attribute, and
whether the object answers to the query's class (for this frame's answer only)."""


@dataclass(slots=True)
class FrameObject:
    """One object seen in one frame, after merging duplicate hypotheses.

    ``position`` is in ``frame`` (``"world"`` when the camera pose was known); ``dimensions`` are metric
    extents sorted largest first; ``appearance`` is a normalised colour histogram (flattened) or None.
    """

    position: np.ndarray
    frame: str
    orientation: np.ndarray = field(default_factory=lambda: np.array(IDENTITY_QUATERNION))
    dimensions: np.ndarray | None = None
    appearance: np.ndarray | None = None
    evidence: list[Evidence] = field(default_factory=list)
    sources: set[str] = field(default_factory=set)
    roi: tuple[int, int, int, int] | None = None
    confidence: float = 1.0
    hypotheses: int = 1
    recording: str = ""
    """The recording the frame belongs to (``CameraInfo.recording``)."""
    doubt: str = ""
    """Why the object's geometry is not trusted ("" when it is); a doubted object never creates a belief."""
    answering: list[Evidence] = field(default_factory=list)
    """Class statements that the object answers to the query's class (from AnswersTo): they count in this frame's
    answer to the query, not in the object's belief (they say how well it answers, not what it is)."""

    def values(self, attribute: str) -> set[str]:
        """The values stated for ``attribute`` in this frame."""
        return {e.value for e in self.evidence if e.attribute == attribute}


@dataclass(frozen=True, slots=True)
class FrameContext:
    """What is needed to place a frame's objects: the organized cloud (camera frame) and the camera pose."""

    points: np.ndarray | None = None
    cam_to_world: np.ndarray | None = None
    camera_frame: str = "camera"
    time: float = 0.0
    recording: str = ""


def _default_reader(hypothesis: ObjectHypothesis, annotation_type: type[A]) -> list[A]:
    return hypothesis.find(annotation_type)


# ------------------------------------------------------------------------------------------ duplicates


def _index_set(hypothesis: ObjectHypothesis) -> np.ndarray:
    indices = np.asarray(hypothesis.point_indices).ravel()
    if indices.size == 0 and hypothesis.mask is not None and np.asarray(hypothesis.mask).size > 1:
        indices = np.flatnonzero(hypothesis.mask)
    indices = indices.astype(np.int64, copy=False)
    if indices.size < 2 or bool(np.all(indices[1:] > indices[:-1])):  # already sorted and unique (flatnonzero)
        return indices
    return np.unique(indices)


def _roi_overlaps(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _roi_overlap_ratio(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> float:
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    if w <= 0 or h <= 0:
        return 0.0
    smaller = min((a[2] - a[0]) * (a[3] - a[1]), (b[2] - b[0]) * (b[3] - b[1]))
    return (w * h) / smaller if smaller > 0 else 0.0


def overlap(a: np.ndarray, b: np.ndarray) -> float:
    """``|A∩B| / min(|A|, |B|)`` of two sorted unique index arrays (0 when one is empty)."""
    if a.size == 0 or b.size == 0:
        return 0.0
    common = np.intersect1d(a, b, assume_unique=True).size
    return common / min(a.size, b.size)


def duplicate_groups(
    hypotheses: Sequence[ObjectHypothesis], min_overlap: float = DEFAULT_MIN_OVERLAP
) -> list[list[int]]:
    """Indices of hypotheses grouped so that overlapping ones (transitively) share a group, in input order."""
    return _groups(hypotheses, [_index_set(h) for h in hypotheses], min_overlap)


def _groups(hypotheses: Sequence[ObjectHypothesis], sets: Sequence[np.ndarray], min_overlap: float) -> list[list[int]]:
    n = len(hypotheses)
    parent = list(range(n))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(n):
        for j in range(i + 1, n):
            a, b = hypotheses[i], hypotheses[j]
            if not _roi_overlaps(a.roi, b.roi):
                continue
            both = sets[i].size and sets[j].size
            score = overlap(sets[i], sets[j]) if both else _roi_overlap_ratio(a.roi, b.roi)
            if score >= min_overlap:
                parent[find(j)] = find(i)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return list(groups.values())


# ------------------------------------------------------------------------------------------ geometry


def _pose_in_frame(pose: Pose, context: FrameContext) -> tuple[np.ndarray, np.ndarray, str]:
    position = np.asarray(pose.position, dtype=np.float64).reshape(3)
    orientation = np.asarray(pose.orientation, dtype=np.float64).reshape(4)
    if pose.frame == WORLD_FRAME:
        return position, orientation, WORLD_FRAME
    if context.cam_to_world is None:  # a camera-frame pose, named after the camera
        return position, orientation, context.camera_frame
    transform = np.asarray(context.cam_to_world, dtype=np.float64) @ pose.matrix()
    return transform[:3, 3].copy(), quaternion_from_matrix(transform[:3, :3]), WORLD_FRAME


def _points_of(indices: np.ndarray, context: FrameContext) -> np.ndarray | None:
    if context.points is None or indices.size == 0:
        return None
    flat = np.asarray(context.points).reshape(-1, 3)
    indices = indices[(indices >= 0) & (indices < flat.shape[0])]
    points = flat[indices].astype(np.float64, copy=False)
    points = points[np.isfinite(points).all(axis=1)]
    if points.shape[0] == 0:
        return None
    if context.cam_to_world is not None:
        transform = np.asarray(context.cam_to_world, dtype=np.float64)
        points = points @ transform[:3, :3].T + transform[:3, 3]
    return points


def _union_roi(rois: Sequence[tuple[int, int, int, int]]) -> tuple[int, int, int, int]:
    return (
        int(min(r[0] for r in rois)),
        int(min(r[1] for r in rois)),
        int(max(r[2] for r in rois)),
        int(max(r[3] for r in rois)),
    )


# ------------------------------------------------------------------------------------------ evidence


def hypothesis_evidence(
    hypothesis: ObjectHypothesis, time: float = 0.0, read: AttachedReader | None = None
) -> list[Evidence]:
    """The attribute statements attached to one hypothesis, one per annotation that states an attribute
    (:data:`~robokudo.core.types.ATTRIBUTE_TYPES`: colour, shape, size class, class, text, region)."""
    reader: AttachedReader = read or _default_reader
    found: list[Evidence] = []
    for annotation_type in ATTRIBUTE_TYPES:
        attribute = annotation_type.attribute
        for annotation in reader(hypothesis, annotation_type):
            value = annotation.attribute_value()
            if value:
                found.append(Evidence(attribute, value, annotation.confidence, annotation.source or "unknown", time))
    return found


def frame_objects(
    hypotheses: Sequence[ObjectHypothesis],
    context: FrameContext | None = None,
    *,
    min_overlap: float = DEFAULT_MIN_OVERLAP,
    read: AttachedReader | None = None,
) -> list[FrameObject]:
    """Merge duplicate hypotheses and collect their annotations into located objects.

    Hypotheses without a position (no Pose annotation and no valid points) are left out: they cannot be
    told apart across frames.
    """
    context = context or FrameContext()
    reader: AttachedReader = read or _default_reader
    objects: list[FrameObject] = []
    sets = [_index_set(h) for h in hypotheses]
    for group in _groups(hypotheses, sets, min_overlap):
        members = [hypotheses[i] for i in group]
        indices = sets[group[0]] if len(group) == 1 else np.unique(np.concatenate([sets[i] for i in group]))
        made = _merge_group(members, indices, context, reader)
        if made is not None:
            objects.append(made)
    return objects


def _merge_group(
    members: Sequence[ObjectHypothesis], indices: np.ndarray, context: FrameContext, reader: AttachedReader
) -> FrameObject | None:
    points = _points_of(indices, context)
    poses = [p for h in members for p in reader(h, Pose)]
    if len(poses) == 1:
        position, orientation, frame = _pose_in_frame(poses[0], context)
    elif poses:
        placed = [(_pose_in_frame(p, context), max(p.confidence, 1e-3)) for p in poses]
        weights = np.array([w for _, w in placed])
        position = np.average(np.stack([pp[0] for pp, _ in placed]), axis=0, weights=weights)
        (_, orientation, frame), _ = max(placed, key=lambda item: item[1])
    elif points is not None:
        position = points.mean(axis=0)
        orientation = np.array(IDENTITY_QUATERNION)
        frame = WORLD_FRAME if context.cam_to_world is not None else context.camera_frame
    else:
        return None
    sizes = [s for h in members for s in reader(h, Size)]
    dimensions: np.ndarray | None = None
    if len(sizes) == 1:
        dimensions = np.sort(np.asarray(sizes[0].dimensions, dtype=np.float64))[::-1]
    elif sizes:
        weights = np.array([max(s.confidence, 1e-3) for s in sizes])
        dims = np.stack([np.sort(np.asarray(s.dimensions, dtype=np.float64))[::-1] for s in sizes])
        dimensions = np.average(dims, axis=0, weights=weights)
    elif points is not None and points.shape[0] >= 4:
        low, high = np.percentile(points, [2.0, 98.0], axis=0)
        dimensions = np.sort(high - low)[::-1]
    histograms = [hist for h in members for hist in reader(h, ColorHistogram)]
    appearance: np.ndarray | None = None
    if histograms:
        shape = np.asarray(histograms[0].histogram).shape
        same = [np.asarray(hist.histogram, dtype=np.float64) for hist in histograms if hist.histogram.shape == shape]
        summed = np.sum(same, axis=0).ravel()
        total = summed.sum()
        appearance = summed / total if total > 0 else None
    position = placed_on_points(np.asarray(position, dtype=np.float64), points)
    doubt = geometry_doubt(dimensions, points, person=any(isinstance(h, PersonHypothesis) for h in members))
    evidence = [e for h in members for e in hypothesis_evidence(h, context.time, reader)]
    answering = [
        Evidence(CLASS_ATTRIBUTE, a.class_name.strip(), a.confidence, a.source or "unknown", context.time)
        for h in members
        for a in reader(h, AnswersTo)
        if a.class_name.strip()
    ]
    sources = {h.source for h in members if h.source}
    sources.update(e.source for e in evidence)
    sources.update(p.source for p in poses if p.source)
    sources.update(s.source for s in sizes if s.source)
    return FrameObject(
        position=np.asarray(position, dtype=np.float64),
        frame=frame,
        orientation=np.asarray(orientation, dtype=np.float64),
        dimensions=dimensions,
        appearance=appearance,
        evidence=evidence,
        sources=sources,
        roi=_union_roi([h.roi for h in members]),
        confidence=max(h.confidence for h in members),
        hypotheses=len(members),
        recording=context.recording,
        doubt=doubt,
        answering=answering,
    )


def _bulk(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    low, high = np.percentile(points, ROBUST_PERCENTILES, axis=0)
    return low, high


def placed_on_points(position: np.ndarray, points: np.ndarray | None) -> np.ndarray:
    """``position``, or the centre of the bulk of ``points`` when it lies outside their box by more than the
    tolerance (:data:`BULK_TOLERANCE`); ``points`` are in the frame of ``position``."""
    if points is None or points.shape[0] < MIN_POINTS:
        return position
    low, high = _bulk(points)
    margin = (BULK_TOLERANCE - 1.0) * float(np.linalg.norm(high - low))
    if np.all(position >= low - margin) and np.all(position <= high + margin):
        return position
    return (low + high) / 2.0


def geometry_doubt(dimensions: np.ndarray | None, points: np.ndarray | None, *, person: bool = False) -> str:
    """Why an object's stated size and support are not to be trusted, or "" (see :data:`BULK_TOLERANCE`).

    ``points`` are the object's valid points (None when the frame has no cloud: then only the size is checked);
    a ``person`` is held to a person's size (:data:`MAX_PERSON_EXTENT`, :data:`MAX_PERSON_SPAN`).
    """
    if points is not None and points.shape[0] < MIN_POINTS:
        return f"only {points.shape[0]} valid points"
    if dimensions is not None and len(dimensions):
        extents = np.sort(np.asarray(dimensions, dtype=np.float64))[::-1]
        largest, middle, smallest = float(extents[0]), float(extents[len(extents) // 2]), float(extents[-1])
        if largest < MIN_EXTENT:
            return f"tiny ({largest * 100:.1f} cm)"
        if smallest < FLAT_EXTENT:
            return f"flat ({smallest * 1000:.0f} mm thick): a patch of a surface"
        longest, broadest = (MAX_PERSON_EXTENT, MAX_PERSON_SPAN) if person else (MAX_EXTENT, MAX_FOOTPRINT)
        if largest > longest or middle > broadest:
            return f"implausibly large ({' x '.join(f'{e:.2f}' for e in extents)} m)"
    if points is None:
        return ""
    low, high = _bulk(points)
    diagonal = float(np.linalg.norm(high - low))
    if dimensions is not None and len(dimensions) and float(np.max(dimensions)) > BULK_TOLERANCE * diagonal:
        return f"stated size {float(np.max(dimensions)):.2f} m exceeds its points' extent ({diagonal:.2f} m)"
    return ""
