"""A person in the built-in kitchen: an articulated figure of capsules with scripted motions.

The figure (1.75 m, skin-coloured head and hands, shirt, trousers, shoes) is posed by a :class:`Posture`: where
it stands, which way it faces, and what its right arm does (hang, point at a world point, wave). A
:class:`PersonScript` is a sequence of timed :class:`Motion` segments (stand, point at a table object, walk
along a path, point at a region) and gives the :class:`PersonPose` at any time ``t``: the world positions of
its joints, named as mediapipe names its landmarks, and the ground-truth target it points at.

The ground truth (joints, target) is for scoring only: the perception path sees the figure in the rendered
colour and depth (``render_kitchen(..., person=pose)``) and nothing else. Without a person the kitchen renders
exactly as before.

A person spec (``person_spec_pose``) names a posture in one word for command lines and plan parameters:
``stand``, ``wave``, ``point:<object or region>``, each optionally ``@x,y`` (where the person stands) —
e.g. ``point:red_cup@0.3,0.75``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from annotators.simulation.kitchen_map import map_regions

__all__ = (
    "PERSON_OBJECT_ID",
    "PERSON_VIEWS",
    "Motion",
    "PersonPose",
    "PersonScript",
    "Posture",
    "person_meshes",
    "person_spec_pose",
    "person_view",
    "pose_person",
)

FloatArray = NDArray[np.float64]
Mesh = tuple[NDArray[np.float32], NDArray[np.uint32]]

PERSON_OBJECT_ID: int = 100
"""The person's id in ``RenderedScene.object_ids`` (ground truth only)."""

PERSON_VIEWS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "person": ((0.0, -1.6, 1.65), (0.0, 0.3, 1.05)),
    "room": ((0.0, -2.35, 1.65), (0.0, 0.3, 0.95)),
}
"""Eye and target of the cameras that see the table and a person behind it: ``person`` near (the table objects
within 2.5 m), ``room`` farther back (more of the floor in view, which the depth people detector stands people
on)."""

DEFAULT_SPOT: tuple[float, float] = (0.0, 0.7)
"""Where the person stands by default: behind the table, facing the robot (-y)."""

SKIN = (214, 160, 128)
SHIRT = (46, 120, 84)
TROUSERS = (44, 48, 70)
SHOES = (30, 26, 24)
HAIR = (48, 34, 24)
EYES = (24, 20, 18)
LIPS = (150, 60, 60)

# body measures (metres): heights above the floor and half-widths
_ANKLE, _KNEE, _HIP, _SHOULDER, _NECK, _HEAD = 0.09, 0.50, 0.93, 1.43, 1.52, 1.64
_HIP_HALF, _SHOULDER_HALF = 0.10, 0.19
_UP = np.array([0.0, 0.0, 1.0])
_UPPER_ARM, _FOREARM = 0.29, 0.26
_HEAD_RADIUS = 0.105


def person_view(name: str = "person") -> FloatArray:
    """cam_to_world of a camera of ``PERSON_VIEWS`` (default: the near one)."""
    from annotators.simulation.kitchen_scene import look_at  # the scene imports this module

    if name not in PERSON_VIEWS:
        raise ValueError(f"unknown person view {name!r}; known: {', '.join(PERSON_VIEWS)}")
    return look_at(*PERSON_VIEWS[name])


@dataclass(frozen=True)
class Posture:
    """Where the person stands (x, y on the floor), the direction it faces (yaw, radians, 0 = +x) and what its
    arms do: ``"hang"``, ``"point"`` (at ``target``, a world point, with the arm on the target's side) or
    ``"wave"`` (the right hand; ``phase`` in radians swings the forearm)."""

    x: float
    y: float
    yaw: float
    arm: str = "hang"
    target: tuple[float, float, float] | None = None
    phase: float = 0.0

    def __post_init__(self) -> None:
        if self.arm not in ("hang", "point", "wave"):
            raise ValueError(f"arm must be hang, point or wave, not {self.arm!r}")
        if self.arm == "point" and self.target is None:
            raise ValueError("a pointing posture needs a target point")


