"""Selecting objects by a relation among those that answer a query: the top box, the leftmost cup, the biggest bowl.

The selections and what they measure are declared in :mod:`queries.selection`; this module takes the measures of
beliefs and orders them. Measures are taken where the beliefs were seen from (:class:`Viewpoint`):

* height: above the support plane (camera frame, the plane's normal points to the camera); without a plane, world
  z (the world frame is z up) for a belief in the world frame, else the camera's up (-y, image up);
* camera x (image left to right) and distance from the camera: in the camera frame (a belief in the world frame
  needs the camera pose to be measured);
* volume: the product of the belief's dimensions.

Live, every belief is measured from the frame's viewpoint; from memory, each from the last view the store recorded
of its recording and frame (``viewpoints``: the camera pose and support plane kept with it), so that memory measures
what the frame did.

A belief that cannot be measured is left out of a selection (the note names it). Objects whose measures differ by
less than the measure's tolerance are a tie: the order among them is the answer's usual order (most likely to be
what was asked first), and the note says so.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from queries.selection import DISTANCE, HEIGHT, IMAGE_X, VOLUME, Measure, SelectionRequest
from reasoning.fusion.frame import WORLD_FRAME
from reasoning.fusion.tracking import ObjectBelief

LENGTH_TOLERANCE = 0.01
"""Metres within which two heights, x positions or distances tie: a segment's centroid moves by about a
centimetre between frames of a Kinect-class sensor at a metre (depth noise and the segment's edge pixels)."""

VOLUME_TOLERANCE = 0.1
"""Relative difference within which two volumes tie: each side of a 10-30 cm object measured to about a centimetre
leaves its box volume uncertain by about a tenth."""

IMAGE_UP = "up in the image, no support plane known"
SUPPORT_PLANE = "above the support plane"
WORLD_UP = "world z"
CAMERA = "camera frame"


@dataclass(frozen=True)
class Viewpoint:
    """Where the measures are taken from: the camera pose in the world frame (4x4, None when unknown) and the
    support plane ``(a, b, c, d)`` in the camera frame (None when none was found)."""

    cam_to_world: np.ndarray | None = None
    plane: np.ndarray | None = None


@dataclass(frozen=True, slots=True)
class SelectionNote:
    """How an answer was selected: the selection's name, its rank, the measure (``description``, ``unit``), what
    the measure was taken in (``basis``), each answered object's measure, whether the last one answered ties with
    the next (``tie_with``: that object's id) and the beliefs that could not be measured."""

    selection: str
    rank: int
    measure: str
    description: str
    unit: str
    basis: str
    values: tuple[tuple[int, float], ...]
    tie_with: int | None = None
    unmeasured: tuple[int, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (measures rounded to 6 decimals)."""
        return {
            "by": self.selection,
            "rank": self.rank,
            "measure": self.measure,
            "description": self.description,
            "unit": self.unit,
            "basis": self.basis,
            "values": [{"id": i, "value": round(v, 6)} for i, v in self.values],
            "tie_with": self.tie_with,
            "unmeasured": list(self.unmeasured),
        }

    def summary(self) -> str:
        """One line for people: ``selected top, greatest height (above the support plane): #2 0.183 m``."""
        ordinal = f" (rank {self.rank})" if self.rank != 1 else ""
        found = ", ".join(f"#{i} {_shown(v, self.unit)}" for i, v in self.values) or "nothing measurable"
        line = f"selected {self.selection}{ordinal}, {self.description} ({self.basis}): {found}"
        if self.tie_with is not None:
            line += f"; a tie with #{self.tie_with}"
        if self.unmeasured:
            why = "no dimensions" if self.unit == "m^3" else "no camera pose known to measure from"
            line += f"; not measured ({why}): {', '.join(f'#{i}' for i in self.unmeasured)}"
        return line


def _shown(value: float, unit: str) -> str:
    return f"{value * 1e6:.0f} cm^3" if unit == "m^3" else f"{value:.3f} {unit}"


def _in_camera(belief: ObjectBelief, viewpoint: Viewpoint) -> np.ndarray | None:
    """The belief's position in the camera frame, None when it is in the world frame and the pose is unknown."""
    position = np.asarray(belief.position, dtype=np.float64)
    if belief.frame != WORLD_FRAME:
        return position
    if viewpoint.cam_to_world is None:
        return None
    pose = np.asarray(viewpoint.cam_to_world, dtype=np.float64)
    return pose[:3, :3].T @ (position - pose[:3, 3])


def _basis(
    measure: Measure,
    beliefs: Sequence[ObjectBelief],
    viewpoint: Viewpoint,
    view_of: Callable[[ObjectBelief], Viewpoint],
) -> str:
    if measure is VOLUME:
        return "of the bounding box"
    if measure is not HEIGHT:
        return CAMERA
    if not beliefs:
        planes = viewpoint.plane is not None
    else:
        planes = all(view_of(b).plane is not None and _in_camera(b, view_of(b)) is not None for b in beliefs)
    if planes:
        return SUPPORT_PLANE
    if beliefs and all(b.frame == WORLD_FRAME for b in beliefs):
        return WORLD_UP
    return IMAGE_UP


def measure_of(belief: ObjectBelief, measure: Measure, viewpoint: Viewpoint, basis: str) -> float | None:
    """The belief's ``measure`` taken in ``basis`` (see the module docstring); None when it cannot be taken."""
    if measure is VOLUME:
        if belief.dimensions is None:
            return None
        return float(np.prod(np.asarray(belief.dimensions, dtype=np.float64)))
    if measure is HEIGHT and basis == WORLD_UP:
        return float(belief.position[2]) if belief.frame == WORLD_FRAME else None
    point = _in_camera(belief, viewpoint)
    if point is None:
        return None
    if measure is HEIGHT:
        if basis == SUPPORT_PLANE and viewpoint.plane is not None:
            plane = np.asarray(viewpoint.plane, dtype=np.float64)
            return float(plane[:3] @ point + plane[3])
        return float(-point[1])
    if measure is IMAGE_X:
        return float(point[0])
    if measure is DISTANCE:
        return float(np.linalg.norm(point))
    raise ValueError(f"no way to measure {measure.name}")


def _ties(measure: Measure, a: float, b: float) -> bool:
    if measure is VOLUME:
        return abs(a - b) <= VOLUME_TOLERANCE * max(abs(a), abs(b))
    return abs(a - b) <= LENGTH_TOLERANCE


def select(
    beliefs: Sequence[ObjectBelief],
    request: SelectionRequest,
    viewpoint: Viewpoint,
    limit: int | None = None,
    *,
    viewpoints: Callable[[ObjectBelief], Viewpoint] | None = None,
) -> tuple[list[ObjectBelief], SelectionNote]:
    """The beliefs ``request`` selects, in its order from its rank on (cut to ``limit``), and the note saying how.

    ``beliefs`` come in the answer's usual order, which decides among equal measures. Each is measured from
    ``viewpoint``, or, with ``viewpoints``, from the viewpoint it gives for that belief (memory: the last view of
    the belief's recording and frame)."""
    selection = request.selection
    measure = selection.measure

    def view_of(belief: ObjectBelief) -> Viewpoint:
        return viewpoint if viewpoints is None else viewpoints(belief)

    basis = _basis(measure, beliefs, viewpoint, view_of)
    measured: list[tuple[float, ObjectBelief]] = []
    unmeasured: list[int] = []
    for belief in beliefs:
        value = measure_of(belief, measure, view_of(belief), basis)
        if value is None or not np.isfinite(value):
            unmeasured.append(belief.id)
        else:
            measured.append((value, belief))
    sign = -1.0 if selection.greatest else 1.0
    measured.sort(key=lambda pair: sign * pair[0])  # stable: equal measures keep the usual answer order
    start = request.rank - 1
    end = None if limit is None else start + limit
    chosen = measured[start:end]
    following = measured[len(chosen) + start] if chosen and len(measured) > len(chosen) + start else None
    tie_with = None
    if following is not None and _ties(measure, chosen[-1][0], following[0]):
        tie_with = following[1].id
    note = SelectionNote(
        selection=selection.name,
        rank=request.rank,
        measure=measure.name,
        description=selection.description,
        unit=measure.unit,
        basis=basis,
        values=tuple((b.id, v) for v, b in chosen),
        tie_with=tie_with,
        unmeasured=tuple(unmeasured),
    )
    return [b for _, b in chosen], note


__all__ = ["LENGTH_TOLERANCE", "VOLUME_TOLERANCE", "SelectionNote", "Viewpoint", "measure_of", "select"]
