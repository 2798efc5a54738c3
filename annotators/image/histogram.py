"""Colour histograms: a normalised hue/saturation histogram of every hypothesis' pixels (appearance matching).

Hue (OpenCV's full 0-255 range) and saturation get ``bins`` bins each; pixels darker than ``MIN_VALUE`` (whose
hue is noise) are left out unless nothing else remains. The histogram sums to 1.
"""

from __future__ import annotations

from typing import ClassVar

import cv2
import numpy as np

from annotators.image.pixel_expert import PixelExpert
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ColorHistogram

MIN_VALUE = 30
"""Pixels with a value (brightness, 0-255) below this are left out of the histogram when others remain."""


def hue_saturation_histogram(rgb: np.ndarray, bins: tuple[int, int]) -> np.ndarray:
    """A ``bins``-shaped float32 histogram over hue x saturation of N RGB pixels (Nx3 uint8), summing to 1."""
    hsv = cv2.cvtColor(np.ascontiguousarray(rgb, dtype=np.uint8).reshape(-1, 1, 3), cv2.COLOR_RGB2HSV_FULL)
    bright = hsv[:, 0, 2] >= MIN_VALUE
    if bright.any():
        hsv = hsv[bright]
    histogram = cv2.calcHist([hsv], [0, 1], None, list(bins), [0, 256, 0, 256])
    total = float(histogram.sum())
    return (histogram / total).astype(np.float32) if total > 0 else histogram.astype(np.float32)


class ColorHistogramAnnotator(PixelExpert):
    """Attaches a normalised hue/saturation ColorHistogram to every object hypothesis."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorHistogram,)
    capability: ClassVar[Capability] = Capability(
        label="colour histogram annotator",
        cost_ms=2.5,
        reliability=0.9,
    )

    def __init__(self, bins: tuple[int, int] = (16, 4), max_pixels: int = 4000, name: str | None = None) -> None:
        super().__init__(max_pixels=max_pixels, name=name)
        if len(bins) != 2 or min(bins) < 1:
            raise ValueError(f"bins must be two positive counts (hue, saturation), got {bins}")
        self.bins = (int(bins[0]), int(bins[1]))

    def describe(self, pixels: np.ndarray) -> ColorHistogram:
        """The hue/saturation histogram of the pixels."""
        return ColorHistogram(histogram=hue_saturation_histogram(pixels, self.bins), bins=self.bins)
