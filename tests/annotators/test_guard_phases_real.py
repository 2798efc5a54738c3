"""How much of the guard frames' objects the segmenter keeps whole wherever its crop happens to start.

The default segmenter cuts its candidates' region into grid cells counted from the crop's corner, and the corner
moves with every object in view: an unrelated object at the edge of the table moves the cells over all the others.
test_guard_objects_real.py checks each frame at the crop it gives; here the crop is started 0, 2 or 4 coarse pixels
earlier in rows and columns (9 cell phases). Grown patches do not depend on the crop at all. The figures are those of
the seventeenth session (``python bench/score_guards.py --offsets 6`` gives all 36 phases): a change that keeps the
tuned phase but loses objects at the others fails here.
"""

from __future__ import annotations

import statistics
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import annotators.cloud.clutter as clutter
from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import LabelledObject, load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, crop_moved, frame_points, segment_points

pytestmark = pytest.mark.real_data

PHASES = [(dy, dx) for dy in (0, 2, 4) for dx in (0, 2, 4)]

Frames = list[tuple[np.ndarray, np.ndarray, list[LabelledObject]]]


@pytest.fixture(scope="module")
def frames(uoc_folder: Path) -> Frames:
    """Each guard frame's points, colours and labelled objects, read once."""
    return [(*frame_points(name, index), objects) for (name, index), objects in load_labelled_objects(LABELS).items()]


def whole_objects(
    frames: Frames, parameters: ClutterParameters, monkeypatch: pytest.MonkeyPatch, dy: int, dx: int
) -> int:
    """Labelled guard objects left whole with the segmenter's crop started ``dy`` rows and ``dx`` columns earlier."""
    monkeypatch.setattr(clutter, "bounding_box", crop_moved(dy, dx))
    return sum(
        verdict.kind == "whole"
        for points, colors, objects in frames
        for verdict in object_verdicts(segment_points(points, colors, parameters), objects).values()
    )


def test_the_default_keeps_most_objects_whole_at_every_cell_phase(
    frames: Frames, monkeypatch: pytest.MonkeyPatch
) -> None:
    counts = [whole_objects(frames, ClutterParameters(), monkeypatch, dy, dx) for dy, dx in PHASES]
    assert statistics.median(counts) >= 36, counts
    assert min(counts) >= 29, counts


def test_grown_patches_keep_the_same_objects_whole_at_every_cell_phase(
    frames: Frames, monkeypatch: pytest.MonkeyPatch
) -> None:
    grown = replace(ClutterParameters(), grown_patches=True)
    counts = [whole_objects(frames, grown, monkeypatch, dy, dx) for dy, dx in PHASES]
    assert counts == [counts[0]] * len(PHASES)
    assert counts[0] >= 39
