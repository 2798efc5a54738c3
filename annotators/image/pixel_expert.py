"""PixelExpert: the shared loop of experts that describe each object hypothesis from its colour pixels."""

from __future__ import annotations

from abc import abstractmethod
from typing import ClassVar

import cv2
import numpy as np

from robokudo.core.annotator import Annotator
from robokudo.core.types import Annotation, CasType, ColorImage, ObjectHypothesis


def hypothesis_pixels(image: np.ndarray, hypothesis: ObjectHypothesis, max_pixels: int = 2000) -> np.ndarray:
    """Up to ``max_pixels`` RGB pixels of the hypothesis, its outline left out when enough remain."""
    x0, y0, x1, y1 = hypothesis.roi
    local = hypothesis.mask[y0:y1, x0:x1]
    inner = cv2.erode(local.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)
    if np.count_nonzero(inner) >= max(20, np.count_nonzero(local) // 3):
        local = inner
    pixels = image[y0:y1, x0:x1][local]
    return pixels[:: max(1, pixels.shape[0] // max_pixels)]


def image_and_hypotheses(annotator: Annotator, purpose: str) -> tuple[np.ndarray, list[ObjectHypothesis]]:
    """The CAS's RGB image and object hypotheses; fails ``annotator`` when the image is not a non-empty HxWx3
    array or there is no hypothesis to ``purpose`` (the failure message's verb)."""
    image = annotator.view(ColorImage).image
    if image.ndim != 3 or image.shape[2] != 3 or image.size == 0:
        annotator.fail(f"colour image must be HxWx3, got shape {image.shape}")
    hypotheses = annotator.annotations(ObjectHypothesis)
    if not hypotheses:
        annotator.fail(f"no object hypotheses to {purpose}")
    return image, hypotheses


class PixelExpert(Annotator):
    """Attaches what :meth:`describe` says about the pixels of every hypothesis; fails on unusable input.

    Subclasses set ``outputs`` and ``purpose`` (the failure message's verb) and implement :meth:`describe`.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    purpose: ClassVar[str] = "describe"

    def __init__(self, max_pixels: int = 1000, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_pixels = max_pixels

    @abstractmethod
    def describe(self, pixels: np.ndarray) -> Annotation:
        """The annotation for one hypothesis from its RGB pixels (Nx3 uint8, N > 0)."""

    def analyse(self) -> None:
        """Describe each hypothesis with pixels; fail on missing or inconsistent input."""
        image, hypotheses = image_and_hypotheses(self, self.purpose)
        described = 0
        for hypothesis in hypotheses:
            if hypothesis.mask.shape != image.shape[:2]:
                self.fail(f"hypothesis mask {hypothesis.mask.shape} and colour image {image.shape[:2]} sizes differ")
            pixels = hypothesis_pixels(image, hypothesis, self.max_pixels)
            if pixels.shape[0] == 0:
                continue
            self.attach(hypothesis, self.describe(pixels))
            described += 1
        if described == 0:
            self.fail("every object hypothesis has an empty mask")
