"""The compiled CIEDE2000 of colour pairs equals the NumPy form to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.color_space import delta_e_2000
from annotators.image.delta_e_loops import delta_e_2000_pairs


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


def test_opposite_hues_and_empty_input_give_the_numpy_form() -> None:
    first, second = np.array([[50.0, 2.49, -0.001]]), np.array([[50.0, -2.49, 0.0009]])
    assert delta_e_2000_pairs(first, second)[0] == delta_e_2000(first, second)[0]
    assert delta_e_2000_pairs(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match="one length"):
        delta_e_2000_pairs(np.zeros((2, 3)), np.zeros((3, 3)))
