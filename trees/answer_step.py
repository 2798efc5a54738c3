"""The answer step: the last leaf of a query's tree, fusing the CAS's hypotheses into the belief store.

:class:`AnswerStep` fuses the CAS's object hypotheses (:mod:`reasoning.fusion.frame`), integrates them into the
:class:`~reasoning.beliefs.store.BeliefStore` (identity, confidence, history) and answers the query with object
designators (:mod:`reasoning.beliefs.answer`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from queries import Query
from reasoning.beliefs.answer import (
    Answer,
    PlacementDesignator,
    PointingAnswer,
    PoseDesignator,
    TrackDesignator,
    class_label,
    designator,
)
from reasoning.beliefs.ranking import best_first
from reasoning.beliefs.selection import SelectionNote, Viewpoint, select
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FUSED_TYPES, WORLD_FRAME, FrameContext, FrameObject, frame_objects
from reasoning.fusion.tracking import BeliefTracker, TrackStep
from robokudo.core.annotator import Annotator
from robokudo.core.types import (
    CameraInfo,
    CasType,
    DepthImage,
    FreePlacement,
    ObjectHypothesis,
    PersonTrack,
    Plane,
    PointCloud,
    PointingTarget,
    QueryAnswer,
    QueryView,
    TargetTrack,
)


def camera_model(
    info: CameraInfo, depth: np.ndarray | None = None, looks_for: Callable[[str], bool] | None = None
) -> CameraModel:
    """The visibility model of a frame: world frame when the camera pose is known, else the camera frame;
    ``looks_for``: the stored classes the frame's detectors report (None: all)."""
    known = info.cam_to_world is not None
    return CameraModel(
        intrinsics=info.intrinsics,
        to_frame=np.asarray(info.cam_to_world, dtype=np.float64) if known else np.eye(4),
        frame=WORLD_FRAME if known else info.frame_id,
        depth=depth,
        recording=info.recording,
        looks_for=looks_for,
    )


StoreSource = BeliefStore | str | Path | Callable[[], BeliefStore] | None


