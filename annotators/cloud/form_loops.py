"""The compiled loops behind :mod:`annotators.cloud.form` (numba, machine code cached on disk next to this file).
Importing this module imports numba; :mod:`~annotators.cloud.form` imports it on first use.

Dot products are added term by term in order, without fused multiply-adds: they agree with NumPy's matrix
products (BLAS, which may fuse) to rounding, not always bit for bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sight_runs(tested: np.ndarray, sight: np.ndarray, equations: np.ndarray) -> np.ndarray:
    """Per Mx3 ``tested`` point with unit line of sight ``sight``: how far the line of sight runs inside the convex
    hull of the faces ``equations`` (Fx4: outward normal, offset): ``max(min_j r_j, 0)`` with
    ``r_j = -(tested . n_j + o_j) / (sight . n_j)`` over the faces it runs towards (``sight . n_j > 1e-12``),
    infinite without such a face; NaN where a distance is NaN."""
    runs = np.empty(tested.shape[0], dtype=np.float64)
    for i in range(tested.shape[0]):
        least = np.inf
        for j in range(equations.shape[0]):
            nx, ny, nz = equations[j, 0], equations[j, 1], equations[j, 2]
            toward = sight[i, 0] * nx + sight[i, 1] * ny + sight[i, 2] * nz
            if toward > 1e-12:
                inside = -(tested[i, 0] * nx + tested[i, 1] * ny + tested[i, 2] * nz + equations[j, 3])
                reach = inside / toward
                if reach < least or reach != reach:
                    least = reach
                    if reach != reach:
                        break
        runs[i] = least if (least > 0.0 or least != least) else 0.0
    return runs


@njit(cache=True, nogil=True)
def within_outline(xy: np.ndarray, equations: np.ndarray, margin: float) -> np.ndarray:
    """Which Mx2 points ``xy`` lie within ``margin`` of (or inside) the convex outline of the edges ``equations``
    (Ex3: outward normal, offset): no edge's signed distance exceeds ``margin`` (a NaN distance: not within)."""
    within = np.empty(xy.shape[0], dtype=np.bool_)
    for i in range(xy.shape[0]):
        inside = True
        for j in range(equations.shape[0]):
            distance = xy[i, 0] * equations[j, 0] + xy[i, 1] * equations[j, 1] + equations[j, 2]
            if not distance <= margin:
                inside = False
                break
        within[i] = inside
    return within
