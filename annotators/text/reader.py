"""Text reading (OCR) on each object hypothesis with RapidOCR's ONNX models (they ship inside its wheel).

The hypothesis' image box is cropped with a margin and scaled up so its longer side is at least ``target_size``
pixels (small print becomes readable); the detector then works at most ``DETECTOR_SIDE`` pixels wide. The lines
read with a score of at least ``min_score`` become one Text per hypothesis, in reading order (top to bottom,
left to right), with the union of their boxes in image pixels and their mean score as confidence.

The engine is built once per annotator instance, lazily, on first use (about 0.3 s); a lock serialises its use
in case a cancelled run's worker is still finishing. Install without opencv-python (the project uses the headless
build): ``pip install --no-deps rapidocr-onnxruntime`` plus its other requirements (see the README).
"""

from __future__ import annotations

from typing import Any, ClassVar

import cv2
import numpy as np

from annotators.image.pixel_expert import image_and_hypotheses
from robokudo.core.capability import Capability
from robokudo.core.resources import Guarded
from robokudo.core.threaded import ThreadedAnnotator
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis, Text

DETECTOR_SIDE = 480
"""The text detector's input is scaled so that its longer side is at most this many pixels."""

MAX_UPSCALE = 4.0
"""Crops are enlarged at most this many times."""


def crop_box(roi: tuple[int, int, int, int], margin: int, shape: tuple[int, ...]) -> tuple[int, int, int, int] | None:
    """The ROI grown by ``margin`` pixels and clipped to an image of ``shape``; None when nothing is left."""
    x0, y0, x1, y1 = roi
    height, width = shape[:2]
    box = (max(0, x0 - margin), max(0, y0 - margin), min(width, x1 + margin), min(height, y1 + margin))
    return box if box[2] - box[0] >= 4 and box[3] - box[1] >= 4 else None


def reading_order(lines: list[tuple[np.ndarray, str, float]]) -> list[tuple[np.ndarray, str, float]]:
    """Text lines (4x2 corner array, text, score) sorted top to bottom, then left to right within a row."""
    if not lines:
        return lines
    heights = [float(np.ptp(box[:, 1])) for box, _, _ in lines]
    row = max(1.0, float(np.median(heights)) / 2)
    return sorted(lines, key=lambda line: (round(float(line[0][:, 1].min()) / row), float(line[0][:, 0].min())))


class TextReader(ThreadedAnnotator):
    """Reads the text printed on every object hypothesis (OCR); heavy, so it works in a thread."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Text,)
    capability: ClassVar[Capability] = Capability(
        label="text reader",
        synonyms=("OCR",),
        description="Reads the text printed on each object hypothesis (RapidOCR, ONNX models shipped in its wheel).",
        cost_ms=170.0,
        reliability=0.7,
    )

    def __init__(
        self,
        min_score: float = 0.6,
        margin: int = 8,
        target_size: int = 320,
        timeout: float = 60.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name, timeout=timeout)
        self.min_score = min_score
        self.margin = margin
        self.target_size = target_size

    def engine(self) -> Guarded[Any]:
        """The OCR engine with its lock, from this annotator's resources (built on first use: shared by every
        tree given the same pool); fails the run when RapidOCR is missing."""
        try:
            from rapidocr_onnxruntime import RapidOCR
        except ImportError as error:
            self.fail(f"OCR needs rapidocr-onnxruntime ({error}); install it as the README says")

        def build() -> Guarded[Any]:
            return Guarded(RapidOCR(det_limit_side_len=float(DETECTOR_SIDE), det_limit_type="max"))

        return self.resources.get(("rapidocr", DETECTOR_SIDE), build)

    def read(self, image: np.ndarray, roi: tuple[int, int, int, int]) -> Text | None:
        """The text read inside ``roi`` of the RGB ``image``, or None when nothing legible is there."""
        box = crop_box(roi, self.margin, image.shape)
        if box is None:
            return None
        x0, y0, x1, y1 = box
        crop = image[y0:y1, x0:x1]
        scale = min(MAX_UPSCALE, max(1.0, self.target_size / max(crop.shape[:2])))
        if scale > 1.0:
            crop = cv2.resize(crop, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
        bgr = np.ascontiguousarray(crop[..., ::-1])
        engine = self.engine()
        with engine.lock:
            result, _ = engine.value(bgr, use_cls=False)
        lines = [
            (np.asarray(corners, dtype=np.float64) / scale + (x0, y0), str(text).strip(), float(score))
            for corners, text, score in (result or [])
            if float(score) >= self.min_score and str(text).strip()
        ]
        if not lines:
            return None
        lines = reading_order(lines)
        corners = np.vstack([line[0] for line in lines])
        union = (
            int(np.floor(corners[:, 0].min())),
            int(np.floor(corners[:, 1].min())),
            int(np.ceil(corners[:, 0].max())),
            int(np.ceil(corners[:, 1].max())),
        )
        confidence = float(np.mean([line[2] for line in lines]))
        return Text(text=" ".join(line[1] for line in lines), box=union, confidence=confidence)

    def analyse(self) -> None:
        """Read every hypothesis' text; fail on broken input (finding no text is a success without Text)."""
        image, hypotheses = image_and_hypotheses(self, "read text on")
        usable = 0
        for hypothesis in hypotheses:
            if self.cancelled:
                return
            if hypothesis.mask.shape != image.shape[:2]:
                self.fail(f"hypothesis mask {hypothesis.mask.shape} and colour image {image.shape[:2]} sizes differ")
            if crop_box(hypothesis.roi, self.margin, image.shape) is None:
                continue
            usable += 1
            text = self.read(image, hypothesis.roi)
            if text is not None:
                self.attach(hypothesis, text)
        if usable == 0:
            self.fail("no object hypothesis has an image box to read text in")
