"""The paper's storage mission on one running engine: four queries in sequence, swapped into the task slot at
run time, on the built-in kitchen with a scripted person.

One :class:`~robokudo.application.service.AnsweringService` serves the whole mission over a live kitchen camera
(:class:`~annotators.readers.streams.KitchenCameraStream`): its engine ticks in the background (perceive, then the
task slot, the paper's Fig. 4) and every goal below is submitted to it and replaces the previous one. Per run:

1. **detect** the table objects (one-shot; the camera looks at the table);
2. **watch** the person until she points at one of them: the pointing query is asked again and again (each a
   one-shot goal that fails while she does not point) until it names an object; the person keeps pointing until
   the robot acknowledged (the camera looks at the table and the person);
3. she grasps the object (a grasp event: it is gone from the table) and walks to the storage region: the robot
   **follows** her with a continuous track goal until the track shows her standing still, then **watches where
   she points** (the region pointing query, again until answered);
4. **free space** on the region she pointed at (``scan { free_space: { region, footprint } }``, the footprint from
   the pointed object's believed size; the camera looks at the region); she puts the object on the largest
   placement (a place event) and a second scan must not report the place it now takes.

The camera follows the service's view policy: a query naming a region looks at it, a query about the person
looks at the table and the person behind it (the person view sees her walk to the fridge); that is the scripted
head motion between phases. The person's script advances in wall-clock time, so a slow machine sees fewer frames
of her walk. Ground truth (the scripts' poses, the scene's objects) is read only to score
(:mod:`.scoring`); the robot's decisions use its answers only.
"""

from __future__ import annotations

import math
import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import py_trees
from py_trees.common import Status

from annotators.cloud.free_space import DEFAULT_CLEARANCE_M
from annotators.readers.streams import KitchenCameraStream
from annotators.simulation.kitchen_person import PersonPose
from annotators.simulation.kitchen_scene import FRIDGE_SHELF_HEIGHTS, SceneObject, kitchen_albedos, kitchen_objects
from annotators.simulation.storage import footprint_in_view, free_spots, shelf_occupants
from reasoning.beliefs.answer import Answer
from robokudo.application.scenario.scoring import (
    FollowSample,
    FreeSpaceRecord,
    GoalRecord,
    Placement,
    RunRecord,
)
from robokudo.application.scenario.setup import TABLE_OBJECTS, RunSetup
from robokudo.application.service import AnsweringService, TaskHandle, TickProgress
from robokudo.core.annotator import Annotator
from robokudo.core.geometry import rotation_matrix
from robokudo.core.types import CameraInfo, QueryAnswer

DETECT_QUERY = "find objects on the table"
POINTING_OBJECT_QUERY = "which object is the person pointing at"
POINTING_REGION_QUERY = "where is the person pointing"
TRACK_QUERY = "track the person"

NOT_A_PERCEPTION_FAILURE = frozenset({"answered", "cancelled", "replaced by another task", "the service closed"})
"""How a one-shot goal may end without an answer that is no perception failure (for a goal that must answer or
fail with the failed experts' reasons, these are process-handling failures)."""

GOAL_TIMEOUT_S = 60.0
"""A one-shot goal that has not ended after this long hangs (a process-handling failure)."""
WATCH_TIMEOUT_S = 40.0
"""How long the robot watches for a pointing gesture before it gives up."""
FOLLOW_TIMEOUT_S = 40.0
"""How long the robot follows at most."""
STILL_WINDOW_S = 1.2
STILL_RADIUS_M = 0.08
"""The track shows her standing when its positions over the last ``STILL_WINDOW_S`` seconds (frame time) lie
within ``STILL_RADIUS_M`` of their mean."""
DEFAULT_FOOTPRINT_M = 0.12
"""The footprint's side when the pointed object's size is unknown."""
FOOTPRINT_MARGIN_M = 0.02


def body_centre(pose: PersonPose) -> tuple[float, float, float]:
    """Ground truth: the middle of her hips and shoulders."""
    names = ("left_hip", "right_hip", "left_shoulder", "right_shoulder")
    centre = np.mean([pose.joint(n) for n in names], axis=0)
    return (float(centre[0]), float(centre[1]), float(centre[2]))


@dataclass
class ExpertTimes:
    """Per-expert run times (ms) collected from the engine's timing records of every goal's tree."""

    samples: dict[str, list[float]] = field(default_factory=lambda: defaultdict(list))

    def add_tree(self, tree: py_trees.behaviour.Behaviour) -> None:
        """Add the runs of every annotator in a finished goal's tree (by class)."""
        for node in tree.iterate():
            if isinstance(node, Annotator):
                self.samples[type(node).__name__].extend(s * 1e3 for s in node.stats.samples)


