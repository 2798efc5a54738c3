"""Colour questions a person asks of the shared real frames (uoc_tabletop_realsense, read in place from
../shared/data), through ``robokudo query``."""

from __future__ import annotations

import pytest

from tests.application.test_real_trial import answered_at, inside, private_data, uoc

__all__ = ["private_data"]  # the fixture keeps the user ontology and the belief store private

TEAL_BOWL = {0: (235, 380), 2: (340, 235), 3: (340, 185)}
"""The teal bowl's labelled pixel per frame (tests/data/labels/real_objects.json)."""


@pytest.mark.real_data
@pytest.mark.parametrize("frame", sorted(TEAL_BOWL))
def test_the_teal_bowl_is_found_though_the_namer_says_no_teal(capsys: pytest.CaptureFixture[str], frame: int) -> None:
    """ "find the teal bowl" was refused ("the colour namer reports no 'teal'"); teal is asked as blue or green, the
    basic colours a person names it by (the namer calls this bowl blue), and the teal bowl is the answer."""
    found = answered_at(capsys, "find the teal bowl", uoc(), frame)
    assert len(found) == 1
    (shown, roi) = found[0]
    assert shown.rstrip("?") == "bowl" and inside(TEAL_BOWL[frame], roi)