class AnswerStep(Annotator):
    """Fuse this frame's hypotheses into the belief store and answer the query (a QueryAnswer in the CAS).

    ``store`` is a store, a path, a factory, or None for :meth:`BeliefStore.default_path`; it is opened on the
    first run. ``tracker`` (class test, regions, gates) defaults to the store's. The query's filter is
    ``belief_filter``, or ``filter_for(query)`` of the CAS's QueryView, or everything seen. The answer holds
    the matching objects seen in this frame, most confident first (under a limit, the most likely to be what was
    asked: :mod:`reasoning.beliefs.ranking`), with their image ROI (an object whose leading class is only a guess
    of the asked class is a candidate too, by the rule the answer from memory applies:
    :mod:`reasoning.beliefs.class_candidates`); when a tracker wrote the frame's
    TargetTrack (a continuous task), only the tracked object, with the track; ``label_of`` names classes (e.g.
    the knowledge base's labels). Objects whose geometry is in doubt confirm known beliefs but create none. With
    ``fail_when_empty`` the step fails when nothing matches. ``timestamp`` 0 in CameraInfo means unknown: ``clock()``
    is used instead. With ``free_space`` the answer also holds the CAS's free placements, largest first.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (
        CameraInfo, PointCloud, DepthImage, QueryView, TargetTrack, PointingTarget, FreePlacement, Plane,
        *FUSED_TYPES,
    )  # fmt: skip
    outputs: ClassVar[tuple[type[CasType], ...]] = (QueryAnswer,)

    def __init__(
        self,
        store: StoreSource = None,
        *,
        tracker: BeliefTracker | None = None,
        belief_filter: BeliefFilter | None = None,
        filter_for: Callable[[object], BeliefFilter] | None = None,
        min_overlap: float = 0.6,
        fail_when_empty: bool = False,
        clock: Callable[[], float] = time.time,
        label_of: Callable[[str], str] = class_label,
        on_integrated: Callable[[TrackStep], None] | None = None,
        free_space: bool = False,
        looks_for: Callable[[str], bool] | None = None,
        name: str | None = None,
    ) -> None:
        """``looks_for``: the stored classes the tree's detectors report (None: every class); a known object of
        another class in view is not missed (a tree that finds people says nothing of the cup it did not look for)."""
        super().__init__(name=name)
        self.free_space = free_space
        self.looks_for = looks_for
        self.on_integrated = on_integrated
        """Told every frame's changes to the store once they are written (e.g. to publish them)."""
        self._store_source = store
        self._store: BeliefStore | None = store if isinstance(store, BeliefStore) else None
        self.tracker = tracker
        self.belief_filter = belief_filter
        self.filter_for = filter_for
        self.min_overlap = min_overlap
        self.fail_when_empty = fail_when_empty
        self.clock = clock
        self.label_of = label_of

    @property
    def store(self) -> BeliefStore:
        """The belief store (opened on first use)."""
        if self._store is None:
            source = self._store_source
            if callable(source) and not isinstance(source, BeliefStore):
                self._store = source()
            else:
                self._store = BeliefStore(BeliefStore.default_path() if source is None else source)
        return self._store

    def shutdown(self) -> None:
        """Close the store if this step opened it (py_trees calls this when the tree shuts down)."""
        if self._store is not None and self._store is not self._store_source:
            self._store.close()
            self._store = None

    def analyse(self) -> None:
        """Fuse, integrate, answer."""
        hypotheses = self.annotations(ObjectHypothesis)
        info = self.optional_view(CameraInfo)
        cloud = self.optional_view(PointCloud)
        depth = self.optional_view(DepthImage)
        stamp = info.timestamp if info is not None and info.timestamp > 0 else self.clock()
        context = FrameContext(
            points=cloud.points if cloud is not None else None,
            cam_to_world=info.cam_to_world if info is not None else None,
            camera_frame=info.frame_id if info is not None else "camera",
            time=stamp,
            recording=info.recording if info is not None else "",
        )
        objects = frame_objects(hypotheses, context, min_overlap=self.min_overlap, read=self.attached)
        tracks = self.annotations(TargetTrack)
        track = tracks[0] if tracks else None
        camera = None
        # a loop following one person reports only that person between its searches: its frames say nothing of
        # anything else in view, so they miss nothing
        if info is not None and not isinstance(track, PersonTrack):
            camera = camera_model(info, depth.depth if depth is not None else None, self.looks_for)
        store = self.store
        viewpoint = self._viewpoint(info)  # kept with the frame's view: memory measures selections from it
        step = store.integrate(objects, stamp, camera=camera, plane=viewpoint.plane, tracker=self.tracker)
        if self.on_integrated is not None:
            self.on_integrated(step)
        belief_filter = self._filter()
        seen = {i: o for i, o in zip(step.assigned, objects, strict=True) if i}
        if belief_filter.ids is not None:  # the query names objects (``id:``): answer only those of them seen here
            seen = {i: o for i, o in seen.items() if i in belief_filter.ids}
        tracked = _tracked_object(track, seen) if track is not None else None
        if track is not None:  # a continuous task answers with its one target
            seen = {tracked: seen[tracked]} if tracked is not None else {}
        # the store's answer for the objects seen here: the rule of the answer from memory (class_candidates)
        matching = store.query(replace(belief_filter, ids=tuple(seen), limit=None))
        selected: SelectionNote | None = None
        if belief_filter.selection is not None:  # ``the top box``: by its measure, the usual order deciding ties
            ordered = best_first(matching, replace(belief_filter, limit=None))
            matching, selected = select(ordered, belief_filter.selection, viewpoint, belief_filter.limit)
        elif belief_filter.limit is not None:  # asked for N objects: the N most likely to be what was asked
            matching = best_first(matching, belief_filter)
        else:
            matching.sort(key=lambda b: (-b.confidence, b.id))
        pointing = self._pointing(seen, info)
        if pointing is not None:  # a pointing query answers with the pointed object (none for a region)
            matching = [
                b
                for b in matching + store.query(replace(belief_filter, ids=tuple(seen), limit=None))
                if b.id == pointing.object_id
            ][:1]
        query_view = self.optional_view(QueryView)
        asked = query_view.query if query_view is not None and isinstance(query_view.query, Query) else None
        text = asked.source if asked is not None else ""
        answer = Answer(
            query=str(text or ""),
            objects=tuple(
                designator(
                    b,
                    class_test=belief_filter.class_test,
                    roi=seen[b.id].roi,
                    label_of=self.label_of,
                    asked_class=belief_filter.object_class,
                    answering=seen[b.id].answering,
                )
                for b in matching
            ),
            observed=tuple(step.assigned),
            track=None if track is None else _track_designator(track, tracked),
            pointing=pointing,
            placements=self._placements() if self.free_space else None,
            counted=asked is not None and asked.counted,
            selection=selected,
        )
        self.write(QueryAnswer(answer))
        if self.fail_when_empty and not matching:
            self.fail(f"no object matches the query among {len(objects)} seen")

    def _pointing(self, seen: dict[int, FrameObject], info: CameraInfo | None) -> PointingAnswer | None:
        """The most confident PointingTarget of this frame, with the belief of the pointed object (the object seen
        here whose image box overlaps the target's most) and the ray in the world frame when the pose is known."""
        targets = self.annotations(PointingTarget)
        if not targets:
            return None
        target = max(targets, key=lambda t: t.confidence)
        object_id = None
        if target.kind == "object" and target.roi is not None:
            overlaps = {i: _box_iou(o.roi, target.roi) for i, o in seen.items() if o.roi is not None}
            best = max(overlaps, key=lambda i: overlaps[i], default=None)
            object_id = best if best is not None and overlaps[best] > 0.5 else None
        origin, direction, frame = target.origin, target.direction, "camera"
        if info is not None and info.cam_to_world is not None:
            pose = np.asarray(info.cam_to_world, dtype=np.float64)
            origin, direction, frame = pose[:3, :3] @ origin + pose[:3, 3], pose[:3, :3] @ direction, WORLD_FRAME
        return PointingAnswer(
            kind=target.kind,
            object_id=object_id,
            region=target.name,
            angular_error_degrees=float(np.degrees(target.angular_error)),
            spread_degrees=float(np.degrees(target.spread)),
            confidence=target.confidence,
            origin=tuple(float(v) for v in origin),
            direction=tuple(float(v) for v in direction),
            frame=frame,
        )

    def _viewpoint(self, info: CameraInfo | None) -> Viewpoint:
        """Where a selection's measures are taken from: the camera pose and the frame's support plane (the plane
        with the most inliers)."""
        planes = self.annotations(Plane)
        plane = max(planes, key=lambda p: len(p.inlier_indices)).model if planes else None
        pose = info.cam_to_world if info is not None else None
        return Viewpoint(cam_to_world=None if pose is None else np.asarray(pose, dtype=np.float64), plane=plane)

    def _placements(self) -> tuple[PlacementDesignator, ...]:
        """The CAS's free placements as designators, largest first."""
        found = sorted(self.annotations(FreePlacement), key=lambda p: -p.size[0] * p.size[1])
        return tuple(
            PlacementDesignator(
                pose=PoseDesignator(
                    position=tuple(float(v) for v in p.position),  # type: ignore[arg-type]
                    orientation=tuple(float(v) for v in p.orientation),  # type: ignore[arg-type]
                    frame=p.frame,
                ),
                size=(float(p.size[0]), float(p.size[1])),
                footprint=(float(p.footprint[0]), float(p.footprint[1])),
                fits=p.fits,
                region=p.region or None,
                confidence=p.confidence,
                experts=(p.source,) if p.source else (),
            )
            for p in found
        )

    def _filter(self) -> BeliefFilter:
        if self.belief_filter is not None:
            return self.belief_filter
        query_view = self.optional_view(QueryView)
        if self.filter_for is not None and query_view is not None:
            return self.filter_for(query_view.query)
        return BeliefFilter(class_test=(self.tracker or self.store.tracker).class_test)


