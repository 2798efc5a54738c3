"""Object hypotheses from colour alone: regions that stand out from the supporting surface (no depth needed).

A fallback segmenter for inputs without depth (or objects depth cannot see, such as glass). On every ``stride``-th
pixel the supporting surface's colour is taken as the median colour (CIE Lab) of the lower middle of the image,
where a robot looking at a table sees the table; pixels whose colour differs from it by more than ``threshold``
(and by more than ``spread`` times the surface's own variation there) are candidates. They are cleaned by a
morphological opening and closing; each 8-connected region of at least ``min_area`` pixels that does not touch
the image border (walls, floor and the table's edges do) and covers at most ``max_share`` of the image becomes an
ObjectHypothesis. Its ``point_indices`` are the flat indices of its pixels on the image grid (the organized grid of
any cloud made from the image).
"""

from __future__ import annotations

from typing import ClassVar

import cv2
import numpy as np

from annotators.geometry.grid_segmentation import bounding_box
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis


def surface_difference(image: np.ndarray) -> tuple[np.ndarray, float]:
    """Per-pixel Lab distance (HxW float32) from the median colour of the image's lower middle, and the typical
    (median absolute) deviation of that region."""
    lab = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2LAB).astype(np.float32)
    rows, cols = lab.shape[:2]
    sample = lab[rows * 2 // 3 : rows * 14 // 15, cols // 4 : cols * 3 // 4].reshape(-1, 3)
    surface = np.median(sample, axis=0)
    distance = np.linalg.norm(lab - surface, axis=2)
    deviation = float(np.median(np.linalg.norm(sample - surface, axis=1)))
    return distance, deviation


class ImageRegionSegmenter(Annotator):
    """Segments the regions that stand out in colour from the supporting surface into object hypotheses."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis,)
    capability: ClassVar[Capability] = Capability(
        label="image region segmenter",
        description=(
            "Regions standing out in colour from the supporting surface become object hypotheses (no depth needed)."
        ),
        cost_ms=4.0,
        reliability=0.5,
    )

    def __init__(
        self,
        threshold: float = 35.0,
        spread: float = 3.0,
        min_area: int = 400,
        max_share: float = 0.3,
        stride: int = 2,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.threshold = threshold
        self.spread = spread
        self.min_area = min_area
        self.max_share = max_share
        self.stride = max(1, stride)

    def analyse(self) -> None:
        """Write one ObjectHypothesis per region; fail when nothing stands out."""
        image = self.view(ColorImage).image
        if image.ndim != 3 or image.shape[2] != 3 or min(image.shape[:2]) < 8 * self.stride:
            self.fail(f"colour image must be HxWx3 and at least {8 * self.stride} pixels wide, got {image.shape}")
        step = self.stride
        distance, deviation = surface_difference(image[::step, ::step])
        limit = max(self.threshold, self.spread * deviation)
        candidates = (distance > limit).astype(np.uint8)
        kernel = np.ones((3, 3), np.uint8)
        candidates = cv2.morphologyEx(candidates, cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
        candidates = cv2.morphologyEx(candidates, cv2.MORPH_CLOSE, kernel)
        count, labels, stats, _ = cv2.connectedComponentsWithStats(candidates, connectivity=8)
        rows, cols = candidates.shape
        height, width = image.shape[:2]
        found = 0
        for label in range(1, count):
            x, y, w, h, area = stats[label]
            touches = x == 0 or y == 0 or x + w == cols or y + h == rows
            if touches or area * step * step < self.min_area or area > self.max_share * rows * cols:
                continue
            coarse = labels == label
            mask = np.repeat(np.repeat(coarse, step, axis=0), step, axis=1)[:height, :width]
            full = np.zeros((height, width), dtype=bool)
            full[: mask.shape[0], : mask.shape[1]] = mask
            self.write(ObjectHypothesis(point_indices=np.flatnonzero(full), mask=full, roi=bounding_box(full)))
            found += 1
        if found == 0:
            self.fail(f"no region stands out from the supporting surface's colour (by more than {limit:.0f} Lab)")
