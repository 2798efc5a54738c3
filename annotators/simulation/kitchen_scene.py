"""Deterministic RGB-D renderer of a small synthetic kitchen with ground truth.

The scene (world frame: z up, metres, floor at z = 0) contains a floor, two
walls, a wooden table with a cereal box, a red cup and a blue bowl on it, and an
open fridge whose upper shelf holds a milk carton with the text "MILK" /
"lactose free" on its front face.  Images are produced by ray casting with
Open3D's :class:`open3d.t.geometry.RaycastingScene` and shaded with numpy
(Lambertian key light + head light + strong ambient, no shadows).

Conventions:

* camera optical frame: x right, y down, z forward; ``cam_to_world`` is a 4x4
  float64 homogeneous transform;
* depth is the z coordinate in the camera frame (not the ray length), float32
  metres, 0.0 where nothing is hit or the hit is farther than ``MAX_DEPTH``;
* ``object_ids`` is 0 for background/furniture and ``SceneObject.object_id``
  on the objects;
* ``SceneObject.size`` is (x, y, z) extent in the object's own frame, i.e.
  (width, depth, height); ``SceneObject.pose`` is the world pose of the centre
  of that (oriented) bounding box.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
import open3d as o3d
from numpy.typing import NDArray

from annotators.cloud.size import SIZE_CLASS_THRESHOLDS, size_class_for
from annotators.simulation.kitchen_map import map_regions
from annotators.simulation.kitchen_person import PERSON_OBJECT_ID, PersonPose, person_meshes
from robokudo.core.regions import RegionBox, region_of
from robokudo.core.types import CameraIntrinsics

__all__ = (
    "DEFAULT_INTRINSICS",
    "FRIDGE_SHELF_HEIGHTS",
    "MAX_DEPTH",
    "SIZE_CLASS_THRESHOLDS",
    "TABLE_TOP_HEIGHT",
    "RenderedScene",
    "SceneObject",
    "camera_looking_at",
    "camera_views",
    "fridge_shelf",
    "kitchen_albedos",
    "kitchen_objects",
    "kitchen_regions",
    "look_at",
    "orbit_views",
    "render_kitchen",
    "size_class_for",
)

FloatArray = NDArray[np.float64]

MAX_DEPTH: float = 4.0
"""Hits farther than this (metres, along the optical axis) get depth 0."""

COLOR_NOISE_SIGMA: float = 2.0
"""Std-dev of the per-pixel, per-channel colour noise (uint8 levels)."""

DEPTH_NOISE_SIGMA: float = 0.001
"""Std-dev of the per-pixel depth noise in metres."""


# --------------------------------------------------------------------------
# Public data types
# --------------------------------------------------------------------------
DEFAULT_INTRINSICS = CameraIntrinsics(fx=570.0, fy=570.0, cx=319.5, cy=239.5, width=640, height=480)


@dataclass(frozen=True, eq=False)
class SceneObject:
    """Ground truth of one graspable object of the kitchen scene."""

    object_id: int
    name: str
    object_class: str
    color: str
    shape: str
    size: tuple[float, float, float]
    size_class: str
    pose: FloatArray
    text: str
    region: str

    @property
    def position(self) -> FloatArray:
        """World position of the object's bounding-box centre."""
        return np.asarray(self.pose[:3, 3], dtype=np.float64).copy()


