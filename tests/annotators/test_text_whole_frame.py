"""Text read once on the whole frame and given to hypotheses by overlap (issue 15, item 4).

On the real uoc frames the Cheez-It box's print is read by one pass over the frame and found by the query word
"CHEEZ" (and by "CHEEL", one OCR error in five letters); a hypothesis holding only half of the box still gets the
whole line running across it, and a box cut into two hypotheses has each line on one of them, none twice. The
assignment rule is checked on synthetic masks for all inputs.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from py_trees.common import Status

from annotators.readers.choice import reader_for
from annotators.text.lines import TextLine, assign_lines, overlap, text_of
from annotators.text.reader import TextReader
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.text_match import text_matches
from robokudo.core.types import ColorImage, ObjectHypothesis, SemanticColor, Text
from trees.tabletop import create_pipeline

CHEEZ_IT = {0: (500, 250), 1: (480, 320)}
"""A pixel inside the Cheez-It box in uoc frames 0 (tuning frame of the labels) and 1."""


class _Given(Annotator):
    """Writes a colour image and hypotheses (test helper)."""

    outputs = (ColorImage, ObjectHypothesis)

    def __init__(self, image: np.ndarray, hypotheses: list[ObjectHypothesis]) -> None:
        super().__init__(name="given")
        self.items = (ColorImage(image), *hypotheses)

    def analyse(self) -> None:
        for item in self.items:
            self.write(item)


def read(image: np.ndarray, hypotheses: list[ObjectHypothesis]) -> list[ObjectHypothesis]:
    """Run one TextReader over ``hypotheses`` on ``image``; the hypotheses as the reader left them."""
    fresh = [replace(h, annotations=[]) for h in hypotheses]
    reader = TextReader()
    pipeline = Pipeline("ocr", [_Given(image, fresh), reader])
    deadline = time.monotonic() + 120
    pipeline.tick_once()
    while reader.status is Status.RUNNING and time.monotonic() < deadline:
        time.sleep(0.01)
        pipeline.tick_once()
    assert reader.status is Status.SUCCESS, reader.feedback_message
    return fresh


def box_mask(shape: tuple[int, int], roi: tuple[int, int, int, int]) -> np.ndarray:
    mask = np.zeros(shape, bool)
    mask[roi[1] : roi[3], roi[0] : roi[2]] = True
    return mask


def hypothesis_from(mask: np.ndarray) -> ObjectHypothesis:
    """A hypothesis of the pixels in ``mask`` (its ROI the mask's box)."""
    ys, xs = np.nonzero(mask)
    roi = (int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1)
    return ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)


@pytest.fixture(scope="module", params=sorted(CHEEZ_IT))
def uoc_frame(request: pytest.FixtureRequest, uoc_folder: Path) -> tuple[np.ndarray, list[ObjectHypothesis], int]:
    """A uoc frame's image, the tabletop tree's hypotheses and the index of the Cheez-It box among them."""
    root = create_pipeline(reader_for(str(uoc_folder), request.param))
    assert Engine(root).tick() is Status.SUCCESS, [(c.name, c.feedback_message) for c in root.children]
    hypotheses = root.cas.annotations(ObjectHypothesis)
    x, y = CHEEZ_IT[request.param]
    (box,) = [i for i, h in enumerate(hypotheses) if h.mask[y, x]]
    return root.cas.view(ColorImage).image, hypotheses, box


@pytest.mark.real_data
def test_cheez_is_read_on_the_box_in_one_pass_over_the_frame(uoc_frame) -> None:
    image, hypotheses, box = uoc_frame
    read_on = read(image, hypotheses)
    (text,) = read_on[box].find(Text)
    assert text_matches("CHEEZ", text.text) and text_matches("cheel", text.text), text.text
    assert 0.6 <= text.confidence <= 1.0
    others = [t.text for i, h in enumerate(read_on) if i != box for t in h.find(Text)]
    assert not any(text_matches("CHEEZ", t) for t in others), others  # the box's lines went to the box only
    assert read_on[box].first(SemanticColor) is None  # the reader added text only (fresh copies)


