"""CIELAB conversion and CIEDE2000 against published values, and the colour-name prototypes of the survey."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from annotators.image.color import CHROMATIC_TERMS
from annotators.image.color_prototypes import basic_term, prototypes, survey_colors
from annotators.image.color_space import delta_e_2000, linear_to_lab, linear_to_srgb, srgb_to_lab, srgb_to_linear

# Pairs from the supplementary test data of Sharma, Wu and Dalal (2005), Color Res. Appl. 30(1), table 1.
SHARMA_PAIRS = [
    ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
    ((50.0, -1.0, 2.0), (50.0, 0.0, 0.0), 2.3669),
    ((50.0, 2.5, 0.0), (50.0, 0.0, -2.5), 4.3065),
    ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
    ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0009), 7.1792),
    ((63.0109, -31.0961, -5.8663), (62.8187, -29.7946, -4.0864), 1.2630),
    ((2.0776, 0.0795, -1.135), (0.9033, -0.0636, -0.5514), 0.9082),
    ((50.0, 2.5, 0.0), (50.0, 3.1736, 0.5854), 1.0000),
]


@pytest.mark.parametrize(("lab1", "lab2", "expected"), SHARMA_PAIRS)
def test_ciede2000_matches_the_published_test_data(lab1: tuple, lab2: tuple, expected: float) -> None:
    assert float(delta_e_2000(np.array(lab1), np.array(lab2))) == pytest.approx(expected, abs=1e-4)
    assert float(delta_e_2000(np.array(lab2), np.array(lab1))) == pytest.approx(expected, abs=1e-4)


def test_parametric_factors_weigh_the_lightness_difference_down() -> None:
    a, b = np.array([40.0, 10.0, 10.0]), np.array([60.0, 10.0, 10.0])
    assert float(delta_e_2000(a, b, k_l=2.0)) == pytest.approx(float(delta_e_2000(a, b)) / 2.0, rel=1e-9)


def test_srgb_white_black_and_red_in_cielab() -> None:
    lab = srgb_to_lab(np.array([[255, 255, 255], [0, 0, 0], [255, 0, 0]], dtype=np.uint8))
    assert lab[0] == pytest.approx([100.0, 0.0, 0.0], abs=1e-3)
    assert lab[1] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    assert lab[2] == pytest.approx([53.24, 80.09, 67.20], abs=0.01)


@given(st.lists(st.integers(0, 255), min_size=3, max_size=3))
def test_linearisation_round_trips(rgb: list[int]) -> None:
    values = np.array(rgb, dtype=np.uint8)
    assert np.rint(255.0 * linear_to_srgb(srgb_to_linear(values))) == pytest.approx(values)


def test_the_survey_list_is_complete() -> None:
    colors = survey_colors()
    assert len(colors) == 949
    assert dict(colors)["purple"] == "#7e1e9c" and dict(colors)["pink"] == "#ff81c0"


@pytest.mark.parametrize(
    ("name", "term"),
    [
        ("red", "red"),
        ("dark red", "red"),
        ("fire engine red", "red"),
        ("brownish red", "red"),
        ("blue with a hint of purple", "blue"),
        ("orange pink", None),
        ("blue green", None),
        ("purple/blue", None),
        ("teal", None),
    ],
)
def test_a_survey_name_is_an_example_of_its_head_word(name: str, term: str | None) -> None:
    assert basic_term(name, (*CHROMATIC_TERMS, "grey")) == term


def test_every_chromatic_term_has_prototypes_and_a_new_term_would_get_its_own() -> None:
    terms, lab, names = prototypes(CHROMATIC_TERMS)
    assert set(terms) == set(CHROMATIC_TERMS) and lab.shape == (len(terms), 3) and len(names) == len(terms)
    teal_terms, _, teal_names = prototypes(("teal", "green", "blue"))
    assert "teal" in teal_terms and "dark teal" in teal_names and "teal green" not in teal_names
    with pytest.raises(ValueError, match="mauvish"):
        prototypes(("mauvish",))


def test_one_colour_converts_as_a_row_of_colours_does() -> None:
    """The single-colour path of linear_to_lab (Python floats) gives the array path's values exactly, on both
    sides of the linear segment near black and above white."""
    rng = np.random.default_rng(0)
    colours = np.concatenate([rng.random((300, 3)), rng.random((300, 3)) * 0.02, rng.random((50, 3)) * 3.0])
    colours[:5] = 0.0
    for colour in colours:
        np.testing.assert_array_equal(linear_to_lab(colour), linear_to_lab(colour[None, :])[0])
    assert linear_to_lab(np.float32([0.2, 0.3, 0.1])).dtype == np.float32
