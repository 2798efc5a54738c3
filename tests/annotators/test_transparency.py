"""The tinted-transparent join (annotators/geometry/transparency.py) on small hand-made grids.

A blue bottle seen in two pieces (a depth seam between them), with blue pixels that have no depth among them,
joins. Without those holes (two identical blue boxes stacked), or when the holes show the table's colour (an opaque
object's depth shadow), or when the pieces have no tint (grey), or two different tints, the pieces stay apart.
"""

from __future__ import annotations

import numpy as np

from annotators.geometry.grid_segmentation import chroma_image
from annotators.geometry.transparency import TransparencyRules, join_see_through, see_through_groups

BLUE = (30, 60, 200)
RED = (200, 40, 30)
GREY = (128, 128, 128)
TABLE = (120, 95, 70)


def scene(
    holes: bool,
    upper: tuple[int, int, int] = BLUE,
    lower: tuple[int, int, int] = BLUE,
    hole_color: tuple[int, int, int] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Labels, depth validity and the chroma image of the colours of a 60x60 grid: an upper piece (label 1, rows
    5-28) and a lower piece (label 2, rows 30-55) of columns 20-40 on a table, an unlabelled seam row between them;
    with ``holes`` a block inside the lower piece has no depth (coloured ``hole_color``, else the lower piece's
    colour)."""
    labels = np.zeros((60, 60), dtype=np.int32)
    colors = np.empty((60, 60, 3), dtype=np.uint8)
    colors[:] = TABLE
    valid = np.ones((60, 60), dtype=bool)
    labels[5:29, 20:41] = 1
    labels[30:56, 20:41] = 2
    colors[5:30, 20:41] = upper
    colors[30:56, 20:41] = lower
    if holes:
        labels[34:52, 25:36] = 0
        valid[34:52, 25:36] = False
        colors[34:52, 25:36] = hole_color or lower
    return labels, valid, chroma_image(colors)


def test_a_tinted_object_with_holes_of_its_tint_is_one_piece() -> None:
    labels, valid, chroma = scene(holes=True)
    joined = join_see_through(labels, valid, chroma)
    assert joined.max() == 1
    assert np.array_equal(joined > 0, labels > 0)


def test_identical_tinted_boxes_without_holes_stay_apart() -> None:
    labels, valid, chroma = scene(holes=False)
    assert see_through_groups(labels, valid, chroma) == []
    assert join_see_through(labels, valid, chroma) is labels


def test_holes_showing_the_table_do_not_join() -> None:
    labels, valid, chroma = scene(holes=True, hole_color=TABLE)
    assert see_through_groups(labels, valid, chroma) == []


def test_untinted_pieces_do_not_join() -> None:
    labels, valid, chroma = scene(holes=True, upper=GREY, lower=GREY)
    assert see_through_groups(labels, valid, chroma) == []


def test_two_tints_do_not_join() -> None:
    labels, valid, chroma = scene(holes=True, upper=RED, lower=BLUE)
    assert see_through_groups(labels, valid, chroma) == []


def test_too_few_holes_do_not_join() -> None:
    labels, valid, chroma = scene(holes=True)
    share = 18 * 11 / np.count_nonzero(labels)
    assert see_through_groups(labels, valid, chroma, TransparencyRules(hole_share=share * 0.9)) == [[1, 2]]
    assert see_through_groups(labels, valid, chroma, TransparencyRules(hole_share=share * 1.1)) == []


def test_pieces_apart_in_the_image_do_not_join() -> None:
    labels, valid, chroma = scene(holes=True)
    labels[5:29, 20:41] = 0
    labels[5:20, 20:41] = 1  # the upper piece now ends 10 rows above the lower one
    assert see_through_groups(labels, valid, chroma) == []
