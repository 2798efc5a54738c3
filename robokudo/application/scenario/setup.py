"""What one run of the storage scenario looks like: where the person stands, what she points at, what blocks the
storage shelf, and her scripted motions per phase (seeded, so a run is reproducible).

The person stands behind the table, points at one of the table objects, grasps it, walks to a spot towards the
fridge (the kitchen's storage region, its upper shelf the storage place) and points at the fridge, sideways, her
face to the robot (an arm pointing away from the camera would hide behind her body). A random
storage layout (``annotators.simulation.storage.random_layout``) blocks places on the shelf. Everything here is
ground truth for staging and scoring; the robot's perception sees only the rendered frames.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from annotators.simulation.kitchen_person import Motion, PersonScript
from annotators.simulation.storage import StorageLayout, random_layout

TABLE_OBJECTS: tuple[str, ...] = ("cereal_box", "red_cup", "bowl")
"""The table objects the person may point at."""

STORAGE_REGION = "fridge"
"""The storage region she points at (its upper shelf holds the storage layout)."""

START_X: tuple[float, float] = (-0.55, -0.1)
START_Y: tuple[float, float] = (0.6, 0.8)
"""Where she may start: behind the table (x, y ranges in metres, world frame)."""

SPOT_X: tuple[float, float] = (0.25, 0.45)
SPOT_Y: tuple[float, float] = (0.7, 0.85)
"""Where she may stop to point at the fridge: behind the table's right half, the fridge to her left at an arm's
raise of about 45 degrees (a nearer fridge would have her arm hang nearly down, which is no pointing)."""

WALK_SPEED = 0.35
"""Her walking speed (m/s)."""

HOLD_S = 600.0
"""How long she keeps a posture the robot has to notice (a pointing gesture until it is acknowledged)."""


@dataclass(frozen=True)
class RunSetup:
    """One run: the seed, where she starts and stops, what she points at, how long she stands before pointing,
    and the storage layout."""

    seed: int
    start: tuple[float, float]
    spot: tuple[float, float]
    target: str
    region: str
    wait_s: float
    layout: StorageLayout

    @classmethod
    def draw(cls, seed: int) -> RunSetup:
        """The run of ``seed``: uniform start and stop spots, a random table object, 0.5-2 s of standing and a
        random storage layout (2-5 objects on the shelf)."""
        rng = np.random.default_rng(seed)
        start = (float(rng.uniform(*START_X)), float(rng.uniform(*START_Y)))
        spot = (float(rng.uniform(*SPOT_X)), float(rng.uniform(*SPOT_Y)))
        target = TABLE_OBJECTS[int(rng.integers(len(TABLE_OBJECTS)))]
        wait_s = float(rng.uniform(0.5, 2.0))
        layout = random_layout(int(rng.integers(0, 2**31 - 1)))
        return cls(seed, start, spot, target, STORAGE_REGION, wait_s, layout)

    def standing(self) -> PersonScript:
        """Phase 1: she stands at her start."""
        return PersonScript((Motion("stand", HOLD_S, (self.start,)),))

    def pointing_at_object(self) -> PersonScript:
        """Phase 2: she stands a moment, then points at the table object until acknowledged."""
        return PersonScript(
            (Motion("stand", self.wait_s, (self.start,)), Motion("point", HOLD_S, (self.start,), self.target))
        )

    @property
    def walk_s(self) -> float:
        """How long her walk to the fridge takes."""
        return math.dist(self.start, self.waypoint) / WALK_SPEED + math.dist(self.waypoint, self.spot) / WALK_SPEED

    @property
    def waypoint(self) -> tuple[float, float]:
        """Where her walk turns: behind the table's right corner, so she walks round it."""
        return (max(self.start[0], 0.75), max(self.start[1], 0.6))

    def walking_to_storage(self) -> PersonScript:
        """Phase 3: she walks round the table to her spot before the fridge and points at it until acknowledged."""
        path = (self.start, self.waypoint, self.spot)
        return PersonScript((Motion("walk", self.walk_s, path), Motion("point", HOLD_S, (self.spot,), self.region)))
