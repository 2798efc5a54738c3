"""Recording what robokudo perceives with Rerun (https://rerun.io): frames, clouds, boxes, beliefs, tree status.

:class:`RerunLog` owns one ``rerun.RecordingStream`` (never the SDK's global recording) that writes an ``.rrd`` file
and/or streams to a running viewer over gRPC. Every entry lies on two timelines: ``tick``, the engine's tick
counter, and ``frame_time``, the frame's ``CameraInfo.timestamp``. The entities:

* ``world/camera`` — the camera pose (``CameraInfo.cam_to_world``, identity when unknown: then the world is the
  camera frame); ``world/camera/image`` its pinhole from the intrinsics, so the 2-D and 3-D views line up, with
  ``color`` and ``depth`` (metres) and ``hypotheses``, the object hypotheses' image boxes and labels;
* ``world/camera/points`` — the point cloud still of interest after filtering (camera frame, at most
  :data:`MAX_CLOUD_POINTS`);
* ``world/objects`` — each hypothesis' 3-D box in the world: centre and orientation from its Pose, extents from
  its Size (or from its points along the pose's axes), labelled like the 2-D boxes;
* ``world/beliefs/<id>`` — each belief a frame changed, at its position with ``#id label``; a belief gone is
  cleared;
* ``tree`` — a text log of the tree with each node's status, written when the statuses changed.

A file that exists already is continued: its recording keeps its id, its data is kept and the ``tick`` timeline
goes on after its last tick, so ``robokudo query ... --rerun run.rrd`` run once per frame builds one recording.

:class:`TickRecorder` connects a :class:`RerunLog` to an engine: a post-tick handler logs each finished task run's
CAS once and the tree when its statuses changed; a belief listener collects the belief store's changes, logged
with the frame that caused them. With ``background=True`` (a server ticking at 30 Hz) the logging itself runs on a
worker thread; the engine thread only takes references and renders the tree text when it changed.
"""

from __future__ import annotations

import contextlib
import math
import os
import queue
import socket
import sys
import threading
import uuid
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

import numpy as np
import py_trees
import pyarrow.compute as pc
import rerun as rr
from py_trees.common import Status
from rerun.chunk import Chunk, RrdReader

from annotators.cloud.pose import hypothesis_points
from reasoning.beliefs.answer import UNKNOWN_LABEL, Answer, ObjectDesignator, designator
from reasoning.fusion.frame import WORLD_FRAME
from reasoning.fusion.tracking import ObjectBelief, TrackStep
from robokudo.application.service import AnsweringService
from robokudo.core.cas import CAS
from robokudo.core.geometry import quaternion_from_matrix, rotation_matrix
from robokudo.core.pipeline import Pipeline, finished_run_cas
from robokudo.core.render import unicode_tree
from robokudo.core.slot import Idle
from robokudo.core.types import (
    CameraInfo,
    Classification,
    ColorImage,
    DepthImage,
    ObjectHypothesis,
    PointCloud,
    Pose,
    QueryAnswer,
    SemanticColor,
    Shape,
    Size,
)

APPLICATION_ID = "robokudo"
TICK_TIMELINE = "tick"
FRAME_TIME_TIMELINE = "frame_time"

DEFAULT_VIEWER_URL = "rerun+http://127.0.0.1:9876/proxy"
"""Where a Rerun viewer started with ``rerun`` listens (the Rerun SDK's own default)."""

MAX_CLOUD_POINTS = 60_000
"""Points of the cloud logged per frame at most (evenly sampled): a full 640x480 cloud is 3.7 MB a frame."""
BOX_POINTS = 800
"""Points of a hypothesis sampled to order its Size's extents along the pose's axes."""
MATCH_IOU = 0.5
"""How much an answer object's image box must overlap a hypothesis' to lend it its ``#id label``."""
BELIEF_RADIUS = 0.02
PENDING_LIMIT = 16
"""Jobs a background recorder queues at most; a frame that would exceed it is dropped (and the drop logged)."""
VIEWER_CHECK_SECONDS = 2.0

ENTITY_CAMERA = "world/camera"
ENTITY_IMAGE = "world/camera/image"
ENTITY_COLOR = "world/camera/image/color"
ENTITY_DEPTH = "world/camera/image/depth"
ENTITY_HYPOTHESES = "world/camera/image/hypotheses"
ENTITY_POINTS = "world/camera/points"
ENTITY_OBJECTS = "world/objects"
ENTITY_BELIEFS = "world/beliefs"
ENTITY_TREE = "tree"


