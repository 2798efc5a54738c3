"""Text lines read on a whole frame and their assignment to object hypotheses by overlap.

A :class:`TextLine` is one line the OCR read: its four corners in image pixels, the text and the recogniser's
score. :func:`assign_lines` gives every line to the hypothesis it overlaps most, so a hypothesis that was cut
too small (half a box) still gets the whole line that runs across it, and no line is given twice.

Overlap of a line with a hypothesis is the mean of two shares of the line's axis-aligned box: the share inside
the hypothesis' image box (ROI) and the share covered by its mask. The mask tells apart an object in front from
one behind whose ROI also contains the line; the ROI keeps a line whose pixels the segmentation missed (glossy
print, depth holes). A line goes to no hypothesis when its best overlap is below ``min_overlap``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robokudo.core.types import ObjectHypothesis, Text

MIN_OVERLAP = 0.25
"""Default least overlap (see the module docstring) for a line to belong to a hypothesis."""


@dataclass(frozen=True, eq=False)
class TextLine:
    """One line of text read on the image: ``corners`` (4x2, x and y in pixels), its text and score in [0, 1]."""

    corners: np.ndarray
    text: str
    score: float

    def box(self) -> tuple[int, int, int, int]:
        """The line's axis-aligned box ``(x0, y0, x1, y1)`` in whole pixels (x1, y1 exclusive)."""
        xs, ys = self.corners[:, 0], self.corners[:, 1]
        return int(np.floor(xs.min())), int(np.floor(ys.min())), int(np.ceil(xs.max())), int(np.ceil(ys.max()))


def reading_order(lines: Sequence[TextLine]) -> list[TextLine]:
    """The lines sorted top to bottom, then left to right within a row (half a median line height)."""
    if not lines:
        return []
    heights = [float(np.ptp(line.corners[:, 1])) for line in lines]
    row = max(1.0, float(np.median(heights)) / 2)

    def key(line: TextLine) -> tuple[int, float]:
        return round(float(line.corners[:, 1].min()) / row), float(line.corners[:, 0].min())

    return sorted(lines, key=key)


def overlap(line: TextLine, hypothesis: ObjectHypothesis) -> float:
    """How much of ``line`` lies on ``hypothesis``: the mean of its ROI share and its mask share (see the module)."""
    height, width = hypothesis.mask.shape
    x0, y0, x1, y1 = line.box()
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(width, x1), min(height, y1)
    if x1 <= x0 or y1 <= y0:
        return 0.0
    area = float((x1 - x0) * (y1 - y0))
    rx0, ry0, rx1, ry1 = hypothesis.roi
    roi_area = max(0, min(x1, rx1) - max(x0, rx0)) * max(0, min(y1, ry1) - max(y0, ry0))
    mask_area = float(np.count_nonzero(hypothesis.mask[y0:y1, x0:x1]))
    return 0.5 * (roi_area / area + mask_area / area)


def assign_lines(
    lines: Sequence[TextLine], hypotheses: Sequence[ObjectHypothesis], min_overlap: float = MIN_OVERLAP
) -> dict[int, list[TextLine]]:
    """Per hypothesis index, the lines it overlaps most (at least ``min_overlap``; ties go to the earlier one)."""
    if not 0.0 < min_overlap <= 1.0:
        raise ValueError(f"min_overlap must be in (0, 1], got {min_overlap}")
    assigned: dict[int, list[TextLine]] = {}
    for line in lines:
        shares = [overlap(line, hypothesis) for hypothesis in hypotheses]
        if not shares:
            break
        best = int(np.argmax(shares))
        if shares[best] >= min_overlap:
            assigned.setdefault(best, []).append(line)
    return assigned


def text_of(lines: Sequence[TextLine]) -> Text:
    """One Text from the lines of one hypothesis: their texts in reading order, the union of their boxes and the
    mean score as confidence; ValueError without lines."""
    if not lines:
        raise ValueError("a Text needs at least one line")
    ordered = reading_order(lines)
    corners = np.vstack([line.corners for line in ordered])
    union = (
        int(np.floor(corners[:, 0].min())),
        int(np.floor(corners[:, 1].min())),
        int(np.ceil(corners[:, 0].max())),
        int(np.ceil(corners[:, 1].max())),
    )
    confidence = float(np.mean([line.score for line in ordered]))
    return Text(text=" ".join(line.text for line in ordered), box=union, confidence=confidence)
