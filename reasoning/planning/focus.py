"""Where an inspection looks: a box around the object the belief store holds, as a region the planner can apply.

``inspect object 3`` refines one believed object. Its plan keeps only the points of a box around where the object
is believed to be (:func:`object_focus`): a cube of the object's largest believed extent (a belief's extents are
not along the world axes) grown by :data:`FOCUS_MARGIN` on every side, reaching :data:`SUPPORT_DEPTH` further down
so that the surface it stands on is inside (the segmentation finds the object as what stands on that surface).
The box is a :class:`~robokudo.core.regions.RegionBox` in the belief's frame, so the region filter the planner adds
for regions applies it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robokudo.core.geometry import IDENTITY_QUATERNION
from robokudo.core.regions import RegionBox

FOCUS_MARGIN = 0.08
"""Metres added around the believed object on every side (its pose may be off by a few centimetres)."""
SUPPORT_DEPTH = 0.06
"""Metres the box reaches below the object's believed bottom (the supporting surface)."""
DEFAULT_EXTENT = 0.12
"""The object's size along each axis when the belief has none (metres)."""
FOCUS_FRAME = "world"
"""The frame a focus box needs: the region filter places the points in the world with the camera pose."""


def focus_name(object_id: int) -> str:
    """The region name of the box around object ``object_id`` (``object 3``)."""
    return f"object {object_id}"


def object_focus(
    object_id: int, position: Sequence[float], dimensions: Sequence[float] | None, frame: str
) -> RegionBox | None:
    """The box to inspect object ``object_id`` in: upright (z up) around its believed ``position``, sized by its
    largest believed extent (``dimensions`` None: :data:`DEFAULT_EXTENT`); None when the belief is not in the world
    frame (then no camera pose places the points, and the whole view is searched)."""
    if frame != FOCUS_FRAME:
        return None
    centre = np.asarray(position, dtype=np.float64).reshape(3)
    size = np.full(3, DEFAULT_EXTENT) if dimensions is None else np.asarray(dimensions, dtype=np.float64).reshape(3)
    if not (np.all(np.isfinite(centre)) and np.all(np.isfinite(size))):
        raise ValueError(f"object {object_id} has no finite position and size to inspect around")
    largest = float(np.max(size))  # beliefs keep extents largest first, not along the world axes
    across = largest + 2 * FOCUS_MARGIN  # any orientation of the object fits
    bottom = centre[2] - largest / 2 - SUPPORT_DEPTH
    top = centre[2] + largest / 2 + FOCUS_MARGIN
    return RegionBox(
        name=focus_name(object_id),
        region_class="",
        frame=frame,
        position=(float(centre[0]), float(centre[1]), float((bottom + top) / 2)),
        orientation=IDENTITY_QUATERNION,
        size=(across, across, float(top - bottom)),
        label=f"around object {object_id}",
    )
