"""Text reading (OCR) with RapidOCR's ONNX models (they ship inside its wheel): one pass over the whole frame.

The detector and recogniser run once per frame on the whole colour image (the detector sees at most
``DETECTOR_SIDE`` pixels on the longer side; a 640x480 frame is read at its own size). The lines read with a score
of at least ``min_score`` are given to the object hypotheses they overlap most (:mod:`annotators.text.lines`), so a
hypothesis cut too small by the segmentation still gets the whole line running across it, and the cost does not
grow with the number of hypotheses. Each hypothesis with lines gets one Text: the lines in reading order, the
union of their boxes in image pixels and their mean score as confidence.

The engine is built once per resource pool, lazily, on first use (about 0.3 s); a lock serialises its use in
case a cancelled run's worker is still finishing. Install without opencv-python (the project uses the headless
build): ``pip install --no-deps rapidocr-onnxruntime`` plus its other requirements (see the README).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from annotators.image.pixel_expert import image_and_hypotheses
from annotators.text.lines import MIN_OVERLAP, TextLine, assign_lines, text_of
from robokudo.core.capability import Capability
from robokudo.core.resources import Guarded, SharedResources
from robokudo.core.threaded import ThreadedAnnotator
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis, Text

DETECTOR_SIDE = 960
"""The text detector's input is scaled so that its longer side is at most this many pixels."""


def ocr_engine(resources: SharedResources) -> Guarded[Any]:
    """The RapidOCR engine with its lock from ``resources`` (built on first use); ImportError without RapidOCR."""
    from rapidocr_onnxruntime import RapidOCR

    def build() -> Guarded[Any]:
        return Guarded(RapidOCR(det_limit_side_len=float(DETECTOR_SIDE), det_limit_type="max"))

    return resources.get(("rapidocr", DETECTOR_SIDE), build)


def read_lines(engine: Guarded[Any], image: np.ndarray, min_score: float) -> list[TextLine]:
    """The text lines RapidOCR reads on the RGB ``image`` with a score of at least ``min_score``."""
    bgr = np.ascontiguousarray(image[..., ::-1])
    with engine.lock:
        result, _ = engine.value(bgr, use_cls=False)
    return [
        TextLine(np.asarray(corners, dtype=np.float64), str(text).strip(), float(score))
        for corners, text, score in (result or [])
        if float(score) >= min_score and str(text).strip()
    ]


class TextReader(ThreadedAnnotator):
    """Reads the text printed on the objects: one OCR pass per frame, lines given to hypotheses by overlap."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Text,)
    capability: ClassVar[Capability] = Capability(
        label="text reader",
        synonyms=("OCR",),
        description="Reads the text printed on the objects: RapidOCR (ONNX models shipped in its wheel) once on "
        "the whole frame, each line given to the hypothesis it overlaps most.",
        cost_ms=400.0,
        reliability=0.7,
    )

    def __init__(
        self,
        min_score: float = 0.6,
        min_overlap: float = MIN_OVERLAP,
        timeout: float = 60.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name, timeout=timeout)
        if not 0.0 < min_overlap <= 1.0:
            raise ValueError(f"min_overlap must be in (0, 1], got {min_overlap}")
        self.min_score = min_score
        self.min_overlap = min_overlap

    def engine(self) -> Guarded[Any]:
        """The OCR engine with its lock, from this annotator's resources (shared by every tree given the same
        pool); fails the run when RapidOCR is missing."""
        try:
            return ocr_engine(self.resources)
        except ImportError as error:
            self.fail(f"OCR needs rapidocr-onnxruntime ({error}); install it as the README says")

    def analyse(self) -> None:
        """Read the frame once and attach each hypothesis' lines as a Text; fail on broken input (finding no
        text is a success without Text)."""
        image, hypotheses = image_and_hypotheses(self, "read text on")
        for hypothesis in hypotheses:
            if hypothesis.mask.shape != image.shape[:2]:
                self.fail(f"hypothesis mask {hypothesis.mask.shape} and colour image {image.shape[:2]} sizes differ")
            x0, y0, x1, y1 = hypothesis.roi
            if x1 <= max(x0, 0) or y1 <= max(y0, 0) or x0 >= image.shape[1] or y0 >= image.shape[0]:
                self.fail(f"hypothesis box {hypothesis.roi} lies outside the {image.shape[1]}x{image.shape[0]} image")
        lines = read_lines(self.engine(), image, self.min_score)
        if self.cancelled:
            return
        for index, assigned in sorted(assign_lines(lines, hypotheses, self.min_overlap).items()):
            self.attach(hypotheses[index], text_of(assigned))
