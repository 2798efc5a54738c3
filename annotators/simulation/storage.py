"""Storage layouts for the built-in kitchen: objects put on the fridge's upper shelf, blocking some places.

The fridge is the kitchen's storage region; its upper shelf holds the milk. A layout adds more objects there
(:func:`half_blocked_layout`: the left half full, :func:`random_layout`: seeded random objects anywhere on it),
to be rendered with ``render_kitchen(..., extra=layout.extra())`` and read by ``KitchenSceneReader(extra=...)``.
Ground truth (:meth:`StorageLayout.is_free`) is for scoring only: perception sees the rendered frames.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from annotators.cloud.size import size_class_for
from annotators.simulation.kitchen_scene import (
    FRIDGE_SHELF_HEIGHTS,
    RenderedScene,
    SceneObject,
    fridge_shelf,
    kitchen_objects,
)

FIRST_ID = 101
"""The object id of a layout's first object (the kitchen's own objects have ids below)."""

_KINDS: tuple[tuple[str, str, str, tuple[float, float, float], tuple[int, int, int]], ...] = (
    ("Cup", "red", "cylinder", (0.08, 0.08, 0.10), (205, 28, 30)),
    ("Mug", "blue", "cylinder", (0.09, 0.09, 0.11), (32, 78, 200)),
    ("Juice", "orange", "box", (0.07, 0.07, 0.19), (240, 140, 30)),
    ("Butter", "yellow", "box", (0.12, 0.07, 0.05), (240, 224, 28)),
    ("Jar", "green", "cylinder", (0.07, 0.07, 0.12), (40, 160, 60)),
)
"""Class, colour, shape, size (width, depth, height) and albedo of the things a layout puts on the shelf."""


@dataclass(frozen=True)
class StorageLayout:
    """Objects on the fridge's upper shelf (besides the milk) and the albedo each is rendered with."""

    objects: tuple[SceneObject, ...]
    albedos: tuple[tuple[int, int, int], ...]

    def extra(self) -> tuple[tuple[SceneObject, tuple[int, int, int]], ...]:
        """The objects with their albedo, as ``render_kitchen(extra=...)`` takes them."""
        return tuple(zip(self.objects, self.albedos, strict=True))

    def occupants(self) -> tuple[SceneObject, ...]:
        """Every object on the shelf: the layout's and the kitchen's milk."""
        shelf_top = FRIDGE_SHELF_HEIGHTS[0]
        on_shelf = [o for o in kitchen_objects() if abs(o.position[2] - o.size[2] / 2 - shelf_top) < 0.01]
        return (*on_shelf, *self.objects)

    def is_free(self, centre: np.ndarray, rotation: np.ndarray, size: tuple[float, float], step: float = 0.005) -> bool:
        """Ground truth: True when the rectangle (world ``centre`` on the shelf, axes the columns of ``rotation``,
        ``size`` along its x and y) lies on the upper shelf between the fridge walls and touches no object."""
        return free_on_shelf(self.occupants(), centre, rotation, size, step)


def shelf_occupants(objects: Sequence[SceneObject]) -> tuple[SceneObject, ...]:
    """The objects of ``objects`` standing on the fridge's upper shelf (their bottom on its top surface)."""
    (cx, cy, _), (sx, sy, _) = fridge_shelf(0)
    return tuple(
        o
        for o in objects
        if abs(o.position[2] - o.size[2] / 2 - FRIDGE_SHELF_HEIGHTS[0]) < 0.01
        and abs(o.position[0] - cx) <= sx / 2
        and abs(o.position[1] - cy) <= sy / 2
    )


def free_on_shelf(
    occupants: Sequence[SceneObject],
    centre: np.ndarray,
    rotation: np.ndarray,
    size: tuple[float, float],
    step: float = 0.005,
) -> bool:
    """Ground truth: True when the rectangle (world ``centre`` on the upper shelf, axes the columns of
    ``rotation``, ``size`` along its x and y) lies on the shelf between the fridge walls and touches none of
    ``occupants``."""
    centre = np.asarray(centre, dtype=np.float64)
    if abs(centre[2] - FRIDGE_SHELF_HEIGHTS[0]) > 0.02:
        return False
    samples = rectangle_samples(centre, rotation, size, step)
    return bool(on_shelf(samples).all() and not any(covers(o, samples).any() for o in occupants))


def free_spots(occupants: Sequence[SceneObject], footprint: tuple[float, float], step: float = 0.01) -> np.ndarray:
    """Ground truth: the centres (``step`` apart, world axes; N x 3) where an axis-aligned ``footprint`` lies on the
    upper shelf touching none of ``occupants``."""
    (cx, cy, _), (sx, sy, _) = fridge_shelf(0)
    half = np.asarray(footprint, dtype=np.float64) / 2
    xs = np.arange(cx - sx / 2 + half[0], cx + sx / 2 - half[0] + 1e-9, step)
    ys = np.arange(cy - sy / 2 + half[1], cy + sy / 2 - half[1] + 1e-9, step)
    centres = np.array([[x, y, FRIDGE_SHELF_HEIGHTS[0]] for x in xs for y in ys]).reshape(-1, 3)
    if not len(centres):
        return centres
    offsets = rectangle_samples(np.zeros(3), np.eye(3), footprint, 0.005)
    samples = (centres[:, None, :] + offsets[None, :, :]).reshape(-1, 3)
    blocked = ~on_shelf(samples)
    for obj in occupants:
        blocked |= covers(obj, samples)
    return centres[~blocked.reshape(len(centres), -1).any(axis=1)]


