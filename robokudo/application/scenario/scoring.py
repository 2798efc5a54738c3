"""Scoring a run of the storage scenario against the scene's ground truth (the paper's Table I criteria).

A :class:`RunRecord` holds what the robot reported (the answers of its goals) beside the ground truth of the
frames they were about; :func:`score_run` turns it into the four verdicts:

* **pointing**: the object she pointed at is a detected table object (its belief came from phase 1) whose believed
  position lies nearest the pointed object's true position among the table objects, and the region she pointed
  at is the true storage region;
* **following**: the track goal was followed until the robot ended it (cancelled, never lost), every tracked
  position was seen and within ``tolerance`` of her body's centre in that frame (3-D), with at least
  :data:`MIN_FOLLOW_SAMPLES` positions;
* **free space**: every placement reported - before and after the place event - is free in the scene's geometry
  (blocked ones are not reported), and some placement is reported whenever the camera saw room for the
  footprint on the shelf;
* **process handling**: every goal ended as expected (answered, a perception failure with its reason for a watch
  that goes on, cancelled by the robot for the track), every goal's tree ran in the task slot (the swap worked)
  and nothing raised.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from annotators.simulation.kitchen_scene import SceneObject
from annotators.simulation.storage import free_on_shelf

MIN_FOLLOW_SAMPLES = 3
"""A follow phase with fewer tracked positions than this did not follow anything."""

DEFAULT_FOLLOW_TOLERANCE = 0.3
"""Metres between a tracked position and the body's centre still counted as following (the figure's torso is
0.34 m wide and 0.22 m deep)."""


@dataclass(frozen=True)
class GoalRecord:
    """One goal the robot sent: the phase, the query, how it ended, whether that was expected and whether its tree
    ran in the task slot."""

    phase: str
    query: str
    ended: str
    expected: bool
    ran: bool


@dataclass(frozen=True)
class FollowSample:
    """One tracked position (world) with the ground truth of the same frame (the body's centre)."""

    stamp: float
    seen: bool
    tracked: tuple[float, float, float] | None
    truth: tuple[float, float, float]

    @property
    def error(self) -> float:
        """Distance (m) between the tracked position and the truth (infinite without a position)."""
        if self.tracked is None:
            return float("inf")
        return float(np.linalg.norm(np.subtract(self.tracked, self.truth)))


@dataclass(frozen=True)
class Placement:
    """A reported free placement: centre (world), axes (3x3, columns x, y, z) and free size (m)."""

    centre: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], ...]
    size: tuple[float, float]


@dataclass(frozen=True)
class FreeSpaceRecord:
    """A free-space answer with the shelf's ground truth at the time: the objects on it and the footprint asked."""

    placements: tuple[Placement, ...]
    occupants: tuple[SceneObject, ...]
    footprint: tuple[float, float]
    answered: bool
    room_in_view: int = 0
    """Ground truth: how many positions (1 cm apart) on the shelf hold the footprint with the free-space
    estimator's clearance around it, free and wholly in view."""


@dataclass
class RunRecord:
    """Everything one run reported and the ground truth to score it (see the module)."""

    seed: int
    target: str
    region: str
    table_truth: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    """True positions of the table objects (name -> world point)."""
    detected: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    """Phase 1: belief id -> believed position of the objects detected on the table."""
    pointed_object: int | None = None
    pointed_position: tuple[float, float, float] | None = None
    pointed_size: tuple[float, float, float] | None = None
    pointed_region: str | None = None
    follow: list[FollowSample] = field(default_factory=list)
    follow_ended: str = ""
    free_space: list[FreeSpaceRecord] = field(default_factory=list)
    goals: list[GoalRecord] = field(default_factory=list)
    error: str = ""
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class RunScore:
    """The four verdicts of one run, and why a failed one failed."""

    pointing: bool
    following: bool
    free_space: bool
    process: bool
    why: tuple[str, ...] = ()


def pointing_correct(record: RunRecord) -> tuple[bool, str]:
    """Whether she was understood: the pointed object is a detected one nearest the true target, and the region."""
    if record.pointed_object is None or record.pointed_position is None:
        return False, "no pointed object"
    if record.pointed_object not in record.detected:
        return False, f"pointed object {record.pointed_object} was not detected on the table in phase 1"
    if not record.table_truth:
        return False, "no ground truth"
    nearest = min(
        record.table_truth,
        key=lambda name: float(np.linalg.norm(np.subtract(record.table_truth[name], record.pointed_position))),
    )
    if nearest != record.target:
        return False, f"pointed at {nearest}, not {record.target}"
    if record.pointed_region != record.region:
        return False, f"pointed region {record.pointed_region}, not {record.region}"
    return True, ""


def following_correct(record: RunRecord, tolerance: float = DEFAULT_FOLLOW_TOLERANCE) -> tuple[bool, str]:
    """Whether she was followed: never lost, every position within ``tolerance`` of the truth."""
    if record.follow_ended != "cancelled":
        return False, f"the track ended: {record.follow_ended or 'never'}"
    if len(record.follow) < MIN_FOLLOW_SAMPLES:
        return False, f"only {len(record.follow)} tracked positions"
    unseen = sum(not s.seen for s in record.follow)
    if unseen:
        return False, f"not seen in {unseen} of {len(record.follow)} frames"
    worst = max(s.error for s in record.follow)
    if worst > tolerance:
        return False, f"tracked up to {worst:.2f} m from her (tolerance {tolerance:g} m)"
    return True, ""


def free_space_correct(record: RunRecord) -> tuple[bool, str]:
    """Whether every reported placement is free and some is reported when there is room."""
    if not record.free_space:
        return False, "no free-space answer"
    for index, scan in enumerate(record.free_space):
        if not scan.answered:
            return False, f"scan {index + 1} was not answered"
        for placement in scan.placements:
            axes = np.asarray(placement.axes, dtype=np.float64)
            if not free_on_shelf(scan.occupants, np.asarray(placement.centre), axes, placement.size):
                return False, f"scan {index + 1} reported a blocked place at {np.round(placement.centre, 3).tolist()}"
        if not scan.placements and scan.room_in_view:
            return False, f"scan {index + 1} reported no place, though the camera saw room on the shelf"
    return True, ""


def process_correct(record: RunRecord) -> tuple[bool, str]:
    """Whether every goal ended as expected, every swap worked and nothing raised."""
    if record.error:
        return False, record.error
    if not record.goals:
        return False, "no goal was sent"
    for goal in record.goals:
        if not goal.ran:
            return False, f"the {goal.phase} goal's tree never ran ({goal.ended})"
        if not goal.expected:
            return False, f"the {goal.phase} goal ended unexpectedly: {goal.ended}"
    return True, ""


def score_run(record: RunRecord, tolerance: float = DEFAULT_FOLLOW_TOLERANCE) -> RunScore:
    """The four verdicts of ``record`` (see the module)."""
    verdicts = (
        pointing_correct(record),
        following_correct(record, tolerance),
        free_space_correct(record),
        process_correct(record),
    )
    names = ("pointing", "following", "free space", "process")
    why = tuple(f"{name}: {reason}" for name, (ok, reason) in zip(names, verdicts, strict=True) if not ok)
    return RunScore(*(ok for ok, _ in verdicts), why=why)


def success_counts(scores: Sequence[RunScore]) -> dict[str, int]:
    """How many runs succeeded per criterion."""
    return {
        "pointing": sum(s.pointing for s in scores),
        "following": sum(s.following for s in scores),
        "free space": sum(s.free_space for s in scores),
        "process handling": sum(s.process for s in scores),
    }
