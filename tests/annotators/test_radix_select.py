"""The compiled radix selection gives the order statistic numpy's sort gives."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.radix_select import kth_smallest


@pytest.mark.parametrize("seed", range(30))
def test_kth_smallest_is_the_sorted_values_kth(seed: int) -> None:
    rng = np.random.default_rng(seed)
    size = int(rng.integers(1, 3000))
    values = (rng.normal(size=size) * 10 ** rng.uniform(-6, 6)).astype(np.float32)
    values[rng.random(size) < 0.2] = 0.0  # ties, and zero among negative and positive values
    if seed % 3 == 0:
        values = np.abs(values)
    ordered = np.sort(values)
    original = values.copy()
    for rank in {0, size // 2, size - 1, int(rng.integers(0, size))}:
        assert kth_smallest(values, rank) == ordered[rank]
    assert np.array_equal(values, original)


def test_extreme_values_and_signed_zeros_order_as_floats() -> None:
    values = np.array([np.inf, -np.inf, -0.0, 0.0, 1e-45, -1e-45, 3.4e38, -3.4e38], dtype=np.float32)
    ordered = np.sort(values)
    for rank in range(values.size):
        assert kth_smallest(values, rank) == ordered[rank]