def rectangle_samples(centre: np.ndarray, rotation: np.ndarray, size: tuple[float, float], step: float) -> np.ndarray:
    """World points covering a rectangle (its edges included) every ``step`` metres or closer."""
    axes = np.asarray(rotation, dtype=np.float64)
    u = np.linspace(-size[0] / 2, size[0] / 2, max(2, math.ceil(size[0] / step) + 1))
    v = np.linspace(-size[1] / 2, size[1] / 2, max(2, math.ceil(size[1] / step) + 1))
    uu, vv = np.meshgrid(u, v)
    return np.asarray(centre)[None, :] + uu.reshape(-1, 1) * axes[:, 0] + vv.reshape(-1, 1) * axes[:, 1]


def on_shelf(points: np.ndarray) -> np.ndarray:
    """Which world points lie over the upper shelf board (x, y within it)."""
    (cx, cy, _), (sx, sy, _) = fridge_shelf(0)
    return (np.abs(points[:, 0] - cx) <= sx / 2) & (np.abs(points[:, 1] - cy) <= sy / 2)


def covers(obj: SceneObject, points: np.ndarray) -> np.ndarray:
    """Which world points lie over the object's footprint: a disc for a cylinder or a bowl (round), else its box's
    width x depth in its own axes."""
    inverse = np.linalg.inv(obj.pose)
    local = points @ inverse[:3, :3].T + inverse[:3, 3]
    if obj.shape in ("cylinder", "sphere"):
        return np.hypot(local[:, 0], local[:, 1]) <= obj.size[0] / 2
    return (np.abs(local[:, 0]) <= obj.size[0] / 2) & (np.abs(local[:, 1]) <= obj.size[1] / 2)


def _scene_object(
    index: int, kind: int, x: float, y: float, yaw_deg: float
) -> tuple[SceneObject, tuple[int, int, int]]:
    object_class, color, shape, size, albedo = _KINDS[kind % len(_KINDS)]
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    pose = np.eye(4)
    pose[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    pose[:3, 3] = (x, y, FRIDGE_SHELF_HEIGHTS[0] + size[2] / 2)
    obj = SceneObject(
        object_id=FIRST_ID + index,
        name=f"stored_{index}_{object_class.lower()}",
        object_class=object_class,
        color=color,
        shape=shape,
        size=size,
        size_class=size_class_for(size),
        pose=pose,
        text="",
        region="fridge",
    )
    return obj, albedo


def _layout(items: list[tuple[SceneObject, tuple[int, int, int]]]) -> StorageLayout:
    return StorageLayout(tuple(o for o, _ in items), tuple(a for _, a in items))


def half_blocked_layout() -> StorageLayout:
    """Four objects filling the left half of the upper shelf (the milk stands in the middle): the right half free."""
    (cx, cy, _), (sx, sy, _) = fridge_shelf(0)
    left = cx - sx / 4
    rows = (cy - sy / 4, cy + sy / 4)
    items = [
        _scene_object(i, kind, left + dx, y, 0.0)
        for i, (kind, dx, y) in enumerate(
            ((0, -0.06, rows[0]), (3, 0.05, rows[0]), (2, -0.06, rows[1]), (4, 0.05, rows[1]))
        )
    ]
    return _layout(items)


def random_layout(seed: int, count: int | None = None, gap: float = 0.02) -> StorageLayout:
    """``count`` (default 2-5) seeded random objects at random places and turns on the upper shelf, none touching
    another object or a fridge wall (at least ``gap`` apart)."""
    rng = np.random.default_rng(seed)
    wanted = int(rng.integers(2, 6)) if count is None else count
    (cx, cy, _), (sx, sy, _) = fridge_shelf(0)
    placed: list[tuple[SceneObject, tuple[int, int, int]]] = []
    occupied = [o for o in StorageLayout((), ()).occupants()]
    for _ in range(200 * max(1, wanted)):
        if len(placed) == wanted:
            break
        kind = int(rng.integers(0, len(_KINDS)))
        radius = math.hypot(*_KINDS[kind][3][:2]) / 2
        x = rng.uniform(cx - sx / 2 + radius + gap, cx + sx / 2 - radius - gap)
        y = rng.uniform(cy - sy / 2 + radius + gap, cy + sy / 2 - radius - gap)
        candidate = _scene_object(len(placed), kind, float(x), float(y), float(rng.uniform(0.0, 90.0)))
        reach = [radius + math.hypot(*o.size[:2]) / 2 + gap for o in occupied]
        if all(math.dist(o.position[:2], (x, y)) >= r for o, r in zip(occupied, reach, strict=True)):
            placed.append(candidate)
            occupied.append(candidate[0])
    if len(placed) < wanted:
        raise ValueError(f"could not put {wanted} objects on the shelf without touching (seed {seed})")
    return _layout(placed)


def footprint_in_view(spot: np.ndarray, footprint: tuple[float, float], scene: RenderedScene) -> bool:
    """Ground truth: True when the camera of ``scene`` sees the surface under the whole axis-aligned ``footprint``
    at ``spot`` (the rendered depth there is the surface's, within 1 cm, at every sample)."""
    samples = rectangle_samples(spot, np.eye(3), footprint, 0.01)
    world_to_cam = scene.world_to_cam
    camera = samples @ world_to_cam[:3, :3].T + world_to_cam[:3, 3]
    if np.any(camera[:, 2] <= 0):
        return False
    pixels = np.rint(scene.intrinsics.project(camera)).astype(int)
    height, width = scene.depth.shape
    if np.any((pixels < 0) | (pixels >= (width, height))):
        return False
    depth = scene.depth[pixels[:, 1], pixels[:, 0]]
    return bool(np.all(np.abs(depth - camera[:, 2]) < 0.01))
