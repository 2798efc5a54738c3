"""The depth noise of a triangulating RGB-D sensor, and the height above a plane from which a point stands on it.

Structured-light (Kinect v1, PrimeSense, Xtion) and active-stereo (RealSense D400) sensors measure disparity and
turn it into depth by triangulation, z = f * b / d. A constant disparity error sigma_d becomes a depth error
sigma_z = z^2 * sigma_d / (f * b): the noise grows with the square of the depth, sigma_z = c * z^2.

* Kinect v1 / PrimeSense (the TUM RGB-D frames, the mOSD and PCL PCDs): Khoshelham & Elberink 2012, "Accuracy and
  resolution of Kinect depth data for indoor mapping applications", Sensors 12(2):1437-1454, eq. 17 and sec. 5:
  the random error grows quadratically and reaches 4 cm at the 5 m limit, c = 0.04 / 5^2 = 1.6e-3 per metre.
  At 2.5 m this is 1 cm, the lift above the plane the segmenters use: the range the tabletop tree reads first.
* RealSense D400 (the uoc frames): Intel's "Tuning depth cameras for best performance" (Grunnet-Jepsen et al.,
  2019) gives the RMS error as z^2 * subpixel / (f * b), subpixel about 0.08, so c = 0.08 / (f * b) with the
  focal length f in pixels and the baseline b (50 mm on a D435, 55 mm on a D415) from the camera's own
  calibration; it is not a constant of the format, so no default is given here for it.

The lift a point must clear to be a candidate object point is ``max(min_height, k * sigma_z(z))``: a desk read at
2.7 m scatters by more than the near lift, and points of it would otherwise stand "above" it and bridge objects.
With k = 1 and Kinect v1 the lift is today's 1 cm up to 2.5 m and grows beyond, so near frames are unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DepthNoise:
    """Depth noise sigma_z = ``coefficient`` * z^2 (metres, z in metres); ``source`` names where it comes from."""

    coefficient: float
    source: str

    def sigma(self, depth: np.ndarray | float) -> np.ndarray | float:
        """The standard deviation of the depth measured at ``depth`` metres."""
        return self.coefficient * np.square(depth)

    def depth_of(self, sigma: float) -> float:
        """The depth (metres) at which the noise reaches ``sigma`` metres."""
        return float(np.sqrt(sigma / self.coefficient))


KINECT_V1 = DepthNoise(
    coefficient=0.04 / 5.0**2,
    source="Khoshelham & Elberink 2012 (Sensors 12:1437): 4 cm random error at 5 m, quadratic in depth",
)
"""Kinect v1 / PrimeSense structured light (TUM RGB-D, mOSD, PCL frames)."""


def noise_lifted_heights(
    heights: np.ndarray, points: np.ndarray, mask: np.ndarray, noise: DepthNoise, min_height: float, k: float = 1.0
) -> np.ndarray:
    """``heights`` (HxW, above the plane) with every point of ``mask`` that does not clear ``k`` times the depth
    noise at its own depth set to 0 (on the plane), where that noise exceeds ``min_height``; ``heights`` itself
    when no point of ``mask`` lies that deep. ``points`` is the HxWx3 organized cloud ``heights`` was measured on."""
    deep = noise.depth_of(min_height / k)
    with np.errstate(invalid="ignore"):
        far = mask & (points[..., 2] > deep)
    if not far.any():
        return heights
    depth = points[..., 2][far]
    lifted = heights.copy()
    values = lifted[far]
    with np.errstate(invalid="ignore"):
        values[np.abs(values) <= k * noise.coefficient * depth * depth] = 0.0
    lifted[far] = values
    return lifted


def reaches_ceiling(heights: np.ndarray, depths: np.ndarray, max_height: float, noise: DepthNoise) -> bool:
    """Whether the highest of a segment's points (``heights`` above the plane at ``depths``, 1-D) comes within the
    depth noise at its depth of the candidates' ceiling ``max_height``: the segment was cut there and belongs to
    something taller than any object standing on the plane (a partition behind a desk, a cabinet)."""
    finite = np.isfinite(heights) & np.isfinite(depths)
    if not finite.any():
        return False
    top = int(np.argmax(np.where(finite, heights, -np.inf)))
    return bool(heights[top] >= max_height - noise.sigma(float(depths[top])))