@dataclass(frozen=True, eq=False)
class RenderedScene:
    """One rendered RGB-D frame plus its ground truth."""

    color: NDArray[np.uint8]
    depth: NDArray[np.float32]
    intrinsics: CameraIntrinsics
    cam_to_world: FloatArray
    object_ids: NDArray[np.int32]
    objects: tuple[SceneObject, ...]
    view: str
    person: PersonPose | None = None
    """The person in the scene (ground truth for scoring only), None when there is none."""

    def object(self, name: str) -> SceneObject:
        """Return the scene object called ``name`` (KeyError if unknown)."""
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise KeyError(f"unknown object {name!r}; known: {[o.name for o in self.objects]}")

    def pixel_count(self, name: str) -> int:
        """Number of pixels on which object ``name`` is visible."""
        oid = self.object(name).object_id
        return int(np.count_nonzero(self.object_ids == oid))

    def visible_objects(self, min_pixels: int = 200) -> tuple[SceneObject, ...]:
        """Objects covering at least ``min_pixels`` pixels of the image."""
        counts = np.bincount(self.object_ids.ravel(), minlength=len(self.objects) + 1)
        return tuple(o for o in self.objects if o.object_id < counts.size and counts[o.object_id] >= min_pixels)

    @property
    def world_to_cam(self) -> FloatArray:
        """Inverse of ``cam_to_world``."""
        return np.linalg.inv(self.cam_to_world)

    def object_centroid_camera(self, name: str) -> FloatArray:
        """Bounding-box centre of object ``name`` in the camera optical frame."""
        p = np.ones(4)
        p[:3] = self.object(name).pose[:3, 3]
        return (self.world_to_cam @ p)[:3]

    def person_position(self) -> FloatArray | None:
        """The person's 3-D position (world frame) as robokudo defines it (see
        :mod:`annotators.people.body_points`): the centroid of the figure's surface visible in this frame,
        from the rendered person pixels and their depth. None without a person in view. Ground truth for
        scoring only."""
        rows, cols = np.nonzero((self.object_ids == PERSON_OBJECT_ID) & (self.depth > 0))
        if rows.size == 0:
            return None
        k = self.intrinsics
        z = self.depth[rows, cols].astype(np.float64)
        camera = np.column_stack(((cols - k.cx) * z / k.fx, (rows - k.cy) * z / k.fy, z)).mean(axis=0)
        return self.cam_to_world[:3, :3] @ camera + self.cam_to_world[:3, 3]


# --------------------------------------------------------------------------
# Geometry helpers
# --------------------------------------------------------------------------
def _pose(x: float, y: float, z: float, yaw_deg: float = 0.0) -> FloatArray:
    """Homogeneous transform: rotation about world z, then translation."""
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    t = np.eye(4)
    t[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    t[:3, 3] = (x, y, z)
    return t


def look_at(
    eye: tuple[float, float, float] | NDArray[np.floating],
    target: tuple[float, float, float] | NDArray[np.floating],
) -> FloatArray:
    """cam_to_world of an optical frame at ``eye`` looking at ``target`` (world z up)."""
    eye_v = np.asarray(eye, dtype=np.float64)
    z = np.asarray(target, dtype=np.float64) - eye_v
    z /= np.linalg.norm(z)
    x = np.cross(z, np.array([0.0, 0.0, 1.0]))
    if np.linalg.norm(x) < 1e-9:
        raise ValueError("viewing direction must not be vertical")
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    t = np.eye(4)
    t[:3, 0], t[:3, 1], t[:3, 2], t[:3, 3] = x, y, z, eye_v
    return t


_Mesh = tuple[NDArray[np.float32], NDArray[np.uint32]]


def _box_mesh(size: tuple[float, float, float]) -> _Mesh:
    """Closed box centred at the origin."""
    hx, hy, hz = (s / 2.0 for s in size)
    v = np.array(
        [[sx * hx, sy * hy, sz * hz] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)],
        dtype=np.float32,
    )
    # vertex index = ix + 2*iy + 4*iz
    f = np.array(
        [
            [0, 2, 1],
            [1, 2, 3],  # z-
            [4, 5, 6],
            [5, 7, 6],  # z+
            [0, 1, 4],
            [1, 5, 4],  # y-
            [2, 6, 3],
            [3, 6, 7],  # y+
            [0, 4, 2],
            [2, 4, 6],  # x-
            [1, 3, 5],
            [3, 7, 5],  # x+
        ],
        dtype=np.uint32,
    )
    return v, f