def _tracked_object(track: TargetTrack, seen: dict[int, FrameObject]) -> int | None:
    """The belief id of the object the tracker associated in this frame (the one whose image box overlaps the
    tracked hypothesis' box most), or None when the target was not seen."""
    if not track.seen or track.hypothesis is None:
        return None
    best, best_overlap = None, 0.0
    for belief_id, item in seen.items():
        overlap = _box_iou(track.hypothesis.roi, item.roi)
        if overlap > best_overlap:
            best, best_overlap = belief_id, overlap
    return best


def _box_iou(a: tuple[int, int, int, int], b: tuple[int, int, int, int] | None) -> float:
    if b is None:
        return 0.0
    width = min(a[2], b[2]) - max(a[0], b[0])
    height = min(a[3], b[3]) - max(a[1], b[1])
    if width <= 0 or height <= 0:
        return 0.0
    inter = width * height
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def _track_designator(track: TargetTrack, object_id: int | None) -> TrackDesignator:
    known = bool(np.all(np.isfinite(track.position)))
    return TrackDesignator(
        target=track.target,
        seen=track.seen,
        position=tuple(float(v) for v in track.position) if known else None,
        velocity=tuple(float(v) for v in track.velocity) if known else None,
        frame=track.frame,
        pixel=track.pixel,
        spread=float(track.spread) if known else None,
        unseen_for=float(track.unseen_for),
        object_id=object_id,
        tracker=track.source,
    )
