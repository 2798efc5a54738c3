"""A thin wide base under a narrower upright body: a cup on its saucer, a mug on a plate or a coaster.

Found on the hypothesis' own points in the upright support frame (z up), from its width over height: the points
below a step height form a flat layer (at most ``BASE_THICKNESS`` thick) whose footprint is wider than the points
above by at least ``1 / STEP_RATIO`` and at least as wide across (a layer spreads beyond the body both ways; the
near arc of a round body's foot, widened by depth noise, is as long but shallow), with ``BEYOND_SHARE`` of its
points beyond the body's footprint, and what stands above is an
upright body (at least as tall as the layer is thick) standing on the layer (its middle within the layer's
footprint; a spoon on a saucer may widen the layer to one side). The step is the lowest of ``STEP_HEIGHTS`` at
which that holds. A mug on the table, a bowl (narrower at its foot), a can on a can or a box on a box (the lower
one is no thin layer: its points above the step widen the body as much) has no such base; the form expert then
measures the whole hypothesis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, QhullError

BASE_THICKNESS = 0.03
"""A saucer, a plate or a coaster is at most about this thick (metres: a saucer 1.5-2.5 cm, a plate 2-3 cm)."""
STEP_HEIGHTS = (0.01, 0.015, 0.02, 0.025, BASE_THICKNESS)
"""The heights above the bottom tried as the step (metres): below 1 cm a layer is not told from the support's depth
noise; every half centimetre up to the thickest base."""
STEP_RATIO = 0.7
"""The body is at most this share of the base's width: a saucer is 1.5-2 times as wide as its cup, a plate more,
while a body's own foot, widened by depth noise or a rim, is within a third of the body's width."""
BEYOND = 0.01
"""A point of the layer lies beyond the body when farther than this (metres: depth noise and the grazing fringe
of a body's outline) outside the body's footprint box."""
BEYOND_SHARE = 1.0 / 3.0
"""At least this share of the layer's points lies beyond the body: a saucer or a plate seen from above shows its
ring in front of and beside the body; a body's own foot, widened by stray points (grazing ones are about a sixth of
a foot's points on the RealSense frames), puts at most about half as many there."""
MIN_POINTS = 20
"""The layer and the body each hold at least this many points (and the layer ``MIN_SHARE`` of all)."""
MIN_SHARE = 0.1
"""The layer holds at least this share of the points: a layer seen, not a few stray points at the foot."""


@dataclass(frozen=True)
class BaseLayer:
    """A thin wide base found under the body: the ``step`` height above the bottom (metres) where the body starts,
    the base's and the body's longer footprint extent (metres)."""

    step: float
    base_width: float
    body_width: float


def footprint_box(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The footprint box of Nx2 points: their mean, principal axes (rows) and the 2 % / 98 % quantiles along them
    (2x2: low row, high row)."""
    centre = xy.mean(axis=0)
    _, _, axes = np.linalg.svd(xy - centre, full_matrices=False)
    return centre, axes, np.quantile((xy - centre) @ axes.T, (0.02, 0.98), axis=0)


def footprint_extents(xy: np.ndarray) -> np.ndarray:
    """The longer and the shorter extent (2 % to 98 % along the principal axes) of Nx2 points."""
    span = footprint_box(xy)[2]
    return np.sort(span[1] - span[0])[::-1]


def beyond_share(layer: np.ndarray, body: np.ndarray) -> float:
    """The share of the Nx2 ``layer`` points farther than ``BEYOND`` outside the footprint box of the ``body``."""
    centre, axes, span = footprint_box(body)
    along = (layer - centre) @ axes.T
    return float(np.mean(np.any((along < span[0] - BEYOND) | (along > span[1] + BEYOND), axis=1)))


def _inside(xy: np.ndarray, outline: np.ndarray) -> bool:
    """Whether the point ``xy`` lies inside the convex hull of the Nx2 ``outline`` points."""
    try:
        return bool(Delaunay(outline).find_simplex(xy[None, :])[0] >= 0)
    except QhullError:
        return False


def find_base(points: np.ndarray, bottom: float, height: float) -> BaseLayer | None:
    """The thin wide base under a narrower upright body among the Nx3 upright ``points`` (see the module
    docstring), measured from ``bottom`` for ``height``; None when there is none."""
    z = points[:, 2] - bottom
    for step in STEP_HEIGHTS:
        below = z < step
        base, body = points[below, :2], points[~below, :2]
        if base.shape[0] < max(MIN_POINTS, MIN_SHARE * points.shape[0]) or body.shape[0] < MIN_POINTS:
            continue
        if height - step < step:  # what stands on the layer is no taller than the layer is thick: no body on it
            break
        base_extents, body_extents = footprint_extents(base), footprint_extents(body)
        wider = body_extents[0] <= STEP_RATIO * base_extents[0] and body_extents[1] <= base_extents[1]
        if wider and beyond_share(base, body) >= BEYOND_SHARE and _inside(np.median(body, axis=0), base):
            return BaseLayer(step=step, base_width=float(base_extents[0]), body_width=float(body_extents[0]))
    return None