def _cup_mesh(radius: float, height: float, resolution: int = 64) -> _Mesh:
    """Cylinder centred at the origin, open at the top (wall + bottom disc)."""
    ang = np.linspace(0.0, 2.0 * np.pi, resolution, endpoint=False)
    ring = np.stack([radius * np.cos(ang), radius * np.sin(ang)], axis=1)
    bottom = np.column_stack([ring, np.full(resolution, -height / 2)])
    top = np.column_stack([ring, np.full(resolution, height / 2)])
    centre = np.array([[0.0, 0.0, -height / 2]])
    v = np.vstack([bottom, top, centre]).astype(np.float32)
    i = np.arange(resolution)
    j = (i + 1) % resolution
    wall = np.concatenate([np.stack([i, j, i + resolution], 1), np.stack([j, j + resolution, i + resolution], 1)])
    cap = np.stack([np.full(resolution, 2 * resolution), j, i], 1)
    return v, np.vstack([wall, cap]).astype(np.uint32)


def _bowl_mesh(radius: float, height: float, rings: int = 16, segments: int = 64) -> _Mesh:
    """Open half-ellipsoid shell (rim on top) centred at its bounding-box centre."""
    polar = np.linspace(0.0, np.pi / 2, rings + 1)  # 0 = rim, pi/2 = bottom pole
    ang = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    pp, aa = np.meshgrid(polar[:-1], ang, indexing="ij")
    r = radius * np.cos(pp)
    z = -height * np.sin(pp) + height / 2
    v = np.column_stack([(r * np.cos(aa)).ravel(), (r * np.sin(aa)).ravel(), z.ravel()])
    v = np.vstack([v, [[0.0, 0.0, -height / 2]]]).astype(np.float32)
    faces = []
    for k in range(rings - 1):
        i = k * segments + np.arange(segments)
        j = k * segments + (np.arange(segments) + 1) % segments
        faces.append(np.stack([i, j, i + segments], 1))
        faces.append(np.stack([j, j + segments, i + segments], 1))
    i = (rings - 1) * segments + np.arange(segments)
    j = (rings - 1) * segments + (np.arange(segments) + 1) % segments
    faces.append(np.stack([i, j, np.full(segments, rings * segments)], 1))
    return v, np.vstack(faces).astype(np.uint32)


def _transform(mesh: _Mesh, pose: FloatArray) -> _Mesh:
    v, f = mesh
    vw = v.astype(np.float64) @ pose[:3, :3].T + pose[:3, 3]
    return vw.astype(np.float32), f


# --------------------------------------------------------------------------
# Scene description
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class _ObjectSpec:
    object_id: int
    name: str
    object_class: str
    color: str
    shape: str
    size: tuple[float, float, float]
    position: tuple[float, float, float]
    yaw_deg: float
    albedo: tuple[int, int, int]
    text: str


TABLE_TOP_HEIGHT: float = 0.75
TABLE_SIZE: tuple[float, float] = (1.2, 0.8)
TABLE_CENTRE: tuple[float, float] = (0.0, 0.0)
FRIDGE_CENTRE: tuple[float, float] = (1.3, 0.85)
FRIDGE_SIZE: tuple[float, float, float] = (0.6, 0.6, 1.6)
FRIDGE_SHELF_HEIGHTS: tuple[float, float] = (0.95, 0.5)
"""Heights (m) of the top surfaces of the fridge shelves (milk on the first)."""
_WALL = 0.03  # fridge wall thickness
_SHELF = 0.02  # fridge shelf thickness

_OBJECT_SPECS: tuple[_ObjectSpec, ...] = (
    _ObjectSpec(
        object_id=1, name="cereal_box", object_class="CerealBox", color="yellow", shape="box",
        size=(0.19, 0.07, 0.28), position=(-0.25, 0.05, TABLE_TOP_HEIGHT + 0.14), yaw_deg=0.0,
        albedo=(240, 224, 28), text="",
    ),
    _ObjectSpec(
        object_id=2, name="red_cup", object_class="Cup", color="red", shape="cylinder",
        size=(0.08, 0.08, 0.10), position=(0.0, -0.12, TABLE_TOP_HEIGHT + 0.05), yaw_deg=0.0,
        albedo=(205, 28, 30), text="",
    ),
    _ObjectSpec(
        object_id=3, name="bowl", object_class="Bowl", color="blue", shape="sphere",
        size=(0.16, 0.16, 0.07), position=(0.26, 0.0, TABLE_TOP_HEIGHT + 0.035), yaw_deg=0.0,
        albedo=(32, 78, 200), text="",
    ),
    _ObjectSpec(
        object_id=4, name="milk", object_class="Milk", color="white", shape="box",
        size=(0.07, 0.07, 0.20), position=(FRIDGE_CENTRE[0], 0.80, FRIDGE_SHELF_HEIGHTS[0] + 0.10),
        yaw_deg=0.0, albedo=(248, 248, 246), text="MILK lactose free",
    ),
)  # fmt: skip

