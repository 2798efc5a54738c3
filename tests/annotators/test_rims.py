"""The rim of an open container (annotators.geometry.rims) on synthetic plane coordinates.

The camera's foot is at the origin of the table plane and it looks along +u; a bowl of radius 7 cm with its rim
8 cm high stands at u = 0.5. Its inner wall seen over the rim is the back of the ring (u beyond the centre), its
outer wall below the rim the front; a can standing in it rises to 10 cm at the centre (it is no piece of the bowl
for join_unsupported either).
"""

from __future__ import annotations

import numpy as np

from annotators.geometry.rims import (
    RimRules,
    curves_like_a_rim,
    fit_circle,
    join_rim_pieces,
    join_single_rims,
    stands_inside,
)
from annotators.geometry.support import SupportRules, join_unsupported

CENTRE = np.array([0.5, 0.0])
RADIUS = 0.07
RIM = 0.08


def ring(angles_degrees: np.ndarray, radius: np.ndarray | float, heights: np.ndarray | float) -> np.ndarray:
    """Nx3 ``(u, v, height)`` points on circles around the bowl's centre."""
    angles = np.radians(angles_degrees)
    radius = np.broadcast_to(radius, angles.shape)
    heights = np.broadcast_to(heights, angles.shape)
    return np.column_stack([CENTRE[0] + radius * np.cos(angles), CENTRE[1] + radius * np.sin(angles), heights])


def inner_wall(first: float, last: float, count: int = 200) -> np.ndarray:
    """Points of the inner wall between two angles: the bowl narrows from the rim down to 3 cm above the table."""
    rng = np.random.default_rng(int(abs(first)))
    heights = rng.uniform(0.03, RIM, count)
    return ring(rng.uniform(first, last, count), RADIUS * (0.6 + 0.4 * heights / RIM), heights)


def outer_wall(count: int = 200) -> np.ndarray:
    """Points of the outer wall's front, from the foot up to just below the rim."""
    rng = np.random.default_rng(7)
    heights = rng.uniform(0.01, RIM - 0.005, count)
    return ring(rng.uniform(110.0, 250.0, count), RADIUS * (0.7 + 0.3 * heights / RIM), heights)


def can(top: float, count: int = 200) -> np.ndarray:
    """The front half of a can of radius 3 cm standing on the bowl's floor at its centre, up to ``top``."""
    rng = np.random.default_rng(3)
    return ring(rng.uniform(100.0, 260.0, count), 0.03, rng.uniform(0.02, top, count))


def test_the_circle_of_an_arc_is_found() -> None:
    centre, radius = fit_circle(ring(np.linspace(10.0, 80.0, 50), RADIUS, RIM)[:, :2])
    assert np.allclose(centre, CENTRE, atol=1e-6) and abs(radius - RADIUS) < 1e-6


def test_the_back_of_a_rim_and_a_whole_rim_curve_like_a_rim_a_solid_front_does_not() -> None:
    back = ring(np.linspace(20.0, 160.0, 40) - 90.0, RADIUS, RIM)[:, :2]  # beyond the centre, seen over the rim
    front = ring(np.linspace(100.0, 260.0, 40), RADIUS, RIM)[:, :2]  # bulging toward the camera
    whole = ring(np.linspace(0.0, 350.0, 60), RADIUS, RIM)[:, :2]
    assert curves_like_a_rim(CENTRE, back)
    assert not curves_like_a_rim(CENTRE, front)
    assert curves_like_a_rim(CENTRE, whole)


def test_a_can_rising_above_the_rim_stands_inside_the_bowl_but_not_its_own_outside() -> None:
    rules = RimRules()
    wall = inner_wall(10.0, 80.0)
    assert stands_inside(wall, can(0.10), rules)
    assert not stands_inside(wall, can(0.07), rules)  # below the rim: could be the bowl's own floor or bottom
    assert not stands_inside(wall, outer_wall(), rules)  # the outside lies on the rim's circle, below the rim
    assert not stands_inside(can(0.10), wall, rules)  # a can's front is no rim


