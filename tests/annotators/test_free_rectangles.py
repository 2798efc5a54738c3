"""Free rectangles on an occupancy grid: free, disjoint, holding the footprint, largest first (for all grids)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from annotators.geometry.free_rectangles import CellRectangle, free_rectangles, largest_fitting_rectangle

grids = arrays(np.bool_, st.tuples(st.integers(1, 9), st.integers(1, 9)), elements=st.booleans())
footprints = st.tuples(st.integers(1, 4), st.integers(1, 4))


def brute_force_largest(free: np.ndarray, rows: int, cols: int) -> int:
    """The largest area of an all-free rectangle holding the footprint either way round (0 when none)."""
    best = 0
    height, width = free.shape
    for r0 in range(height):
        for r1 in range(r0 + 1, height + 1):
            for c0 in range(width):
                for c1 in range(c0 + 1, width + 1):
                    rectangle = CellRectangle(r0, c0, r1, c1)
                    if rectangle.holds(rows, cols) and free[r0:r1, c0:c1].all():
                        best = max(best, rectangle.area)
    return best


@settings(max_examples=150, deadline=None)
@given(grids, footprints)
def test_the_largest_fitting_rectangle_is_the_largest(free: np.ndarray, footprint: tuple[int, int]) -> None:
    found = largest_fitting_rectangle(free, *footprint)
    expected = brute_force_largest(free, *footprint)
    if expected == 0:
        assert found is None
    else:
        assert found is not None and found.area == expected
        assert free[found.row0 : found.row1, found.col0 : found.col1].all()


@settings(max_examples=150, deadline=None)
@given(grids, footprints, st.integers(1, 6))
def test_free_rectangles_are_free_disjoint_fitting_and_largest_first(
    free: np.ndarray, footprint: tuple[int, int], limit: int
) -> None:
    found = free_rectangles(free, *footprint, limit=limit)
    taken = np.zeros_like(free)
    assert len(found) <= limit
    for rectangle in found:
        block = (slice(rectangle.row0, rectangle.row1), slice(rectangle.col0, rectangle.col1))
        assert free[block].all() and not taken[block].any()
        assert rectangle.holds(*footprint) and rectangle.fits(*footprint) >= 1
        taken[block] = True
    assert [r.area for r in found] == sorted((r.area for r in found), reverse=True)
    if len(found) < limit:  # nothing left where the footprint fits
        assert largest_fitting_rectangle(free & ~taken, *footprint) is None


def test_bad_footprints_and_grids_are_refused() -> None:
    with pytest.raises(ValueError, match="at least one cell"):
        largest_fitting_rectangle(np.ones((3, 3), bool), 0, 2)
    with pytest.raises(ValueError, match="2-D"):
        largest_fitting_rectangle(np.ones(3, bool), 1, 1)
    with pytest.raises(ValueError, match="limit"):
        free_rectangles(np.ones((3, 3), bool), 1, 1, limit=0)