class StorageMission:
    """Runs the mission (see the module) on ``service``, whose stream is ``stream``; one :meth:`run` per setup."""

    def __init__(self, service: AnsweringService, stream: KitchenCameraStream) -> None:
        if service.stream is not stream:
            raise ValueError("the mission needs the service that serves its kitchen camera stream")
        self.service = service
        self.stream = stream
        self.times = ExpertTimes()

    # ------------------------------------------------------------------ one run
    def run(self, setup: RunSetup, log: Callable[[str], None] = lambda _: None) -> RunRecord:
        """Play one run and record what the robot reported beside the ground truth."""
        record = RunRecord(seed=setup.seed, target=setup.target, region=setup.region)
        record.table_truth = {
            o.name: tuple(float(v) for v in o.position) for o in kitchen_objects() if o.name in TABLE_OBJECTS
        }
        self.stream.stage(setup.standing(), setup.layout.extra())
        try:
            self._detect(record)
            log(f"  detected {len(record.detected)} objects on the table")
            self.stream.play(setup.pointing_at_object())
            self._watch_object(record)
            log(f"  she points at object {record.pointed_object} (truth: {setup.target})")
            grasped = self.stream.grasp(setup.target)
            self.stream.play(setup.walking_to_storage())
            self._follow(record)
            log(f"  followed her over {len(record.follow)} frames ({record.follow_ended})")
            self._watch_region(record)
            log(f"  she points at region {record.pointed_region} (truth: {setup.region})")
            self._free_space(record, grasped)
        except Exception as error:  # any error is a process-handling failure of this run
            record.error = f"{type(error).__name__}: {error}"
            self.service.cancel()
        return record

    # ------------------------------------------------------------------ goals
    def _one_shot(self, record: RunRecord, phase: str, query: str, *, may_fail: bool) -> Answer | None:
        """Submit a one-shot goal and wait for it; its answer (None when it failed). A perception failure is
        expected when ``may_fail`` (a watch that goes on)."""
        handle = self.service.submit(query)
        ended = handle.wait(GOAL_TIMEOUT_S)
        if not ended:
            handle.cancel()
        answer = handle.result
        reason = handle.reason if ended else f"hung for {GOAL_TIMEOUT_S:g} s"
        failed_with_reason = reason not in NOT_A_PERCEPTION_FAILURE and not reason.startswith("timed out")
        expected = ended and (answer is not None or (may_fail and failed_with_reason))
        ended_as = "answered" if answer is not None else reason
        record.goals.append(GoalRecord(phase, query, ended_as, expected, _ran(handle)))
        self.times.add_tree(handle.tree)
        return answer

    def _detect(self, record: RunRecord) -> None:
        answer = self._one_shot(record, "detect", DETECT_QUERY, may_fail=False)
        for obj in answer.objects if answer is not None else ():
            record.detected[obj.id] = tuple(float(v) for v in obj.pose.position)

    def _watch(self, record: RunRecord, phase: str, query: str, kind: str) -> Answer | None:
        """Ask ``query`` until it names a pointing target of ``kind`` (or the watch times out)."""
        deadline = time.monotonic() + WATCH_TIMEOUT_S
        while time.monotonic() < deadline:
            answer = self._one_shot(record, phase, query, may_fail=True)
            if answer is not None and answer.pointing is not None and answer.pointing.kind == kind:
                return answer
        record.notes.append(f"{phase}: no pointing seen within {WATCH_TIMEOUT_S:g} s")
        return None

    def _watch_object(self, record: RunRecord) -> None:
        answer = self._watch(record, "watch (object)", POINTING_OBJECT_QUERY, "object")
        if answer is None or answer.pointing is None:
            return
        record.pointed_object = answer.pointing.object_id
        for obj in answer.objects:
            if obj.id == answer.pointing.object_id:
                record.pointed_position = tuple(float(v) for v in obj.pose.position)
                record.pointed_size = obj.size

    def _watch_region(self, record: RunRecord) -> None:
        answer = self._watch(record, "watch (region)", POINTING_REGION_QUERY, "region")
        if answer is not None and answer.pointing is not None:
            record.pointed_region = answer.pointing.region

    def _follow(self, record: RunRecord) -> None:
        """Track her until the track shows her standing still; each run's position beside the frame's truth."""
        samples: list[FollowSample] = []
        holder: list[TaskHandle] = []
        last_stamp = [0.0]

        def heard(_: TickProgress) -> None:  # engine thread: read this run's answer and frame
            if not holder:
                return
            pipeline = holder[0].pipeline
            if pipeline.status is not Status.SUCCESS:
                return
            info = pipeline.cas.view(CameraInfo)
            found = pipeline.cas.view(QueryAnswer)
            if info is None or found is None or info.timestamp == last_stamp[0]:
                return
            last_stamp[0] = info.timestamp
            answer = found.answer
            pose = self.stream.pose_at_stamp(info.timestamp)
            track = getattr(answer, "track", None)
            if pose is None or track is None:
                return
            samples.append(FollowSample(info.timestamp, track.seen, track.position, body_centre(pose)))

        handle = self.service.submit(TRACK_QUERY, on_tick=heard)
        holder.append(handle)
        started = time.monotonic()
        while not handle.done and time.monotonic() - started < FOLLOW_TIMEOUT_S:
            time.sleep(0.05)
            if _standing(list(samples)):
                break
        ended_by_robot = not handle.done
        handle.cancel()
        handle.wait(GOAL_TIMEOUT_S)
        record.follow = list(samples)
        record.follow_ended = handle.reason
        expected = (ended_by_robot and handle.reason == "cancelled") or handle.reason.startswith("target lost")
        record.goals.append(GoalRecord("follow", TRACK_QUERY, handle.reason, expected, _ran(handle)))
        self.times.add_tree(handle.tree)

    def _free_space(self, record: RunRecord, grasped: SceneObject) -> None:
        """Scan the pointed region for room for the pointed object, put the object on the largest placement and
        scan again."""
        region = record.pointed_region
        if region is None:
            record.notes.append("free space: no storage region was pointed at")
            return
        size = record.pointed_size
        side = DEFAULT_FOOTPRINT_M if not size else max(size[0], size[1]) + FOOTPRINT_MARGIN_M
        footprint = (side, side)
        query = f"scan {{ free_space: {{ region: {region}, footprint: [{side * 100:.0f}cm, {side * 100:.0f}cm] }} }}"
        first = self._scan(record, query, footprint)
        if not first:
            return
        obj = grasped
        best = first[0]  # the largest
        axes = np.asarray(best.axes)
        yaw = math.atan2(axes[1, 0], axes[0, 0])
        pose = np.eye(4)
        c, s = math.cos(yaw), math.sin(yaw)
        pose[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
        pose[:3, 3] = (best.centre[0], best.centre[1], FRIDGE_SHELF_HEIGHTS[0] + obj.size[2] / 2)
        self.stream.place(replace(obj, pose=pose, region=region), kitchen_albedos()[obj.name])
        self._scan(record, query, footprint, phase="free space (after placing)")

    def _scan(
        self, record: RunRecord, query: str, footprint: tuple[float, float], phase: str = "free space"
    ) -> tuple[Placement, ...]:
        occupants = shelf_occupants(self.stream.ground_truth())
        answer = self._one_shot(record, phase, query, may_fail=False)
        placements = tuple(
            Placement(
                tuple(float(v) for v in p.pose.position),
                tuple(tuple(float(v) for v in row) for row in rotation_matrix(p.pose.orientation)),
                (float(p.size[0]), float(p.size[1])),
            )
            for p in (answer.placements or () if answer is not None else ())
        )
        scene = self.stream.last_scene  # ground truth of the view the scan looked from, for scoring only
        room = 0
        if scene is not None:
            # room the estimator promises to find: the footprint with the clearance it keeps from obstacles on
            # every side, free and wholly in view
            grown = tuple(side + 2 * DEFAULT_CLEARANCE_M for side in footprint)
            room = sum(footprint_in_view(spot, grown, scene) for spot in free_spots(occupants, grown))
        record.free_space.append(FreeSpaceRecord(placements, occupants, footprint, answer is not None, room))
        return placements


def _ran(handle: TaskHandle) -> bool:
    """Whether the goal's tree ran in the task slot (the swap worked)."""
    return handle.first_tick is not None


def _standing(samples: list[FollowSample]) -> bool:
    """Whether the track's positions over the last ``STILL_WINDOW_S`` s lie within ``STILL_RADIUS_M`` of their
    mean (judged from the robot's answers only)."""
    seen = [s for s in samples if s.seen and s.tracked is not None]
    if len(seen) < 3 or seen[-1].stamp - seen[0].stamp < STILL_WINDOW_S:
        return False
    window = [s for s in seen if s.stamp >= seen[-1].stamp - STILL_WINDOW_S]
    if len(window) < 3:
        return False
    points = np.array([s.tracked for s in window])
    return bool(np.all(np.linalg.norm(points - points.mean(axis=0), axis=1) <= STILL_RADIUS_M))