class RerunTargetError(Exception):
    """The recording cannot be written where asked (the file is no Rerun recording, no viewer listens, ...)."""


# ------------------------------------------------------------------------------------------- what is logged


@dataclass(frozen=True)
class ObjectBox:
    """A hypothesis' box in the world: centre, unit quaternion (x, y, z, w) and half extents along its axes."""

    centre: np.ndarray
    orientation: np.ndarray
    half_sizes: np.ndarray


@dataclass(frozen=True)
class BeliefMark:
    """A belief as the recording shows it: id, label and world position (None when it is gone or not placeable)."""

    id: int
    label: str
    position: np.ndarray | None
    roi: tuple[int, int, int, int] | None = None
    """Its image box when it was seen in the frame logged with it."""


def _iou(a: Sequence[int], b: Sequence[int]) -> float:
    width = min(a[2], b[2]) - max(a[0], b[0])
    height = min(a[3], b[3]) - max(a[1], b[1])
    if width <= 0 or height <= 0:
        return 0.0
    inter = width * height
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def _object_label(found: ObjectDesignator) -> str:
    return f"#{found.id} {found.class_label or UNKNOWN_LABEL}"


def hypothesis_labels(cas: CAS, seen: Iterable[BeliefMark] = ()) -> list[str]:
    """A label per object hypothesis: ``#id label`` of the answer object, else of the belief, seen at its image box
    (else ``hypothesis N`` and the class an expert attached), then the colour, shape and size class experts
    attached."""
    found = cas.view(QueryAnswer)
    answered = found.answer.objects if found is not None and isinstance(found.answer, Answer) else ()
    known = [(o.roi, _object_label(o)) for o in answered if o.roi is not None]
    known += [(mark.roi, mark.label) for mark in seen if mark.roi is not None]
    labels = []
    for number, hypothesis in enumerate(cas.annotations(ObjectHypothesis), start=1):
        overlap, label = max(((_iou(roi, hypothesis.roi), label) for roi, label in known), default=(0.0, ""))
        named = overlap >= MATCH_IOU
        label = label if named else f"hypothesis {number}"
        stated = (SemanticColor, Shape, Size) if named else (Classification, SemanticColor, Shape, Size)
        words = [a.attribute_value() for a in (hypothesis.first(t) for t in stated) if a is not None]
        labels.append(label + (f": {' '.join(words)}" if words else ""))
    return labels


def object_box(
    hypothesis: ObjectHypothesis, cloud: PointCloud | None, cam_to_world: np.ndarray | None
) -> ObjectBox | None:
    """The hypothesis' 3-D box in the world frame (the camera frame when the camera pose is unknown), None without
    a Pose. Its Size's extents (largest first) go to the pose's axes in the order of the points' spread along
    them; without a Size the extents are the spread itself (1 % to 99 %)."""
    pose = hypothesis.first(Pose)
    if pose is None:
        return None
    to_world = np.eye(4) if cam_to_world is None else np.asarray(cam_to_world, dtype=np.float64)
    rotation = rotation_matrix(pose.orientation)
    centre = np.asarray(pose.position, dtype=np.float64).reshape(3)
    if pose.frame != WORLD_FRAME:  # a camera-frame pose
        rotation = to_world[:3, :3] @ rotation
        centre = to_world[:3, :3] @ centre + to_world[:3, 3]
    spread = None
    if cloud is not None:
        points = hypothesis_points(cloud, hypothesis, BOX_POINTS)
        if points.shape[0] >= 3:
            local = (points @ to_world[:3, :3].T + to_world[:3, 3] - centre) @ rotation
            ordered = np.sort(local, axis=0)  # 1 % and 99 % quantiles (np.percentile costs ten times more)
            last = ordered.shape[0] - 1
            spread = ordered[round(0.99 * last)] - ordered[round(0.01 * last)]
    size = hypothesis.first(Size)
    if size is not None:
        extents = np.zeros(3)
        order = np.argsort(-spread, kind="stable") if spread is not None else np.arange(3)
        extents[order] = np.asarray(size.dimensions, dtype=np.float64)
    elif spread is not None:
        extents = spread
    else:
        return None
    return ObjectBox(centre, quaternion_from_matrix(rotation), extents / 2)


