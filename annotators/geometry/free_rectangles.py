"""Free rectangles on an occupancy grid: the largest axis-aligned free rectangles that hold a footprint.

A grid is a 2-D boolean array (True = free). :func:`largest_fitting_rectangle` finds the rectangle of largest
area whose every cell is free and that holds a ``rows x cols`` footprint in either orientation; it scans the
rows once, keeping per column the run of free cells ending in the current row (a histogram) and a stack of
rising bars, so every maximal rectangle is seen once (O(rows x cols)). :func:`free_rectangles` takes such
rectangles greedily, largest first, each disjoint from those taken before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class CellRectangle:
    """Rows ``row0 <= r < row1`` and columns ``col0 <= c < col1`` of a grid."""

    row0: int
    col0: int
    row1: int
    col1: int

    @property
    def rows(self) -> int:
        """Its height in cells."""
        return self.row1 - self.row0

    @property
    def cols(self) -> int:
        """Its width in cells."""
        return self.col1 - self.col0

    @property
    def area(self) -> int:
        """Its number of cells."""
        return self.rows * self.cols

    def holds(self, rows: int, cols: int) -> bool:
        """True when a ``rows x cols`` footprint fits inside, in either orientation."""
        return (self.rows >= rows and self.cols >= cols) or (self.rows >= cols and self.cols >= rows)

    def fits(self, rows: int, cols: int) -> int:
        """How many ``rows x cols`` footprints fit side by side (the better of the two orientations)."""
        upright = (self.rows // rows) * (self.cols // cols) if rows and cols else 0
        turned = (self.rows // cols) * (self.cols // rows) if rows and cols else 0
        return max(upright, turned)


def _footprint(rows: int, cols: int) -> tuple[int, int]:
    if rows < 1 or cols < 1:
        raise ValueError(f"a footprint needs at least one cell each way, got {rows} x {cols}")
    return int(rows), int(cols)


def largest_fitting_rectangle(free: np.ndarray, rows: int, cols: int) -> CellRectangle | None:
    """The free rectangle of largest area that holds a ``rows x cols`` footprint (either way round), or None.

    Ties go to the rectangle found first (lowest bottom row, then leftmost).
    """
    rows, cols = _footprint(rows, cols)
    grid = np.asarray(free, dtype=bool)
    if grid.ndim != 2:
        raise ValueError(f"the free grid must be 2-D, got shape {grid.shape}")
    short, long = min(rows, cols), max(rows, cols)
    height = np.zeros(grid.shape[1] + 1, dtype=np.int64)  # a zero sentinel column closes every bar
    best: CellRectangle | None = None
    for row in range(grid.shape[0]):
        height[:-1] = np.where(grid[row], height[:-1] + 1, 0)
        if height[:-1].max(initial=0) < short:
            continue
        bars = height.tolist()
        stack: list[int] = []  # columns of rising bars
        for col, h in enumerate(bars):
            while stack and bars[stack[-1]] >= h:
                top = stack.pop()
                bar = bars[top]
                left = stack[-1] + 1 if stack else 0
                width = col - left
                if bar >= short and width >= short and (bar >= long or width >= long):
                    candidate = CellRectangle(row + 1 - bar, left, row + 1, col)
                    if candidate.holds(rows, cols) and (best is None or candidate.area > best.area):
                        best = candidate
            stack.append(col)
    return best


def free_rectangles(free: np.ndarray, rows: int, cols: int, limit: int = 10) -> list[CellRectangle]:
    """Up to ``limit`` disjoint free rectangles that each hold a ``rows x cols`` footprint, largest first."""
    if limit < 1:
        raise ValueError(f"limit must be at least 1, got {limit}")
    rows, cols = _footprint(rows, cols)
    remaining = np.array(free, dtype=bool)  # a copy: taken rectangles are cleared
    found: list[CellRectangle] = []
    while len(found) < limit:
        rectangle = largest_fitting_rectangle(remaining, rows, cols)
        if rectangle is None:
            break
        found.append(rectangle)
        remaining[rectangle.row0 : rectangle.row1, rectangle.col0 : rectangle.col1] = False
    return found
