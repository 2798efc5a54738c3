"""join_necked_pieces: a piece standing on another on a neck far narrower than itself (an upright drill's body
on its grip, cut at the battery's top) joins it; a can standing on a can, a box lying across a can and pieces
side by side stay apart."""

from __future__ import annotations

import numpy as np

from annotators.geometry.necks import NeckRules, join_necked_pieces, neck_and_body, neck_partners

ROWS, COLUMNS = 60, 100
U_STEP = 0.0025  # metres across the table per column: 100 columns span 25 cm
H_STEP = 0.003  # metres of height per row: 60 rows span 18 cm


def side_view(parts: dict[int, list[tuple[tuple[float, float], tuple[float, float]]]]) -> tuple[np.ndarray, np.ndarray]:
    """Labels and ``(u, v, height)`` plane points of objects seen from the side: each label a list of boxes
    ``((u0, u1), (h0, h1))`` in metres, height growing up the image."""
    rows, columns = np.mgrid[0:ROWS, 0:COLUMNS]
    u = columns * U_STEP
    height = (ROWS - rows) * H_STEP
    v = 0.002 * (rows % 3)  # a little depth, as a front surface has
    plane_points = np.stack([u, v, height], axis=-1).astype(np.float32)
    labels = np.zeros((ROWS, COLUMNS), dtype=np.int64)
    for label, boxes in parts.items():
        for (u0, u1), (h0, h1) in boxes:
            labels[(u >= u0) & (u < u1) & (height > h0) & (height <= h1)] = label
    return labels, plane_points


BATTERY = [((0.08, 0.17), (0.0, 0.05))]  # 9 cm long, 5 cm high


def test_a_body_on_a_grip_narrower_than_a_third_of_it_joins_the_battery_it_enters() -> None:
    drill = [((0.11, 0.14), (0.05, 0.11)), ((0.03, 0.23), (0.11, 0.18))]  # a 3 cm grip under a 20 cm body
    labels, plane_points = side_view({1: BATTERY, 2: drill})
    neck, body = neck_and_body(labels, plane_points, 2, NeckRules())
    assert neck < 0.03 and body > 0.15  # spans from the 5 % to the 95 % quantile
    assert neck_partners(labels, plane_points, NeckRules()) == [(2, 1)]
    joined = join_necked_pieces(labels, plane_points)
    assert joined.max() == 1 and np.array_equal(joined > 0, labels > 0)


def test_objects_resting_on_their_whole_base_or_side_by_side_stay_apart() -> None:
    can = [((0.09, 0.16), (0.05, 0.15))]  # a can standing on the battery-sized block: as wide at its foot as above
    across = [((0.02, 0.24), (0.05, 0.09))]  # a box lying across it: its lowest band is its whole front edge
    beside = [((0.17, 0.20), (0.0, 0.05)), ((0.17, 0.24), (0.05, 0.15))]  # a narrow foot, but on the table
    for upper in (can, across, beside):
        labels, plane_points = side_view({1: BATTERY, 2: upper})
        assert neck_partners(labels, plane_points, NeckRules()) == []
        assert np.array_equal(join_necked_pieces(labels, plane_points), labels)


def test_a_wide_piece_on_a_narrow_neck_that_starts_below_the_lower_ones_top_stays_apart() -> None:
    # the neck reaches 4 cm down into the block's heights: not standing on its top (an object in front of it)
    drill = [((0.11, 0.14), (0.01, 0.11)), ((0.03, 0.23), (0.11, 0.18))]
    labels, plane_points = side_view({1: BATTERY, 2: drill})
    assert neck_partners(labels, plane_points, NeckRules()) == []


def test_a_neck_under_pieces_apart_in_the_image_is_no_rigid_body() -> None:
    # the grip and a body one row above it, unlabelled between: two surfaces, not one piece held on a neck
    drill = [((0.11, 0.14), (0.05, 0.11)), ((0.03, 0.23), (0.114, 0.18))]
    labels, plane_points = side_view({1: BATTERY, 2: drill})
    assert neck_partners(labels, plane_points, NeckRules(one_surface=0.5)) == [(2, 1)]
    assert neck_partners(labels, plane_points, NeckRules()) == []
