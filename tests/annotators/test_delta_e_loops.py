"""The compiled CIEDE2000 of colour pairs, and of every colour against the colour-name prototypes, equals the NumPy
form to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.color_prototypes import prototypes
from annotators.image.color_space import delta_e_2000
from annotators.image.delta_e_loops import delta_e_2000_outer, delta_e_2000_pairs


def random_labs(rng: np.random.Generator, count: int, dtype: type) -> np.ndarray:
    """CIELAB colours over the whole space, some neutral (a* = b* = 0) and some with a* = 0."""
    labs = np.column_stack([rng.uniform(0, 100, count), rng.normal(0, 40, count), rng.normal(0, 40, count)])
    labs[::17, 1:] = 0.0
    labs[1::23, 1] = 0.0
    return labs.astype(dtype)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("factors", [(1.0, 1.0, 1.0), (2.0, 0.5, 1.5)])
def test_pairs_equal_the_numpy_form_to_the_last_bit(dtype: type, factors: tuple[float, float, float]) -> None:
    rng = np.random.default_rng(7)
    first, second = random_labs(rng, 20000, dtype), random_labs(rng, 20000, dtype)
    expected = delta_e_2000(first, second, *factors)
    found = delta_e_2000_pairs(first, second, *factors)
    assert found.dtype == expected.dtype
    assert np.array_equal(found.view(np.uint8), expected.view(np.uint8))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_every_colour_against_the_prototypes_equals_the_numpy_form_to_the_last_bit(dtype: type) -> None:
    colours = random_labs(np.random.default_rng(3), 300, dtype)
    references = prototypes(("red", "green", "blue", "purple", "pink", "brown"))[1].astype(dtype)
    expected = delta_e_2000(colours[:, None, :], references[None, :, :])
    found = delta_e_2000_outer(colours, references)
    assert found.shape == expected.shape == (300, references.shape[0])
    assert np.array_equal(found.view(np.uint8), expected.view(np.uint8))


def test_colours_that_are_not_finite_give_the_numpy_form() -> None:
    colours = np.array([[50.0, np.nan, 3.0], [60.0, 10.0, np.inf]], dtype=np.float32)
    others = np.array([[55.0, 5.0, 5.0], [40.0, -20.0, 30.0]], dtype=np.float32)
    with np.errstate(invalid="ignore"):  # NaN and infinity in, NaN out: numpy says so; that is the point here
        expected = delta_e_2000(colours, others)
        found = delta_e_2000_pairs(colours, others)
    assert np.array_equal(found, expected, equal_nan=True)


def test_opposite_hues_and_empty_input_give_the_numpy_form() -> None:
    first, second = np.array([[50.0, 2.5, -1.0]]), np.array([[50.0, -2.5, 1.0]])  # hue vectors sum to zero
    assert delta_e_2000_pairs(first, second)[0] == delta_e_2000(first, second)[0]
    assert delta_e_2000_pairs(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match="one length"):
        delta_e_2000_pairs(np.zeros((2, 3)), np.zeros((3, 3)))