@dataclass(frozen=True, eq=False)
class PersonPose:
    """The figure at one instant: joint world positions (mediapipe landmark names plus ``head`` and ``neck``),
    the activity (``standing``, ``pointing``, ``waving``, ``walking``) and, when pointing, the target's name and
    world point. Ground truth for scoring only."""

    joints: Mapping[str, FloatArray]
    activity: str
    target_name: str = ""
    target_point: FloatArray | None = None
    posture: Posture | None = None

    def joint(self, name: str) -> FloatArray:
        """The world position of joint ``name`` (KeyError listing the joints when unknown)."""
        if name not in self.joints:
            raise KeyError(f"unknown joint {name!r}; known: {', '.join(self.joints)}")
        return self.joints[name]

    @property
    def position(self) -> FloatArray:
        """Where the person stands: the point on the floor below the hips' midpoint."""
        mid = (self.joints["left_hip"] + self.joints["right_hip"]) / 2
        return np.array([mid[0], mid[1], 0.0])


def pose_person(posture: Posture, activity: str | None = None, target_name: str = "") -> PersonPose:
    """The joints of the figure in ``posture``."""
    forward = np.array([math.cos(posture.yaw), math.sin(posture.yaw), 0.0])
    left = np.array([-forward[1], forward[0], 0.0])  # the person's left (forward x up)
    up = np.array([0.0, 0.0, 1.0])
    base = np.array([posture.x, posture.y, 0.0])

    def at(height: float, side: float = 0.0, ahead: float = 0.0) -> FloatArray:
        return base + height * up + side * left + ahead * forward

    joints: dict[str, FloatArray] = {}
    for sign, side in ((1.0, "left"), (-1.0, "right")):
        joints[f"{side}_hip"] = at(_HIP, sign * _HIP_HALF)
        joints[f"{side}_knee"] = at(_KNEE, sign * _HIP_HALF, 0.01)
        joints[f"{side}_ankle"] = at(_ANKLE, sign * _HIP_HALF)
        joints[f"{side}_heel"] = at(0.03, sign * _HIP_HALF, -0.05)
        joints[f"{side}_foot_index"] = at(0.02, sign * _HIP_HALF, 0.14)
        joints[f"{side}_shoulder"] = at(_SHOULDER, sign * _SHOULDER_HALF)
        joints[f"{side}_ear"] = at(_HEAD, sign * 0.095, -0.01)
        joints[f"{side}_eye"] = at(_HEAD + 0.03, sign * 0.035, 0.09)
        joints[f"{side}_mouth"] = at(_HEAD - 0.05, sign * 0.025, 0.095)
    joints["neck"] = at(_NECK)
    joints["head"] = at(_HEAD)
    joints["nose"] = at(_HEAD, 0.0, 0.11)
    # both arms hang, then the posture moves one: a pointing arm is the one on the target's side, a waving one
    # the right
    for sign, side in ((1.0, "left"), (-1.0, "right")):
        joints[f"{side}_elbow"] = at(_SHOULDER - _UPPER_ARM, sign * (_SHOULDER_HALF + 0.03))
        joints[f"{side}_wrist"] = at(_SHOULDER - _UPPER_ARM - _FOREARM, sign * (_SHOULDER_HALF + 0.04), 0.03)
    if posture.arm == "point":
        target = np.asarray(posture.target, dtype=np.float64)
        side = "left" if np.dot(target - base, left) > 0 else "right"
        shoulder = joints[f"{side}_shoulder"]
        direction = _unit(target - shoulder)
        joints[f"{side}_elbow"] = shoulder + _UPPER_ARM * direction
        joints[f"{side}_wrist"] = shoulder + (_UPPER_ARM + _FOREARM) * direction
    elif posture.arm == "wave":
        shoulder = joints["right_shoulder"]
        elbow = shoulder + _UPPER_ARM * _unit(-0.85 * left + 0.5 * up + 0.15 * forward)
        swing = 0.5 * math.sin(posture.phase)
        forearm = _unit(math.sin(swing) * -left + math.cos(swing) * up)
        joints["right_elbow"] = elbow
        joints["right_wrist"] = elbow + _FOREARM * forearm
    for side in ("left", "right"):
        elbow, wrist = joints[f"{side}_elbow"], joints[f"{side}_wrist"]
        joints[f"{side}_index"] = wrist + 0.08 * _unit(wrist - elbow)
    name = activity or {"point": "pointing", "wave": "waving"}.get(posture.arm, "standing")
    target = None if posture.target is None or posture.arm != "point" else np.asarray(posture.target, float)
    return PersonPose(joints, name, target_name if target is not None else "", target, posture)


