"""Colour questions a person asks of the shared real frames (uoc_tabletop_realsense, read in place from
../shared/data), through ``robokudo query``."""

from __future__ import annotations

import pytest

from tests.application.test_real_trial import answered_at, inside, private_data, query, uoc

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


SOUP_CAN_FRAME_0 = (540, 365)
"""A pixel of the Campbell's soup can (red top, white label) in frame 0 (inside its box in
tests/data/colors/real_colors.json)."""


@pytest.mark.real_data
def test_the_red_can_is_the_red_and_white_soup_can(capsys: pytest.CaptureFixture[str]) -> None:
    """ "find the red can" on uoc frame 0 found nothing: the colour expert names the soup can white and red, but the
    fused colour is white and the red was never more likely than not. An object answers to the colours stated in
    its last sighting, and the answer says both."""
    found = answered_at(capsys, "find the red can", uoc(), 0)
    assert len(found) == 1 and inside(SOUP_CAN_FRAME_0, found[0][1])
    lines = query(capsys, "find the white can", "--input", uoc(), "--frame", "0")
    assert len(lines) == 1 and "(white and red)" in lines[0]
