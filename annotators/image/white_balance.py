"""White balance of a frame: the illuminant estimated by the grey-edge hypothesis, and the surround luminance.

Grey-edge (van de Weijer, Gevers and Gijsenij 2007, "Edge-based color constancy"): the average colour derivative
of a scene is achromatic, so the mean gradient magnitude per channel (first order, Minkowski norm 1, Gaussian
sigma 1 pixel at full size; computed on the half-size frame for speed) estimates the illuminant colour. It is
divided out in linear RGB (von Kries). Grey-world and the support plane are no good references on wooden or
coloured tables: they make the table grey instead of the light. The surround luminance is the median luminance of
the half-size frame after the gains (:func:`~annotators.image.radix_select.kth_smallest`).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from annotators.image.color_space import srgb_to_linear

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
"""Relative luminance Y of linear sRGB."""


@dataclass(frozen=True)
class FrameLight:
    """The light of one frame: linear-RGB white-balance gains and the surround's luminance after them."""

    gains: np.ndarray
    surround: float


NEUTRAL_LIGHT = FrameLight(gains=np.ones(3), surround=0.18)
"""No white-balance correction and a mid-grey surround (for pixels without their frame)."""


_UINT8_TO_LINEAR = srgb_to_linear(np.arange(256, dtype=np.uint8)).astype(np.float32)


def grey_edge_illuminant(linear: np.ndarray, clipped: np.ndarray | None = None, sigma: float = 1.0) -> np.ndarray:
    """The illuminant colour (3 values with mean 1) of a linear RGB image (HxWx3) by first-order grey-edge
    (p = 1); ``clipped`` (HxW bool) pixels are left out of the average when enough others remain."""
    return _grey_edge(linear, None if clipped is None else (~clipped).view(np.uint8), sigma)


def _grey_edge(linear: np.ndarray, unclipped: np.ndarray | None, sigma: float) -> np.ndarray:
    """:func:`grey_edge_illuminant` with the pixels to average given as an HxW uint8 mask (non-zero: kept)."""
    smooth = cv2.GaussianBlur(np.asarray(linear, dtype=np.float32), (0, 0), sigma)
    magnitude = cv2.magnitude(cv2.Sobel(smooth, cv2.CV_32F, 1, 0), cv2.Sobel(smooth, cv2.CV_32F, 0, 1))
    mask = unclipped if unclipped is not None and cv2.countNonZero(unclipped) >= 100 else None
    illuminant = np.array(cv2.mean(magnitude, mask=mask)[:3])
    if not np.all(illuminant > 0):
        return np.ones(3)
    return illuminant / illuminant.mean()


def estimate_frame_light(image: np.ndarray, max_gain: float = 2.0, scale: int = 2) -> FrameLight:
    """White-balance gains (grey-edge, each within ``1/max_gain..max_gain``) and surround luminance of an RGB
    frame (HxWx3 uint8), estimated on the frame reduced ``scale`` times (the grey-edge sigma shrinks with it)."""
    rgb = np.ascontiguousarray(image, dtype=np.uint8)
    if scale > 1:
        height, width = rgb.shape[:2]
        rgb = cv2.resize(rgb, (max(1, width // scale), max(1, height // scale)), interpolation=cv2.INTER_AREA)
    linear = cv2.LUT(rgb, _UINT8_TO_LINEAR.reshape(1, 256))
    unclipped = cv2.inRange(rgb, (0, 0, 0), (247, 247, 247)) & 1  # 1 where no channel reaches 248 (cv2.mean
    # sums in another order for a mask of 255s)
    gains = np.clip(1.0 / _grey_edge(linear, unclipped, sigma=1.0 / scale), 1.0 / max_gain, max_gain)
    from annotators.image.radix_select import kth_smallest  # numba is loaded with the first frame

    luminance = cv2.transform(linear, (gains * LUMINANCE).astype(np.float32).reshape(1, 3)).reshape(-1)
    surround = kth_smallest(luminance, luminance.size // 2)
    return FrameLight(gains=gains, surround=max(surround, 1e-4))