def belief_marks(
    beliefs: Iterable[ObjectBelief],
    gone: Iterable[int],
    seen: Iterable[int],
    label_of: Callable[[str], str],
    recording: str,
) -> list[BeliefMark]:
    """Marks for changed beliefs (those in another recording's camera frame cannot be placed: position None; those
    ``seen`` in this frame keep their image box) and for the ids marked gone."""
    seen = set(seen)
    marks = []
    for belief in beliefs:
        placeable = belief.frame == WORLD_FRAME or belief.recording == recording
        marks.append(
            BeliefMark(
                belief.id,
                _object_label(designator(belief, label_of=label_of)),
                np.asarray(belief.position, dtype=np.float64).reshape(3) if placeable else None,
                belief.roi if belief.id in seen else None,
            )
        )
    marks += [BeliefMark(belief_id, "", None) for belief_id in gone]
    return marks


def tree_text(root: py_trees.behaviour.Behaviour, task: py_trees.behaviour.Behaviour | None) -> tuple[str, str]:
    """The text log entry of the tree's statuses and its level: a first line with the task's status (and the
    failed nodes' messages), then the tree."""
    failed = [n for n in root.iterate() if n.status is Status.FAILURE and n.feedback_message]
    head = f"{task.name}: {task.status.name}" if task is not None else f"{root.name}: {root.status.name}"
    if failed:
        head += " — " + "; ".join(f"{n.name}: {n.feedback_message}" for n in failed)
    level = rr.TextLogLevel.ERROR if failed else rr.TextLogLevel.INFO
    return head + "\n" + unicode_tree(root, show_status=True, show_reasons=False), level


def status_signature(root: py_trees.behaviour.Behaviour, task: py_trees.behaviour.Behaviour | None) -> tuple:
    """What the tree text log follows: the task and its nodes' statuses (INVALID ones left out: nodes reset
    between runs), and every failed node. An idle slot and a perception pipeline that only reads the next frame
    change nothing, so a served tree without a task logs nothing 30 times a second."""
    watched = (
        ()
        if task is None or isinstance(task, Idle)
        else tuple((node.name, node.status) for node in task.iterate() if node.status is not Status.INVALID)
    )
    failed = tuple(node.name for node in root.iterate() if node.status is Status.FAILURE)
    return id(task), watched, failed


# ------------------------------------------------------------------------------------------------ the log


def _previous_recording(path: Path) -> tuple[str, list[Chunk], int]:
    """The recording id, the chunks and the next tick of an existing ``.rrd`` file (RerunTargetError if it is
    none)."""
    try:
        reader = RrdReader(path)
        recordings = reader.recordings()
        chunks = reader.stream().to_chunks() if recordings else []
    except (RuntimeError, ValueError, OSError) as error:
        raise RerunTargetError(f"{path} exists but is not a Rerun recording ({error}); give another file") from None
    if not recordings:
        raise RerunTargetError(f"{path} holds no Rerun recording; give another file")
    last = -1
    for chunk in chunks:
        if TICK_TIMELINE in chunk.timeline_names and chunk.num_rows:
            last = max(last, int(pc.max(chunk.to_record_batch().column(TICK_TIMELINE)).as_py()))
    return recordings[0].recording_id, chunks, last + 1


def check_viewer(url: str) -> None:
    """Raise RerunTargetError unless something accepts connections at the viewer URL's host and port."""
    parts = urlsplit(url)
    if parts.scheme not in ("rerun", "rerun+http", "rerun+https") or parts.hostname is None:
        raise RerunTargetError(f"{url!r} is no Rerun viewer URL (like {DEFAULT_VIEWER_URL})")
    port = parts.port or (80 if parts.scheme == "rerun+http" else 443)
    try:
        with socket.create_connection((parts.hostname, port), timeout=VIEWER_CHECK_SECONDS):
            pass
    except OSError as error:
        raise RerunTargetError(
            f"no Rerun viewer at {url} ({error.strerror or error}); start one with `rerun`, or record to a file"
        ) from None