# Surface patterns
_PLAIN, _CHECKER, _WOOD, _LABEL = 0, 1, 2, 3

_BACKGROUND_RGB = (28, 30, 36)
_LIGHT_DIR: tuple[float, float, float] = (0.35, -0.6, 1.0)  # towards the key light (normalised on use)
_AMBIENT, _KEY, _HEAD = 0.5, 0.35, 0.2


def kitchen_albedos() -> dict[str, tuple[int, int, int]]:
    """The RGB albedo each kitchen object is rendered with, by name (to put a grasped object down again)."""
    return {spec.name: spec.albedo for spec in _OBJECT_SPECS}


def kitchen_regions() -> tuple[RegionBox, ...]:
    """The semantic-map regions of the kitchen (the table top "table", the fridge interior "fridge"), as the
    built-in map ``ontology/kitchen_map.ttl`` declares them."""
    return map_regions()


def kitchen_objects(
    moved: Mapping[str, NDArray[np.floating]] | None = None,
) -> tuple[SceneObject, ...]:
    """Ground truth of all objects, optionally with some of them moved.

    ``moved`` maps an object name to either a new 4x4 world pose or a 3-vector
    world translation offset.  ``region`` is recomputed from the final pose
    ("" if the object is in no region).
    """
    moved = dict(moved or {})
    known = {s.name for s in _OBJECT_SPECS}
    unknown = set(moved) - known
    if unknown:
        raise ValueError(f"unknown object(s) {sorted(unknown)}; known: {sorted(known)}")
    regions = kitchen_regions()
    objects = []
    for spec in _OBJECT_SPECS:
        pose = _pose(*spec.position, spec.yaw_deg)
        if spec.name in moved:
            m = np.asarray(moved[spec.name], dtype=np.float64)
            if m.shape == (4, 4):
                pose = m.copy()
            elif m.shape == (3,):
                pose[:3, 3] += m
            else:
                raise ValueError(f"moved[{spec.name!r}] must be a 4x4 pose or a 3-vector, got shape {m.shape}")
        objects.append(
            SceneObject(
                object_id=spec.object_id,
                name=spec.name,
                object_class=spec.object_class,
                color=spec.color,
                shape=spec.shape,
                size=spec.size,
                size_class=size_class_for(spec.size),
                pose=pose,
                text=spec.text,
                region=region.name if (region := region_of(pose[:3, 3], regions)) is not None else "",
            )
        )
    return tuple(objects)


@dataclass(frozen=True, eq=False)
class _Part:
    """One mesh of the render scene with its appearance."""

    mesh: _Mesh
    albedo: tuple[int, int, int]
    object_id: int = 0
    pattern: int = _PLAIN


