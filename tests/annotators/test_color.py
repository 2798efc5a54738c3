"""HSV colour naming: pure and shaded patches, achromatic objects, confidence as the winning share."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from annotators.image.color import COLOR_NAMES, COLOR_RULES, classify_names, name_color


def patch(rgb: tuple[int, int, int], shading: float = 1.0, count: int = 400) -> np.ndarray:
    """``count`` pixels of one albedo under one shading factor, with a little noise."""
    rng = np.random.default_rng(0)
    values = np.array(rgb, dtype=float) * shading + rng.normal(0, 2, (count, 3))
    return np.clip(np.rint(values), 0, 255).astype(np.uint8)


@pytest.mark.parametrize(
    ("rgb", "expected"),
    [
        ((205, 28, 30), "red"),
        ((240, 140, 20), "orange"),
        ((240, 224, 28), "yellow"),
        ((40, 170, 60), "green"),
        ((32, 78, 200), "blue"),
        ((120, 40, 180), "purple"),
        ((230, 80, 170), "pink"),
        ((110, 70, 40), "brown"),
        ((248, 248, 246), "white"),
        ((120, 120, 122), "grey"),
        ((20, 20, 22), "black"),
    ],
)
def test_clean_patches_get_their_name(rgb: tuple[int, int, int], expected: str) -> None:
    color, share, _ = name_color(patch(rgb))
    assert color == expected
    assert share > 0.9


@pytest.mark.parametrize("shading", [0.5, 0.7, 1.0])
def test_shaded_colours_keep_their_name(shading: float) -> None:
    for rgb, expected in (((205, 28, 30), "red"), ((32, 78, 200), "blue"), ((240, 224, 28), "yellow")):
        assert name_color(patch(rgb, shading))[0] == expected


def test_a_white_object_is_white_even_where_it_is_shaded() -> None:
    lit = patch((248, 248, 246), 1.0, 300)
    shaded = patch((248, 248, 246), 0.45, 300)
    color, share, _ = name_color(np.vstack([lit, shaded]))
    assert color == "white" and share == 1.0


def test_a_dark_saturated_navy_is_blue_not_black() -> None:
    assert name_color(patch((10, 25, 60)))[0] == "blue"


def test_confidence_is_the_share_of_the_winning_colour() -> None:
    red, yellow, white = patch((205, 28, 30), 1, 600), patch((240, 224, 28), 1, 300), patch((248, 248, 246), 1, 100)
    pixels = np.vstack([red, yellow, white])
    color, share, shares = name_color(pixels)
    assert color == "red"
    assert share == pytest.approx(0.6, abs=0.02)
    assert shares["yellow"] == pytest.approx(0.3, abs=0.02)
    assert sum(shares.values()) == pytest.approx(1.0)


def test_hue_boundaries_follow_the_rule_table() -> None:
    for rule in COLOR_RULES:
        if rule.value[1] < 1.0 or rule.saturation[1] < 1.0:
            continue  # special rules (brown, pale pink) are checked above
        low, high = rule.hues[0]
        hue = (low + min(high, 360.0)) / 2
        hsv = np.array([[[round(hue * 255 / 360), 230, 220]]], dtype=np.uint8)
        rgb = cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB_FULL).reshape(1, 3)
        assert classify_names(rgb)[0] == rule.name, (rule.name, hue)


def test_every_name_is_an_ontology_style_lower_case_word() -> None:
    assert set(COLOR_NAMES) == {
        "red", "orange", "yellow", "green", "blue", "purple", "pink", "brown", "white", "grey", "black",
    }  # fmt: skip


def test_no_pixels_is_an_error() -> None:
    with pytest.raises(ValueError):
        name_color(np.zeros((0, 3), dtype=np.uint8))
