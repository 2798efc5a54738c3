"""Where the clutter segmenter's cells start: at the corner of each group of nearby surfaces, not of the grid."""

from __future__ import annotations

import numpy as np

from annotators.geometry.convexity import CELL_MARGIN, grid_patches

CELL = 6


def same_partition(first: np.ndarray, second: np.ndarray) -> bool:
    """Do two label arrays of the same pixels cut them into the same parts (whatever the numbers)?"""
    pairs = np.unique(np.column_stack([first, second]), axis=0)
    return len(pairs) == len(np.unique(first)) == len(np.unique(second))


def box(surfaces: np.ndarray, label: int, rows: slice, cols: slice) -> None:
    """Write a rectangular surface ``label`` into ``surfaces``."""
    surfaces[rows, cols] = label


def test_neither_the_crop_nor_a_far_surface_moves_the_cells_of_another() -> None:
    alone = np.zeros((80, 90), dtype=np.int32)
    box(alone, 1, slice(40, 63), slice(50, 75))
    mug = alone == 1
    expected = grid_patches(alone, CELL)[mug]
    for start in range(CELL):  # a crop, or the box of the candidates, starting at every row and column of a cell
        cropped = alone[start:, start // 2 :]
        assert same_partition(grid_patches(cropped, CELL)[mug[start:, start // 2 :]], expected), start
        with_far = alone.copy()
        box(with_far, 2, slice(start, start + 5), slice(3, 10))  # far above and to the left of it
        assert same_partition(grid_patches(with_far, CELL)[mug], expected), start


def test_a_lone_surface_gets_the_cells_of_a_crop_with_the_margin() -> None:
    surfaces = np.zeros((40, 40), dtype=np.int32)
    box(surfaces, 1, slice(CELL_MARGIN, 30), slice(CELL_MARGIN, 25))
    rows, cols = np.nonzero(surfaces)
    cells = (rows // CELL) * 100 + cols // CELL  # counted from the corner of a crop leaving the margin around it
    patches = grid_patches(surfaces, CELL)[rows, cols]
    assert same_partition(patches, cells)
    assert len(np.unique(patches)) == len(np.unique(cells)) == 5 * 5


def test_surfaces_within_a_cell_of_each_other_share_one_grid_of_cells() -> None:
    surfaces = np.zeros((60, 60), dtype=np.int32)
    box(surfaces, 1, slice(10, 40), slice(10, 20))
    box(surfaces, 2, slice(13, 40), slice(24, 34))  # 4 px to the right of the first: within a cell
    rows, cols = np.nonzero(surfaces == 2)
    shared = ((rows - 10 + CELL_MARGIN) // CELL) * 100 + (cols - 10 + CELL_MARGIN) // CELL  # the first one's grid
    own = ((rows - 13 + CELL_MARGIN) // CELL) * 100 + (cols - 24 + CELL_MARGIN) // CELL  # its own corner's grid
    patches = grid_patches(surfaces, CELL)[rows, cols]
    assert same_partition(patches, shared)
    assert not same_partition(patches, own)


def test_a_cell_two_surfaces_share_gives_one_patch_to_each() -> None:
    surfaces = np.zeros((20, 20), dtype=np.int32)
    box(surfaces, 1, slice(2, 6), slice(2, 4))
    box(surfaces, 2, slice(2, 6), slice(4, 6))  # the same cell's right part, another surface
    patches = grid_patches(surfaces, CELL)
    assert len(np.unique(patches[surfaces == 1])) == len(np.unique(patches[surfaces == 2])) == 1
    assert patches[2, 2] != patches[2, 4]