class RerunLog:
    """One Rerun recording of robokudo's frames, boxes, beliefs and tree status (see the module).

    Log from one thread at a time: the timeline positions (``set_time``) are per thread.
    """

    def __init__(self, file: str | Path | None = None, viewer_url: str | None = None) -> None:
        """Record to ``file`` (continued when it exists) and/or stream to the viewer at ``viewer_url``.

        RerunTargetError when the file is not a Rerun recording or no viewer listens at the URL.
        """
        if file is None and viewer_url is None:
            raise ValueError("a Rerun log needs a file or a viewer URL")
        if viewer_url is not None:
            check_viewer(viewer_url)
        self.path = None if file is None else Path(file).expanduser()
        recording_id, previous, self.tick_offset = uuid.uuid4().hex, [], 0
        if self.path is not None and self.path.exists():
            recording_id, previous, self.tick_offset = _previous_recording(self.path)
        self._partial: Path | None = None
        sinks: list[rr.FileSink | rr.GrpcSink] = []
        if self.path is not None:
            if not self.path.parent.is_dir():
                raise RerunTargetError(f"cannot write {self.path}: no folder {self.path.parent}")
            if previous:  # rewrite beside it, replace it when done: a crash leaves the old recording intact
                self._partial = self.path.with_name(f".{self.path.name}.{os.getpid()}.part")
            sinks.append(rr.FileSink(str(self._partial or self.path)))
        if viewer_url is not None:
            sinks.append(rr.GrpcSink(viewer_url))
        self.stream = rr.RecordingStream(APPLICATION_ID, recording_id=recording_id, send_properties=not previous)
        self.stream.set_sinks(*sinks)
        if previous:
            self.stream.send_chunks(previous)
        self._last_recording: str | None = None
        self._logged = False
        self._closed = False

    # -------------------------------------------------------------- timelines

    def at(self, tick: int, frame_time: float | None) -> None:
        """Put what this thread logs next at engine tick ``tick`` (after the continued file's ticks) and, when
        known, at ``frame_time`` (seconds since the epoch)."""
        self._logged = True
        self.stream.set_time(TICK_TIMELINE, sequence=self.tick_offset + tick)
        if frame_time is not None and frame_time > 0:
            self.stream.set_time(FRAME_TIME_TIMELINE, timestamp=frame_time)

    # -------------------------------------------------------------- entities

    def log_frame(self, cas: CAS, tick: int, beliefs: Sequence[BeliefMark] = ()) -> bool:
        """Log the CAS's camera, colour, depth, cloud and hypotheses (2-D and 3-D boxes) at ``tick`` and its frame
        time, then ``beliefs`` (the changes this frame made, which also name the hypotheses); False when it holds
        no colour image (only the beliefs are logged then)."""
        camera = cas.view(CameraInfo)
        self.at(tick, camera.timestamp if camera is not None else None)
        color = cas.view(ColorImage)
        if color is None:
            self.log_beliefs(beliefs)
            return False
        cam_to_world = None if camera is None or camera.cam_to_world is None else np.asarray(camera.cam_to_world)
        log = self.stream.log
        log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP if cam_to_world is not None else rr.ViewCoordinates.RDF)
        to_world = np.eye(4) if cam_to_world is None else cam_to_world
        log(ENTITY_CAMERA, rr.Transform3D(translation=to_world[:3, 3], mat3x3=to_world[:3, :3]))
        if camera is not None and camera.intrinsics.is_valid():
            intrinsics = camera.intrinsics
            log(
                ENTITY_IMAGE,
                rr.Pinhole(
                    image_from_camera=intrinsics.matrix(),
                    resolution=[intrinsics.width, intrinsics.height],
                    camera_xyz=rr.ViewCoordinates.RDF,
                ),
            )
        log(ENTITY_COLOR, rr.Image(color.image))
        depth = cas.view(DepthImage)
        if depth is not None:
            log(ENTITY_DEPTH, rr.DepthImage(depth.depth, meter=1.0))
        cloud = cas.view(PointCloud)
        if cloud is not None:
            self._log_cloud(cloud)
        self._log_hypotheses(cas, cloud, cam_to_world, beliefs)
        recording = camera.recording if camera is not None else ""
        if cam_to_world is None and recording != self._last_recording:
            # beliefs in another recording's camera frame do not belong in this frame's space
            log(ENTITY_BELIEFS, rr.Clear(recursive=True))
        self._last_recording = recording
        self.log_beliefs(beliefs)
        return True

    def _log_cloud(self, cloud: PointCloud) -> None:
        step = max(1, math.ceil(math.sqrt(np.count_nonzero(cloud.mask) / MAX_CLOUD_POINTS)))
        mask = cloud.mask[::step, ::step]  # every step-th row and column: views, one boolean selection
        points = cloud.points[::step, ::step][mask]
        finite = np.isfinite(points).all(axis=1)
        colors = None if cloud.colors is None else cloud.colors[::step, ::step][mask][finite]
        self.stream.log(ENTITY_POINTS, rr.Points3D(points[finite], colors=colors, radii=0.002))

    def _log_hypotheses(
        self, cas: CAS, cloud: PointCloud | None, cam_to_world: np.ndarray | None, beliefs: Sequence[BeliefMark]
    ) -> None:
        hypotheses = cas.annotations(ObjectHypothesis)
        labels = hypothesis_labels(cas, beliefs)
        if not hypotheses:
            self.stream.log(ENTITY_HYPOTHESES, rr.Clear(recursive=False))
            self.stream.log(ENTITY_OBJECTS, rr.Clear(recursive=False))
            return
        ids = list(range(1, len(hypotheses) + 1))
        self.stream.log(
            ENTITY_HYPOTHESES,
            rr.Boxes2D(
                array=np.array([h.roi for h in hypotheses], dtype=np.float32),
                array_format=rr.Box2DFormat.XYXY,
                labels=labels,
                class_ids=ids,
            ),
        )
        boxes = [
            (object_box(h, cloud, cam_to_world), label, i) for h, label, i in zip(hypotheses, labels, ids, strict=True)
        ]
        placed = [(box, label, i) for box, label, i in boxes if box is not None]
        if not placed:
            self.stream.log(ENTITY_OBJECTS, rr.Clear(recursive=False))
            return
        self.stream.log(
            ENTITY_OBJECTS,
            rr.Boxes3D(
                centers=[box.centre for box, _, _ in placed],
                half_sizes=[box.half_sizes for box, _, _ in placed],
                quaternions=[rr.Quaternion(xyzw=box.orientation) for box, _, _ in placed],
                labels=[label for _, label, _ in placed],
                class_ids=[i for _, _, i in placed],
            ),
        )

    def log_beliefs(self, marks: Iterable[BeliefMark]) -> None:
        """Log changed beliefs at their positions (``world/beliefs/<id>``) and clear those without one (gone, or
        in another recording's camera frame); at the current timeline positions (:meth:`at`)."""
        for mark in marks:
            path = f"{ENTITY_BELIEFS}/{mark.id}"
            if mark.position is None:
                self.stream.log(path, rr.Clear(recursive=True))
            else:
                self.stream.log(
                    path, rr.Points3D([mark.position], labels=[mark.label], class_ids=[mark.id], radii=BELIEF_RADIUS)
                )

    def log_tree(self, text: str, level: str = rr.TextLogLevel.INFO) -> None:
        """Log the tree status text (:func:`tree_text`) at the current timeline positions (:meth:`at`)."""
        self.stream.log(ENTITY_TREE, rr.TextLog(text, level=level))

    def log_note(self, text: str) -> None:
        """A warning in the tree's text log (e.g. frames dropped by a background recorder)."""
        self.stream.log(ENTITY_TREE, rr.TextLog(text, level=rr.TextLogLevel.WARN))

    def close(self) -> None:
        """Flush, finish the file (its footer) and, when a file was continued, put it in place of the old one; a
        new file nothing was logged to is removed (a continued one stays as it was). A viewer that went away is
        reported on stderr (the file is complete all the same)."""
        if self._closed:
            return
        self._closed = True
        try:
            self.stream.flush()
        except RuntimeError as error:  # a gRPC viewer went away
            print(f"robokudo: rerun: the viewer did not get everything: {error}", file=sys.stderr, flush=True)
        with contextlib.suppress(RuntimeError):
            self.stream.disconnect()
        if self.path is not None and not self._logged:  # nothing ran (a bad query, ...): leave no empty recording
            (self._partial or self.path).unlink(missing_ok=True)
        elif self._partial is not None and self.path is not None:
            os.replace(self._partial, self.path)

    def __enter__(self) -> RerunLog:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()