@pytest.mark.real_data
def test_a_box_cut_in_half_still_gets_its_text(uoc_frame) -> None:
    image, hypotheses, box = uoc_frame
    whole = hypotheses[box]
    x0, _, x1, _ = whole.roi
    middle = (x0 + x1) // 2
    columns = np.arange(whole.mask.shape[1])
    left = hypothesis_from(whole.mask & (columns < middle))
    right = hypothesis_from(whole.mask & (columns >= middle))

    (alone,) = read(image, [left])  # only the left half was segmented
    (text,) = alone.find(Text)
    assert text_matches("CHEEZ", text.text), text.text
    assert text.box[2] > middle  # the whole line, also the part beyond the half

    (full,) = read(image, [whole])
    halves = read(image, [left, right])
    words = sorted(w for h in halves for t in h.find(Text) for w in t.text.split())
    assert words == sorted(full.first(Text).text.split())  # every line once, on one of the halves


# ------------------------------------------------------------------------------------------ the rule, synthetic

SHAPE = (60, 80)


def line_at(x0: int, y0: int, x1: int, y1: int, text: str = "word", score: float = 0.9) -> TextLine:
    return TextLine(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float), text, score)


def test_a_line_goes_to_the_object_in_front_not_the_one_behind_whose_box_holds_it() -> None:
    behind = hypothesis_from(box_mask(SHAPE, (0, 0, 80, 60)) & ~box_mask(SHAPE, (20, 20, 50, 40)))
    front = hypothesis_from(box_mask(SHAPE, (20, 20, 50, 40)))
    line = line_at(25, 25, 45, 32)
    assert assign_lines([line], [behind, front]) == {1: [line]}


def test_a_line_far_from_every_object_is_given_to_none() -> None:
    hypothesis = hypothesis_from(box_mask(SHAPE, (0, 0, 20, 20)))
    assert assign_lines([line_at(50, 40, 70, 50)], [hypothesis]) == {}
    assert assign_lines([line_at(50, 40, 70, 50)], []) == {}


def test_text_of_lines_is_in_reading_order_with_their_union_box_and_mean_score() -> None:
    text = text_of([line_at(10, 30, 40, 38, "free", 0.8), line_at(10, 10, 40, 18, "milk", 0.9)])
    assert (text.text, text.box) == ("milk free", (10, 10, 40, 38))
    assert text.confidence == pytest.approx(0.85)
    with pytest.raises(ValueError):
        text_of([])
    with pytest.raises(ValueError):
        assign_lines([], [], min_overlap=0.0)


boxes = st.tuples(st.integers(0, 70), st.integers(0, 50), st.integers(2, 30), st.integers(2, 30)).map(
    lambda b: (b[0], b[1], min(80, b[0] + b[2]), min(60, b[1] + b[3]))
)


@given(st.lists(boxes, min_size=1, max_size=5), st.lists(boxes, min_size=0, max_size=6))
def test_every_line_goes_to_at_most_one_hypothesis_overlapping_it_most(objects, lines) -> None:
    hypotheses = [hypothesis_from(box_mask(SHAPE, b)) for b in objects]
    text_lines = [line_at(*b, text=f"w{i}") for i, b in enumerate(lines)]
    assigned = assign_lines(text_lines, hypotheses)
    given_lines = [line.text for group in assigned.values() for line in group]
    assert len(given_lines) == len(set(given_lines))
    for index, group in assigned.items():
        for line in group:
            share = overlap(line, hypotheses[index])
            assert share >= 0.25 and all(overlap(line, h) <= share for h in hypotheses)
    for line in text_lines:  # a line lying inside a hypothesis is never lost
        if line.text not in given_lines:
            assert all(overlap(line, h) < 0.25 for h in hypotheses)
