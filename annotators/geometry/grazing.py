"""Grazing points: measured pixels whose surface runs nearly along the camera's line of sight.

Where a line of sight grazes a surface, or crosses a depth jump (a pixel mixing the depth of an object's outline
with the depth behind or in front of it), the points of neighbouring pixels lie one behind the other along the line
of sight instead of side by side: streaks of stray points that stick out of an object's outline seen from above.
A pixel is grazing when, to one of its 4-neighbours on the grid, the step between their points runs more than
``ratio`` times as far along its line of sight as across it (the surface is within ``atan(1 / ratio)`` of the line of
sight); no surface is measured reliably at such an angle.
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np

GRAZING_RATIO = 5.0
"""A surface seen within about 11 degrees (atan(1/5)) of the line of sight is grazing."""


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.grazing_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import grazing_loops

    return grazing_loops


def grazing_pixels(points: np.ndarray, pixels: np.ndarray, ratio: float = GRAZING_RATIO) -> np.ndarray:
    """Which of the flat ``pixels`` of the HxWx3 camera-frame ``points`` are grazing (see the module docstring);
    a pixel without a finite point, or whose neighbours have none, is not. A compiled loop over the pixels
    (:mod:`annotators.geometry.grazing_loops`)."""
    return _loops().grazing_pixels(points, np.asarray(pixels, dtype=np.int64).reshape(-1), float(ratio))
