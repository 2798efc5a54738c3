"""Compiled passes over a labelling for :mod:`annotators.geometry.support`: the per-piece summary its joins read,
made in one pass over the label image instead of whole-array numpy with a sort of every sampled pixel.

The kernels give exactly what the numpy expressions they replace give (sizes, heights picked from the input with
the same float32 rounding, the same sampled feet). They are compiled by numba on first use (numba is imported
then, not with this module) and the machine code is cached on disk next to the loops.
"""

from __future__ import annotations

import functools
from types import ModuleType

import numpy as np


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.geometry.support_loops`, imported (and numba with it) on first use."""
    from annotators.geometry import support_loops

    return support_loops


def piece_summary(
    labels: np.ndarray, plane_points: np.ndarray, step: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(sizes, low, high, top, feet, starts)`` of HxW non-negative integer ``labels``: each label's pixel count
    (int64), the 5 %, 95 % and 99 % of the heights (``plane_points[..., 2]``, HxWx3 float32, clipped to +-0.49
    metres and rounded as float32 ``height + 0.5``; NaN without one) on every ``step``-th pixel with a finite
    height, and those pixels' ``(u, v)`` (Nx2 float32, row-major within a label; label k owns
    ``feet[starts[k]:starts[k + 1]]``)."""
    return _loops().piece_summary(
        np.ascontiguousarray(labels), np.ascontiguousarray(plane_points, dtype=np.float32), max(1, int(step))
    )
