"""The body of a round object as a surface of revolution: one vertical axis with a radius per height band.

Fitted to the points in the upright support frame (z up) by linear least squares: a point ``p`` at distance ``r_k``
from the axis through ``c`` satisfies ``|p|^2 = 2 c.p + (r_k^2 - |c|^2)``, linear in ``c`` and one offset per band
(solved by centring each band, which takes the offsets out and leaves a 2x2 system for ``c``).
Refitted twice without the points farther off the surface than ``OUTLIER_SPREAD`` robust standard deviations (a
handle, stray points), it follows a tapered mug or a bowl's curve where one circle fitted at the foot comes out too
wide (the camera sees only a half arc of it).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import ModuleType

import numpy as np

BANDS = 6
"""Height bands, each with its own radius."""
ROUNDS = 3
"""Fits: the first to all points, each further one without the previous fit's outliers."""
OUTLIER_SPREAD = 2.5
"""Points farther off the surface than this many robust standard deviations are left out of the next fit."""
MIN_SPREAD = 0.002
"""The robust standard deviation is taken as at least this (metres: the depth noise of a surface)."""


@dataclass(frozen=True)
class BodyProfile:
    """A vertical axis through ``centre`` (x, y) and the body's radius at each of ``heights`` (NaN: no points)."""

    centre: np.ndarray
    heights: np.ndarray
    radii: np.ndarray

    def radius_at(self, z: np.ndarray) -> np.ndarray:
        """The body's radius at heights ``z`` (interpolated between the bands' middles, constant beyond)."""
        known = np.isfinite(self.radii)
        return np.interp(z, self.heights[known], self.radii[known])


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.cloud.body_profile_loops`, imported (and numba with it) on first use."""
    from annotators.cloud import body_profile_loops

    return body_profile_loops


def body_profile(points: np.ndarray, bottom: float, height: float) -> BodyProfile | None:
    """The body profile of Nx3 upright ``points`` between ``bottom`` and ``bottom + height``; None when fewer than
    two bands hold points or the fit is degenerate."""
    z = points[:, 2] - bottom
    inside = (z >= 0.0) & (z <= height)
    xy, z = points[inside, :2], z[inside]
    edges = np.linspace(0.0, height, BANDS + 1)
    band = np.clip(np.searchsorted(edges, z, side="right") - 1, 0, BANDS - 1)
    keep = np.ones(z.size, dtype=bool)
    squares = (xy**2).sum(axis=1)
    loops = _loops()
    profile = None
    for _ in range(ROUNDS):
        # the band offsets taken out by centring each band (the same least-squares solution, a 2x2 system)
        counts, means, matrix, rhs = loops.band_system(xy, squares, band, keep, BANDS)
        present = counts > 0
        if np.count_nonzero(present) < 2 or np.count_nonzero(keep) < 3 + np.count_nonzero(present):
            break
        solution, *_ = np.linalg.lstsq(matrix, rhs, rcond=None)
        centre = solution
        if not np.all(np.isfinite(centre)):
            break
        radii = np.full(BANDS, np.nan)
        offsets = means[present, 2] - 2.0 * means[present, :2] @ centre
        radii[present] = np.sqrt(np.maximum(offsets + centre @ centre, 0.0))
        profile = BodyProfile(centre, (edges[:-1] + edges[1:]) / 2.0, radii)
        off = loops.surface_offsets(xy, band, centre, radii)
        spread = max(1.4826 * float(np.median(off[keep])), MIN_SPREAD)
        keep = off < OUTLIER_SPREAD * spread
    return profile