def _unit(v: FloatArray) -> FloatArray:
    return v / np.linalg.norm(v)


# ----------------------------------------------------------------------------------------------- meshes
def _capsule(a: FloatArray, b: FloatArray, radius: float, flat: float = 1.0, side: FloatArray | None = None) -> Mesh:
    """A closed capsule from ``a`` to ``b``; its cross-section is an ellipse with half-axes ``radius`` along
    ``side`` (default any horizontal direction) and ``flat * radius`` across it."""
    rings, segments = 8, 20
    axis = np.asarray(b, float) - np.asarray(a, float)
    length = float(np.linalg.norm(axis))
    z = axis / length if length > 1e-9 else np.array([0.0, 0.0, 1.0])
    x = side if side is not None else (np.cross(z, [0.0, 0.0, 1.0]) if abs(z[2]) < 0.99 else np.array([1.0, 0, 0]))
    x = np.asarray(x, float) - np.dot(x, z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    angles = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    polar = np.linspace(-np.pi / 2, np.pi / 2, 2 * rings + 1)  # south pole .. north pole
    rows = []
    for k, p in enumerate(polar):
        offset = (0.0 if k <= rings else length) + radius * math.sin(p)
        r = radius * math.cos(p)
        ring = (
            np.asarray(a, float) + offset * z + np.outer(r * np.cos(angles), x) + np.outer(flat * r * np.sin(angles), y)
        )
        rows.append(ring)
        if k == rings:  # duplicate the equator: the cylinder part joins the two hemispheres
            rows.append(ring + length * z)
    vertices = np.vstack(rows)
    faces = []
    count = len(rows)
    for i in range(count - 1):
        s = np.arange(segments)
        t = (s + 1) % segments
        lo, hi = i * segments, (i + 1) * segments
        faces.append(np.stack([lo + s, lo + t, hi + s], 1))
        faces.append(np.stack([lo + t, hi + t, hi + s], 1))
    return vertices.astype(np.float32), np.vstack(faces).astype(np.uint32)


def person_meshes(pose: PersonPose) -> list[tuple[Mesh, tuple[int, int, int]]]:
    """The figure's meshes with their colours, in world coordinates."""
    j = pose.joints
    parts: list[tuple[Mesh, tuple[int, int, int]]] = []
    hips = (j["left_hip"] + j["right_hip"]) / 2
    shoulders = (j["left_shoulder"] + j["right_shoulder"]) / 2
    lateral = _unit(j["left_shoulder"] - j["right_shoulder"])
    parts.append((_capsule(hips + 0.02 * _UP, shoulders - 0.03 * _UP, 0.17, 0.65, lateral), SHIRT))
    parts.append((_capsule(j["neck"] - 0.05 * _UP, j["head"] - 0.06 * _UP, 0.05), SKIN))
    head_lo, head_hi = j["head"] - 0.03 * _UP, j["head"] + 0.03 * _UP
    parts.append((_capsule(head_lo, head_hi, _HEAD_RADIUS, 1.05, lateral), SKIN))
    back = _unit(j["head"] - j["nose"]) * 0.02
    parts.append((_capsule(head_hi + back, head_hi + back + 0.01 * _UP, _HEAD_RADIUS * 0.98, 1.05, lateral), HAIR))
    ahead = _unit(j["nose"] - j["head"])
    for side in ("left", "right"):  # a face, so front and back (and thus left and right) can be told apart
        eye = j[f"{side}_eye"]
        parts.append((_capsule(eye - 0.012 * lateral, eye + 0.012 * lateral, 0.014), EYES))
        brow = eye + 0.028 * _UP + 0.004 * ahead
        parts.append((_capsule(brow - 0.018 * lateral, brow + 0.018 * lateral, 0.007), HAIR))
    parts.append((_capsule(j["left_mouth"] + 0.004 * ahead, j["right_mouth"] + 0.004 * ahead, 0.011), LIPS))
    parts.append((_capsule(j["nose"] - 0.03 * ahead + 0.025 * _UP, j["nose"] - 0.005 * ahead, 0.016), SKIN))
    for side in ("left", "right"):
        parts.append((_capsule(j[f"{side}_shoulder"], j[f"{side}_elbow"], 0.048), SHIRT))
        parts.append((_capsule(j[f"{side}_elbow"], j[f"{side}_wrist"], 0.038), SKIN))
        parts.append((_capsule(j[f"{side}_wrist"], j[f"{side}_index"], 0.03), SKIN))
        parts.append((_capsule(j[f"{side}_hip"], j[f"{side}_knee"], 0.07), TROUSERS))
        parts.append((_capsule(j[f"{side}_knee"], j[f"{side}_ankle"], 0.052), TROUSERS))
        parts.append((_capsule(j[f"{side}_heel"] + 0.02 * _UP, j[f"{side}_foot_index"] + 0.02 * _UP, 0.04), SHOES))
    return parts


# ----------------------------------------------------------------------------------------------- targets
def target_point(name: str, objects: Sequence[object] | None = None) -> FloatArray:
    """The world point of a table object (its bounding-box centre) or a semantic-map region (its centre)."""
    from annotators.simulation.kitchen_scene import kitchen_objects  # the scene imports this module

    for obj in objects if objects is not None else kitchen_objects():
        if getattr(obj, "name", None) == name:
            return np.asarray(obj.position, dtype=np.float64)  # type: ignore[attr-defined]
    for region in map_regions():
        if region.name == name:
            return np.asarray(region.position, dtype=np.float64)
    known = [getattr(o, "name", "") for o in (objects or kitchen_objects())] + [r.name for r in map_regions()]
    raise ValueError(f"unknown pointing target {name!r}; known objects and regions: {', '.join(known)}")


def facing(x: float, y: float, point: Sequence[float]) -> float:
    """The yaw of a person at (x, y) facing ``point``."""
    return math.atan2(point[1] - y, point[0] - x)


def person_spec_pose(spec: str) -> PersonPose:
    """The pose a one-word spec names: ``stand``, ``wave`` or ``point:<target>``, optionally ``@x,y``."""
    text = spec.strip()
    where = DEFAULT_SPOT
    if "@" in text:
        text, _, place = text.partition("@")
        try:
            x, y = (float(v) for v in place.split(","))
        except ValueError:
            raise ValueError(f"person spec {spec!r}: the place after @ must be x,y in metres") from None
        where = (x, y)
    action, _, target = text.partition(":")
    table = (0.0, 0.0, 0.0)
    if action == "point":
        if not target:
            raise ValueError(f"person spec {spec!r}: point needs a target, e.g. point:red_cup")
        point = target_point(target)
        posture = Posture(where[0], where[1], facing(where[0], where[1], table), "point", tuple(point))
        return pose_person(posture, target_name=target)
    if action in ("stand", "wave") and not target:
        arm = "wave" if action == "wave" else "hang"
        return pose_person(Posture(where[0], where[1], facing(where[0], where[1], table), arm))
    raise ValueError(f"person spec {spec!r}: expected stand, wave or point:<target>, each optionally @x,y")


# ----------------------------------------------------------------------------------------------- scripts
@dataclass(frozen=True)
class Motion:
    """One timed segment of a script: ``kind`` is ``stand``, ``point``, ``wave`` or ``walk``; ``duration`` in
    seconds; ``path`` the (x, y) waypoints of a walk (the first is where it starts; a standing or pointing motion
    stays at the first); ``target`` names what a pointing motion points at (a table object or a region)."""

    kind: str
    duration: float
    path: tuple[tuple[float, float], ...]
    target: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("stand", "point", "wave", "walk"):
            raise ValueError(f"motion kind must be stand, point, wave or walk, not {self.kind!r}")
        if not self.duration > 0:
            raise ValueError("a motion lasts a positive time")
        if not self.path or (self.kind == "walk" and len(self.path) < 2):
            raise ValueError("a motion needs a place (a walk at least two waypoints)")
        if self.kind == "point" and not self.target:
            raise ValueError("a pointing motion names its target")


@dataclass(frozen=True)
class PersonScript:
    """Motions played one after another; after the last one the person keeps its last pose."""

    motions: tuple[Motion, ...]
    facing_point: tuple[float, float] = (0.0, -1.0)
    _starts: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.motions:
            raise ValueError("a script needs at least one motion")
        starts = np.concatenate([[0.0], np.cumsum([m.duration for m in self.motions])])
        object.__setattr__(self, "_starts", tuple(float(s) for s in starts))

    @property
    def duration(self) -> float:
        """Total length of the script in seconds."""
        return self._starts[-1]

    def motion_at(self, t: float) -> tuple[Motion, float]:
        """The motion playing at time ``t`` and the time since it started."""
        index = int(np.searchsorted(self._starts, t, side="right")) - 1
        index = min(max(index, 0), len(self.motions) - 1)
        return self.motions[index], min(max(t - self._starts[index], 0.0), self.motions[index].duration)

    def pose_at(self, t: float) -> PersonPose:
        """The figure's pose at time ``t`` (seconds from the script's start)."""
        motion, since = self.motion_at(t)
        x, y = motion.path[0]
        look = self.facing_point
        if motion.kind == "walk":
            x, y, heading = _along(motion.path, since / motion.duration)
            posture = Posture(x, y, heading, "hang")
            return pose_person(posture, activity="walking")
        yaw = facing(x, y, look)
        if motion.kind == "point":
            point = target_point(motion.target)
            return pose_person(Posture(x, y, yaw, "point", tuple(point)), target_name=motion.target)
        if motion.kind == "wave":
            return pose_person(Posture(x, y, yaw, "wave", phase=2 * math.pi * since))
        return pose_person(Posture(x, y, yaw))

    @classmethod
    def storage_mission(cls, table_object: str, region: str, start: tuple[float, float] = DEFAULT_SPOT) -> PersonScript:
        """The paper's mission: stand, point at a table object, walk towards the region, point at the region."""
        region_point = target_point(region)
        near = (float(np.clip(region_point[0] - 0.7, -1.2, 2.2)), float(np.clip(region_point[1] - 0.6, -0.9, 0.9)))
        return cls(
            (
                Motion("stand", 2.0, (start,)),
                Motion("point", 3.0, (start,), table_object),
                Motion("walk", 4.0, (start, near)),
                Motion("point", 3.0, (near,), region),
            )
        )


def _along(path: Sequence[tuple[float, float]], fraction: float) -> tuple[float, float, float]:
    """The point at ``fraction`` (0..1) of a polyline's length and the heading of its segment there."""
    points = np.asarray(path, dtype=np.float64)
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    total = float(lengths.sum())
    distance = min(max(fraction, 0.0), 1.0) * total
    last = len(lengths) - 1
    for index, length in enumerate(lengths):
        if distance <= length or index == last:
            a, b = points[index], points[index + 1]
            s = 0.0 if length == 0 else min(distance / length, 1.0)
            p = a + s * (b - a)
            return float(p[0]), float(p[1]), math.atan2(b[1] - a[1], b[0] - a[0])
        distance -= float(length)
    raise ValueError("a path needs at least two points")