def _furniture_parts() -> list[_Part]:
    parts: list[_Part] = []
    # floor and walls
    floor = _box_mesh((6.0, 5.0, 0.02))
    parts.append(_Part(_transform(floor, _pose(0.0, -1.3, -0.01)), (160, 154, 146), 0, _CHECKER))
    back_wall = _box_mesh((6.0, 0.05, 2.6))
    parts.append(_Part(_transform(back_wall, _pose(0.0, 1.225, 1.3)), (196, 204, 212)))
    side_wall = _box_mesh((0.05, 5.0, 2.6))
    parts.append(_Part(_transform(side_wall, _pose(-1.625, -1.3, 1.3)), (206, 200, 188)))
    parts.append(_Part(_transform(side_wall, _pose(2.625, -1.3, 1.3)), (206, 200, 188)))
    # table
    tx, ty = TABLE_CENTRE
    sx, sy = TABLE_SIZE
    top_t = 0.04
    wood = (132, 84, 48)
    top = _box_mesh((sx, sy, top_t))
    parts.append(_Part(_transform(top, _pose(tx, ty, TABLE_TOP_HEIGHT - top_t / 2)), wood, 0, _WOOD))
    leg_h = TABLE_TOP_HEIGHT - top_t
    leg = _box_mesh((0.05, 0.05, leg_h))
    for lx in (-1, 1):
        for ly in (-1, 1):
            p = _pose(tx + lx * (sx / 2 - 0.06), ty + ly * (sy / 2 - 0.06), leg_h / 2)
            parts.append(_Part(_transform(leg, p), (110, 70, 40)))
    # fridge: open front facing -y, door swung open around the hinge at (+x, -y)
    fx, fy = FRIDGE_CENTRE
    wx, wy, wz = FRIDGE_SIZE
    body, inside = (232, 233, 236), (214, 220, 228)
    x0, x1, y0, y1 = fx - wx / 2, fx + wx / 2, fy - wy / 2, fy + wy / 2
    slabs = (  # (size, centre, colour)
        ((_WALL, wy, wz), (x0 + _WALL / 2, fy, wz / 2), body),  # left wall
        ((_WALL, wy, wz), (x1 - _WALL / 2, fy, wz / 2), body),  # right wall
        ((wx, _WALL, wz), (fx, y1 - _WALL / 2, wz / 2), inside),  # back
        ((wx, wy, 0.08), (fx, fy, 0.04), body),  # bottom / plinth
        ((wx, wy, _WALL), (fx, fy, wz - _WALL / 2), body),  # top
    )
    for size, centre, col in slabs:
        parts.append(_Part(_transform(_box_mesh(size), _pose(*centre)), col))
    for level in range(len(FRIDGE_SHELF_HEIGHTS)):
        centre, shelf_size = fridge_shelf(level)
        parts.append(_Part(_transform(_box_mesh(shelf_size), _pose(*centre)), (198, 206, 216)))
    door_t = 0.05
    door = _box_mesh((wx, door_t, wz - 0.02))
    opening = 100.0  # degrees
    hinge = _pose(x1, y0, 0.0, opening)
    door_local = _pose(-wx / 2, -door_t / 2, (wz - 0.02) / 2 + 0.01)
    parts.append(_Part(_transform(door, hinge @ door_local), body))
    return parts


def fridge_shelf(level: int = 0) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """World centre and size (along the world axes) of a fridge shelf board; level 0 is the upper one (the milk's),
    whose top surface is at ``FRIDGE_SHELF_HEIGHTS[level]``."""
    fx, fy = FRIDGE_CENTRE
    wx, wy, _ = FRIDGE_SIZE
    size = (wx - 2 * _WALL, wy - _WALL - 0.02, _SHELF)
    top = FRIDGE_SHELF_HEIGHTS[level]
    return (fx, fy - wy / 2 + 0.02 + size[1] / 2, top - _SHELF / 2), size


def _object_parts(
    objects: tuple[SceneObject, ...], albedos: Mapping[str, tuple[int, int, int]] | None = None
) -> list[_Part]:
    colours = {s.name: s.albedo for s in _OBJECT_SPECS} | dict(albedos or {})
    parts: list[_Part] = []
    for obj in objects:
        albedo = colours[obj.name]
        w, _, h = obj.size
        if obj.shape == "box":
            mesh = _box_mesh(obj.size)
        elif obj.shape == "cylinder":
            mesh = _cup_mesh(w / 2, h)
        else:
            mesh = _bowl_mesh(w / 2, h)
        pattern = _LABEL if obj.text else _PLAIN
        parts.append(_Part(_transform(mesh, obj.pose), albedo, obj.object_id, pattern))
    return parts