# ------------------------------------------------------------------------------------ engine side


def _frame_time(cas: CAS | None) -> float | None:
    camera = cas.view(CameraInfo) if cas is not None else None
    return camera.timestamp if camera is not None and camera.timestamp > 0 else None


class TickRecorder:
    """Logs an engine's work into a :class:`RerunLog` (see the module): register :meth:`after_tick` as a post-tick
    handler (after the service's own) and :meth:`beliefs_changed` as a belief listener."""

    def __init__(
        self,
        log: RerunLog,
        *,
        task_of: Callable[[py_trees.behaviour.Behaviour], py_trees.behaviour.Behaviour | None],
        tick_of: Callable[[], int],
        perceived_of: Callable[[], CAS | None] = lambda: None,
        label_of: Callable[[str], str] = lambda name: name,
        background: bool = False,
    ) -> None:
        """``task_of(root)`` is the subtree whose runs are the frames to log (the task slot's subtree, or the root
        itself); ``tick_of()`` the engine's tick count; ``perceived_of()`` the CAS of the newest perceived frame
        (its time stamps tree entries between frames); ``label_of`` names a class for people."""
        self.log = log
        self.task_of = task_of
        self.tick_of = tick_of
        self.perceived_of = perceived_of
        self.label_of = label_of
        self._last_cas: CAS | None = None
        self._last_signature: tuple | None = None
        self._frame_time: float | None = None
        self._pending_beliefs: list[TrackStep] = []
        self._jobs: queue.Queue[Callable[[], None] | None] | None = None
        self._worker: threading.Thread | None = None
        self._dropped = 0
        self._closed = False
        if background:
            self._jobs = queue.Queue()
            self._worker = threading.Thread(target=self._work, name="robokudo-rerun", daemon=True)
            self._worker.start()

    def after_tick(self, tree: py_trees.trees.BehaviourTree) -> None:
        """Post-tick handler (engine thread): log the task run that finished this tick, and the tree when its
        statuses changed."""
        self.record(tree.root)

    def record(self, root: py_trees.behaviour.Behaviour) -> None:
        """Look at ``root`` after a tick (engine thread); see :meth:`after_tick`."""
        if self._closed:
            return
        tick = self.tick_of()
        task = self.task_of(root)
        finished = finished_run_cas(task)
        if finished is self._last_cas:
            finished = None
        running = task.cas if isinstance(task, Pipeline) else None
        self._frame_time = _frame_time(finished or running) or _frame_time(self.perceived_of()) or self._frame_time
        frame_time = self._frame_time
        signature = status_signature(root, task)
        if signature != self._last_signature:
            self._last_signature = signature
            text, level = tree_text(root, task)
            self._submit(lambda: self._log_tree(text, level, tick, frame_time))
        if finished is not None:
            self._last_cas = finished
            beliefs, self._pending_beliefs = self._pending_beliefs, []
            camera = finished.view(CameraInfo)
            recording = camera.recording if camera is not None else ""
            self._submit(lambda: self._log_frame(finished, beliefs, recording, tick), droppable=True)

    def beliefs_changed(self, step: TrackStep) -> None:
        """Belief listener (engine thread): keep the changes for the frame that caused them."""
        self._pending_beliefs.append(step)

    def _log_tree(self, text: str, level: str, tick: int, frame_time: float | None) -> None:
        self.log.at(tick, frame_time)
        self.log.log_tree(text, level)

    def _log_frame(self, cas: CAS, steps: list[TrackStep], recording: str, tick: int) -> None:
        marks = [
            mark
            for step in steps
            for mark in belief_marks(step.changed, step.gone, step.assigned, self.label_of, recording)
        ]
        self.log.log_frame(cas, tick, marks)

    def _submit(self, job: Callable[[], None], *, droppable: bool = False) -> None:
        if self._jobs is None:
            job()
            return
        if droppable and self._jobs.qsize() >= PENDING_LIMIT:
            self._dropped += 1
            return
        self._jobs.put(job)

    def _work(self) -> None:
        assert self._jobs is not None
        while (job := self._jobs.get()) is not None:
            try:
                job()
            except Exception as error:  # a frame the SDK refuses must not end the recording
                print(f"robokudo: rerun: {type(error).__name__}: {error}", file=sys.stderr, flush=True)
            if self._dropped:
                dropped, self._dropped = self._dropped, 0
                self.log.log_note(f"the recorder fell behind: {dropped} frame(s) not recorded")

    def close(self) -> None:
        """Log what is still queued, then close the log; later ticks are not recorded."""
        self._closed = True
        if self._jobs is not None and self._worker is not None:
            self._jobs.put(None)
            self._worker.join()
            self._jobs = None
        self.log.close()


def service_recorder(log: RerunLog, service: AnsweringService, *, background: bool = False) -> TickRecorder:
    """A recorder of an answering service's engine: its task slot's runs, its perception's newest frame for the
    time stamps, its knowledge base's class labels. Register its handlers with the service's engine and belief
    store (``robokudo query`` and ``robokudo serve`` do)."""
    perception = service.perception
    return TickRecorder(
        log,
        task_of=lambda _: service.task_tree,
        tick_of=lambda: service.engine.tick_count,
        perceived_of=(lambda: perception.cas) if perception is not None else (lambda: None),
        label_of=service.kb.label,
        background=background,
    )
