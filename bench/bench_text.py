"""Text reading cost per frame: one OCR pass over the whole frame vs one pass per hypothesis crop, side by side.

On the real uoc frames 000000-000004 (../shared/data/uoc_tabletop_realsense) the tabletop tree makes the
hypotheses; then, in one run and on the same shared RapidOCR engines, each frame is read (a) the way TextReader
reads it now, once on the whole frame with the lines given to hypotheses by overlap, and (b) the way it used to,
once per hypothesis on its box grown by 8 px and enlarged to 320 px (at most 4x). Printed per frame: ms of each,
OCR passes, and on which hypotheses a query word of the frame's print is found.

Goal: the whole-frame pass costs less per frame than the crops (ratio < 1) and finds "CHEEZ" on the Cheez-It box
in every frame that shows it.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from py_trees.common import Status  # noqa: E402

from annotators.readers.choice import reader_for  # noqa: E402
from annotators.text.lines import TextLine, assign_lines, text_of  # noqa: E402
from annotators.text.reader import ocr_engine, read_lines  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.resources import Guarded, SharedResources  # noqa: E402
from robokudo.core.text_match import text_matches  # noqa: E402
from robokudo.core.types import ColorImage, ObjectHypothesis  # noqa: E402
from trees.tabletop import create_pipeline  # noqa: E402

UOC = ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense"
CHEEZ_IT = {0: (500, 250), 1: (480, 320), 2: (260, 70), 3: (260, 70)}
"""A pixel inside the Cheez-It box, per frame that shows it."""
RUNS = 3
MIN_SCORE = 0.6


def crop_engine(pool: SharedResources) -> Guarded:
    """The engine the per-crop reader used (detector input at most 480 px)."""
    from rapidocr_onnxruntime import RapidOCR

    return pool.get(("crop", 480), lambda: Guarded(RapidOCR(det_limit_side_len=480.0, det_limit_type="max")))


def per_crop(engine: Guarded, image: np.ndarray, hypotheses: list[ObjectHypothesis]) -> dict[int, str]:
    """The old way: one OCR pass per hypothesis on its enlarged box crop; the text read per hypothesis."""
    texts = {}
    for index, hypothesis in enumerate(hypotheses):
        x0, y0, x1, y1 = hypothesis.roi
        x0, y0 = max(0, x0 - 8), max(0, y0 - 8)
        x1, y1 = min(image.shape[1], x1 + 8), min(image.shape[0], y1 + 8)
        crop = image[y0:y1, x0:x1]
        scale = min(4.0, max(1.0, 320 / max(crop.shape[:2])))
        if scale > 1.0:
            crop = cv2.resize(crop, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
        lines = [
            TextLine(line.corners / scale + (x0, y0), line.text, line.score)
            for line in read_lines(engine, crop, MIN_SCORE)
        ]
        if lines:
            texts[index] = text_of(lines).text
    return texts


def whole_frame(engine: Guarded, image: np.ndarray, hypotheses: list[ObjectHypothesis]) -> dict[int, str]:
    """The new way: one OCR pass over the frame, lines given by overlap; the text read per hypothesis."""
    lines = read_lines(engine, image, MIN_SCORE)
    return {index: text_of(group).text for index, group in assign_lines(lines, hypotheses).items()}


def timed(function, *args) -> tuple[float, dict[int, str]]:
    """Median ms of ``RUNS`` calls and the last result."""
    times, result = [], {}
    for _ in range(RUNS):
        start = time.perf_counter()
        result = function(*args)
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times)), result


def main() -> int:
    if not UOC.is_dir():
        print(f"no data at {UOC}")
        return 1
    pool = SharedResources()
    whole_engine, old_engine = ocr_engine(pool), crop_engine(pool)
    blank = np.full((64, 64, 3), 255, np.uint8)
    read_lines(whole_engine, blank, MIN_SCORE), read_lines(old_engine, blank, MIN_SCORE)  # load the models
    print(f"{'frame':>5} {'hyps':>4} {'whole ms':>9} {'crops ms':>9} {'ratio':>6}  CHEEZ on the box (whole / crops)")
    ratios, found_all = [], True
    for frame in range(5):
        root = create_pipeline(reader_for(str(UOC), frame))
        if Engine(root).tick() is not Status.SUCCESS:
            print(f"frame {frame}: the tabletop tree failed")
            return 1
        image = root.cas.view(ColorImage).image
        hypotheses = root.cas.annotations(ObjectHypothesis)
        whole_ms, whole_texts = timed(whole_frame, whole_engine, image, hypotheses)
        crop_ms, crop_texts = timed(per_crop, old_engine, image, hypotheses)
        ratios.append(whole_ms / crop_ms)
        shown = "-"
        if frame in CHEEZ_IT:
            x, y = CHEEZ_IT[frame]
            box = next(i for i, h in enumerate(hypotheses) if h.mask[y, x])
            whole_hit = text_matches("CHEEZ", whole_texts.get(box, ""))
            crop_hit = text_matches("CHEEZ", crop_texts.get(box, ""))
            found_all &= whole_hit
            shown = f"{whole_hit} {whole_texts.get(box)!r} / {crop_hit} {crop_texts.get(box)!r}"
        print(f"{frame:>5} {len(hypotheses):>4} {whole_ms:>9.0f} {crop_ms:>9.0f} {ratios[-1]:>6.2f}  {shown}")
    mean = float(np.mean(ratios))
    met = mean < 1.0 and found_all
    print(f"whole-frame / per-crop cost: mean ratio {mean:.2f} (1 OCR pass per frame vs 1 per hypothesis)")
    print(f"goal: ratio < 1 and CHEEZ found on the box in every frame showing it -> {'met' if met else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