def _label_texture(width_m: float, height_m: float) -> NDArray[np.float64]:
    """Front-face texture of the milk carton (RGB float in [0, 1])."""
    px_per_m = 2000.0
    tw, th = round(width_m * px_per_m), round(height_m * px_per_m)
    img = np.full((th, tw, 3), 248, dtype=np.uint8)
    blue = (24, 70, 205)
    font = cv2.FONT_HERSHEY_DUPLEX
    lines = (
        ("MILK", 0.90 * tw, 5, blue, 0.30),
        ("lactose", 0.86 * tw, 2, (20, 20, 20), 0.50),
        ("free", 0.56 * tw, 2, (20, 20, 20), 0.62),
    )
    for text, target_w, thick, col, rel_y in lines:
        (w1, _), _ = cv2.getTextSize(text, font, 1.0, thick)
        scale = target_w / w1
        (tw_px, th_px), _ = cv2.getTextSize(text, font, scale, thick)
        org = ((tw - tw_px) // 2, round(rel_y * th + th_px / 2))
        cv2.putText(img, text, org, font, scale, col, thick, cv2.LINE_AA)
    return img.astype(np.float64) / 255.0


# --------------------------------------------------------------------------
# Views
# --------------------------------------------------------------------------
_VIEW_EYE_TARGET: tuple[tuple[str, tuple[float, float, float], tuple[float, float, float]], ...] = (
    ("table", (0.0, -1.05, 1.42), (0.0, -0.08, 0.72)),
    ("fridge", (1.3, 0.33, 1.22), (1.3, 0.80, 1.04)),
    ("overview", (-0.6, -2.7, 2.0), (0.45, 0.3, 0.75)),
)
_REGION_VIEW: tuple[tuple[str, str], ...] = (("table", "table"), ("fridge", "fridge"))


def camera_views() -> dict[str, FloatArray]:
    """Named cam_to_world poses: "table" (default), "fridge" and "overview"."""
    return {name: look_at(eye, target) for name, eye, target in _VIEW_EYE_TARGET}


def camera_looking_at(region_name: str) -> str:
    """Name of the camera view that looks at region ``region_name`` (case-insensitive)."""
    key = region_name.strip().lower()
    for region, view in _REGION_VIEW:
        if region == key:
            return view
    known = ", ".join(r for r, _ in _REGION_VIEW)
    raise ValueError(f"no camera view for region {region_name!r}; known regions: {known}")


def orbit_views(
    n: int = 5, radius: float = 1.15, height: float = 1.40, span_deg: float = 100.0
) -> tuple[FloatArray, ...]:
    """``n`` cam_to_world poses on an arc around the table, all seeing the table objects.

    The arc is centred on the robot side (-y) of the table and spans ``span_deg``.
    """
    if n < 1:
        raise ValueError("n must be >= 1")
    cx, cy = TABLE_CENTRE
    angles = [0.0] if n == 1 else list(np.linspace(-span_deg / 2, span_deg / 2, n))
    target = (cx, cy - 0.04, TABLE_TOP_HEIGHT)
    poses = []
    for a in angles:
        r = math.radians(a)
        eye = (cx + radius * math.sin(r), cy - radius * math.cos(r), height)
        poses.append(look_at(eye, target))
    return tuple(poses)


# --------------------------------------------------------------------------
# Rendering
# --------------------------------------------------------------------------
def _camera_rays(cam_to_world: FloatArray, k: CameraIntrinsics) -> tuple[FloatArray, FloatArray]:
    """Per-pixel ray directions (camera z-component 1) in world, and the origin."""
    u = (np.arange(k.width, dtype=np.float64) - k.cx) / k.fx
    v = (np.arange(k.height, dtype=np.float64) - k.cy) / k.fy
    r = cam_to_world[:3, :3]
    # world direction = R @ (u, v, 1), separable in u and v
    dirs_world = (u[None, :, None] * r[:, 0] + v[:, None, None] * r[:, 1]) + r[:, 2]
    return dirs_world, cam_to_world[:3, 3].copy()


def _shade_patterns(
    albedo: NDArray[np.float32],
    pattern: NDArray[np.int64],
    points: NDArray[np.float32],
    geom: NDArray[np.int64],
    parts: list[_Part],
    objects: tuple[SceneObject, ...],
) -> None:
    """Modulate the per-pixel albedo (N x 3) in place according to the surface patterns."""
    idx = np.flatnonzero(pattern == _CHECKER)
    if idx.size:
        q = points[idx, :2] / np.float32(0.5)
        cells = np.floor(q)
        tiles = (cells[:, 0] + cells[:, 1]).astype(np.int64) % 2
        frac = np.abs(q - np.rint(q))
        grout = (frac[:, 0] < 0.01) | (frac[:, 1] < 0.01)
        factor = np.where(tiles == 0, 1.0, 0.88) * np.where(grout, 0.75, 1.0)
        albedo[idx] *= factor.astype(np.float32)[:, None]
    idx = np.flatnonzero(pattern == _WOOD)
    if idx.size:
        p = points[idx]
        grain = np.sin(2 * np.pi * (p[:, 1] / 0.035 + 0.8 * np.sin(2 * np.pi * p[:, 0] / 0.9)))
        albedo[idx] *= (1.0 + 0.06 * grain).astype(np.float32)[:, None]
    for obj in objects:
        if not obj.text:
            continue
        gid = next(i for i, part in enumerate(parts) if part.object_id == obj.object_id)
        idx = np.flatnonzero(geom == gid)
        if not idx.size:
            continue
        w, d, h = obj.size
        inv = np.linalg.inv(obj.pose)
        local = points[idx].astype(np.float64) @ inv[:3, :3].T + inv[:3, 3]
        front = np.abs(local[:, 1] + d / 2) < 1e-3
        if not front.any():
            continue
        tex = _label_texture(w, h)
        th, tw = tex.shape[:2]
        uu = np.clip((local[front, 0] / w + 0.5) * tw - 0.5, 0, tw - 1)
        vv = np.clip((0.5 - local[front, 2] / h) * th - 0.5, 0, th - 1)
        albedo[idx[front]] = _bilinear(tex, uu, vv) * 255.0


def _bilinear(img: FloatArray, u: FloatArray, v: FloatArray) -> FloatArray:
    h, w = img.shape[:2]
    u0 = np.floor(u).astype(np.int64)
    v0 = np.floor(v).astype(np.int64)
    u1, v1 = np.minimum(u0 + 1, w - 1), np.minimum(v0 + 1, h - 1)
    a, b = (u - u0)[:, None], (v - v0)[:, None]
    return img[v0, u0] * (1 - a) * (1 - b) + img[v0, u1] * a * (1 - b) + img[v1, u0] * (1 - a) * b + img[v1, u1] * a * b


def _resolve_view(view: str | NDArray[np.floating]) -> tuple[str, FloatArray]:
    if isinstance(view, str):
        views = camera_views()
        if view not in views:
            raise ValueError(f"unknown view {view!r}; known: {sorted(views)}")
        return view, views[view]
    pose = np.asarray(view, dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"custom view must be a 4x4 cam_to_world, got shape {pose.shape}")
    return "custom", pose.copy()


def render_kitchen(
    view: str | NDArray[np.floating] = "table",
    *,
    seed: int = 0,
    noise: bool = True,
    moved: Mapping[str, NDArray[np.floating]] | None = None,
    intrinsics: CameraIntrinsics = DEFAULT_INTRINSICS,
    person: PersonPose | None = None,
    extra: Sequence[tuple[SceneObject, tuple[int, int, int]]] = (),
    hidden: Collection[str] = (),
) -> RenderedScene:
    """Render one RGB-D frame of the kitchen.

    ``view`` is a named view (see :func:`camera_views`) or a 4x4 cam_to_world.
    ``noise`` toggles the seeded colour (sigma ``COLOR_NOISE_SIGMA``) and depth
    (sigma ``DEPTH_NOISE_SIGMA``) noise; without noise the output does not
    depend on ``seed``.  ``moved`` is passed to :func:`kitchen_objects`.  ``person`` adds the articulated
    figure of :mod:`annotators.simulation.kitchen_person` in that pose (pixels of id ``PERSON_OBJECT_ID``).
    ``extra`` adds objects (box, cylinder or bowl shapes) with their RGB albedo to the
    scene and its ground truth, e.g. a storage layout (``annotators.simulation.storage``);
    their names and ids must differ from the kitchen's. ``hidden`` names kitchen objects left out of the scene and
    its ground truth (taken away, e.g. grasped).
    """
    view_name, cam_to_world = _resolve_view(view)
    objects = kitchen_objects(moved)
    unknown = set(hidden) - {o.name for o in objects}
    if unknown:
        raise ValueError(f"cannot hide unknown object(s) {sorted(unknown)}; known: {[o.name for o in objects]}")
    objects = tuple(o for o in objects if o.name not in hidden)
    added = tuple(obj for obj, _ in extra)
    taken = {o.name for o in objects} | {o.object_id for o in objects}
    clashes = [o.name for o in added if o.name in taken or o.object_id in taken or o.object_id <= 0]
    if clashes or len({o.name for o in added}) < len(added) or len({o.object_id for o in added}) < len(added):
        raise ValueError(f"extra objects need names and positive ids of their own; clashing: {clashes or 'each other'}")
    objects += added
    parts = _furniture_parts() + _object_parts(objects, {obj.name: albedo for obj, albedo in extra})
    if person is not None:
        parts += [_Part(mesh, color, PERSON_OBJECT_ID) for mesh, color in person_meshes(person)]

    scene = o3d.t.geometry.RaycastingScene()
    for part in parts:
        v, f = part.mesh
        scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))

    k = intrinsics
    dirs, origin = _camera_rays(cam_to_world, k)
    rays = np.empty((k.height * k.width, 6), dtype=np.float32)
    rays[:, :3] = origin
    rays[:, 3:] = dirs.reshape(-1, 3)
    hits = scene.cast_rays(o3d.core.Tensor(rays))
    t_hit = hits["t_hit"].numpy()
    geom_raw = hits["geometry_ids"].numpy()
    normals = hits["primitive_normals"].numpy()

    hit = np.isfinite(t_hit)
    t = np.where(hit, t_hit, np.float32(0.0))
    # t_hit is in units of |dir| and dir has camera-z component 1 -> t_hit == z depth
    depth = np.where(t <= MAX_DEPTH, t, np.float32(0.0))

    # look-up tables; index len(parts) is the "no hit" background
    background = len(parts)
    geom = np.where(hit, geom_raw, background).astype(np.int64)
    ids_lut = np.array([p.object_id for p in parts] + [0], dtype=np.int32)
    albedo_lut = np.array([p.albedo for p in parts] + [_BACKGROUND_RGB], dtype=np.float32)
    pattern_lut = np.array([p.pattern for p in parts] + [_PLAIN], dtype=np.int64)
    object_ids = ids_lut[geom]

    d = rays[:, 3:]
    d_unit = d / np.sqrt(np.einsum("ij,ij->i", d, d))[:, None]
    points = rays[:, :3] + d * t[:, None]
    albedo = albedo_lut[geom]
    _shade_patterns(albedo, pattern_lut[geom], points, geom, parts, objects)
    light = np.asarray(_LIGHT_DIR, dtype=np.float32) / np.float32(np.linalg.norm(_LIGHT_DIR))
    # flip normals to face the camera (insides of the open bowl and cup)
    cos_view = -np.einsum("ij,ij->i", normals, d_unit)
    normals *= np.where(cos_view < 0, np.float32(-1.0), np.float32(1.0))[:, None]
    shade = _AMBIENT + _KEY * np.clip(normals @ light, 0.0, None) + _HEAD * np.abs(cos_view)
    shade[~hit] = 1.0
    color = albedo * shade[:, None]

    if noise:
        rng = np.random.default_rng(seed)
        valid = np.flatnonzero(depth > 0)
        depth[valid] += DEPTH_NOISE_SIGMA * rng.standard_normal(valid.size, dtype=np.float32)
        color += COLOR_NOISE_SIGMA * rng.standard_normal(color.shape, dtype=np.float32)

    shape2 = (k.height, k.width)
    color_u8 = np.clip(np.rint(color), 0, 255).astype(np.uint8).reshape(*shape2, 3)
    return RenderedScene(
        color=np.ascontiguousarray(color_u8),
        depth=np.ascontiguousarray(depth.astype(np.float32).reshape(shape2)),
        intrinsics=k,
        cam_to_world=cam_to_world,
        object_ids=np.ascontiguousarray(object_ids.reshape(shape2)),
        objects=objects,
        view=view_name,
        person=person,
    )
