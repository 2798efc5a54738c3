"""The default clutter segmenter on the five real uoc frames, scored object by object against hand labels
(tests/data/labels/guard_objects.json; bench/score_guards.py prints the same verdicts for both patch stages).

No labelled object may be cut into pieces, merged with another or missed: the robot would report two half mugs, or
one drill-and-box, or nothing. A segment may spill over onto a little table (uoc 1's half-hidden soup can does).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from annotators.cloud.clutter import ClutterParameters
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts
from tests.annotators.guard_frames import LABELS, segment_frame

pytestmark = pytest.mark.real_data

FRAMES = load_labelled_objects(LABELS)


@pytest.mark.parametrize("key", sorted(FRAMES), ids=lambda key: f"{Path(key[0]).stem}-{key[1]}")
def test_no_labelled_object_is_cut_merged_or_missed(key: tuple[str, int]) -> None:
    verdicts = object_verdicts(segment_frame(*key, ClutterParameters()), FRAMES[key])
    wrong = {name: str(v) for name, v in verdicts.items() if v.kind not in ("whole", "spills over")}
    assert wrong == {}
    assert sum(v.kind == "whole" for v in verdicts.values()) >= len(verdicts) - 1