def grid_of(
    blocks: dict[int, tuple[slice, slice, np.ndarray]], shape: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """Labels and HxWx3 plane coordinates with each label's points laid out over its block of pixels."""
    labels = np.zeros(shape, dtype=np.int32)
    plane = np.full((*shape, 3), np.nan, dtype=np.float32)
    for label, (rows, columns, points) in blocks.items():
        labels[rows, columns] = label
        cells = labels[rows, columns].size
        plane[rows, columns] = points[np.arange(cells) % points.shape[0]].reshape(*labels[rows, columns].shape, 3)
    return labels, plane


def test_the_rim_pieces_on_both_sides_of_a_can_join_with_the_outer_wall_and_the_can_stays_apart() -> None:
    beside = np.column_stack(  # a box standing beside the bowl, as high as its rim
        [np.full(100, 0.52), np.linspace(-0.16, -0.10, 100), np.linspace(0.0, RIM, 100)]
    )
    labels, plane = grid_of(
        {
            1: (slice(0, 20), slice(0, 20), inner_wall(10.0, 80.0)),  # the left of the inner wall
            3: (slice(0, 20), slice(20, 40), can(0.10)),  # the can, between the two
            2: (slice(0, 20), slice(40, 60), inner_wall(-80.0, -10.0)),  # the right of the inner wall
            4: (slice(20, 30), slice(0, 60), outer_wall()),  # the outer wall below the front rim
            5: (slice(0, 20), slice(60, 70), beside),
        },
        (30, 70),
    )
    joined = join_rim_pieces(labels, plane)
    bowl = {int(joined[5, 5]), int(joined[5, 45]), int(joined[25, 30])}
    assert len(bowl) == 1, joined
    assert int(joined[5, 30]) not in bowl and int(joined[5, 65]) not in bowl


def test_walls_of_two_bowls_or_at_two_heights_stay_apart() -> None:
    other_bowl = inner_wall(-80.0, -10.0) + np.array([0.0, -0.15, 0.0])  # a bowl beside it, the can between
    lower = inner_wall(-80.0, -10.0) * np.array([1.0, 1.0, 0.7])  # a rim 2.4 cm lower
    for right in (other_bowl, lower):
        labels, plane = grid_of(
            {
                1: (slice(0, 20), slice(0, 20), inner_wall(10.0, 80.0)),
                3: (slice(0, 20), slice(20, 40), can(0.10)),
                2: (slice(0, 20), slice(40, 60), right),
            },
            (20, 60),
        )
        assert join_rim_pieces(labels, plane) is labels


def whole_bowl(count: int = 400) -> np.ndarray:
    """Points of a whole bowl seen from above: its inner wall all around (the rim on top) and its outer wall in
    front, down to the table."""
    rng = np.random.default_rng(11)
    inside = inner_wall(-90.0, 90.0, count // 2)
    outside = ring(rng.uniform(90.0, 270.0, count // 2), RADIUS * rng.uniform(0.7, 1.0, count // 2), 0.0)
    outside[:, 2] = rng.uniform(0.0, RIM, count // 2)
    return np.concatenate([inside, outside])


def test_a_can_standing_in_a_whole_bowl_is_no_piece_of_it() -> None:
    """join_unsupported: the can does not reach the table, its footprint lies within the bowl's and its foot in the
    lower half of the bowl's heights - the marks of a piece that cannot stand by itself - but it stands inside."""
    labels, plane = grid_of(
        {1: (slice(0, 20), slice(0, 40), whole_bowl()), 2: (slice(20, 30), slice(10, 30), can(0.10))}, (30, 40)
    )
    apart = join_unsupported(labels, plane)
    assert apart[5, 5] != apart[25, 20]
    joined = join_unsupported(labels, plane, SupportRules(standing_inside=False))
    assert joined[5, 5] == joined[25, 20]  # without the rim test it would be taken for a piece of the bowl


def test_a_piece_the_sampled_rows_miss_joins_nothing_and_breaks_nothing() -> None:
    """join_single_rims reads every second row and column: a piece of one pixel on an odd row and column (the highest
    label) has none of them. It crashed the segmenter on mOSD learn4 seen by a camera rolled by 270 degrees."""
    labels, plane = grid_of(
        {1: (slice(0, 20), slice(0, 40), inner_wall(-90.0, 90.0)), 2: (slice(20, 30), slice(0, 40), outer_wall())},
        (30, 40),
    )
    labels[21, 21] = 3
    joined = join_single_rims(labels, plane)
    assert joined[21, 21] != 0 and joined[5, 5] == joined[25, 5]  # the inner wall still joins its outer wall
